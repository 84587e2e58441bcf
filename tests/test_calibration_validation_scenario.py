"""The calibration validation's scoring guards (issue 22): fresh seeds only, frozen diagnosis settings."""

from __future__ import annotations

import importlib.util

import pytest

from heavecomp.report.scenario import ROOT


def _scenario():
    spec = importlib.util.spec_from_file_location("calibration_validation",
                                                  ROOT / "scenarios" / "calibration_validation.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_the_seed_base_sets_every_case_seed_and_a_spent_range_is_refused(tmp_path, capsys):
    cv = _scenario()
    assert [c.seed for c in cv.cases(seed0=560000)][:3] == [560000, 560001, 560002]
    # 210000+ is this scenario's own spent first scoring run: refused before any run starts
    assert cv.main(["--seed-base", "210000", "--out", str(tmp_path)]) == 2
    assert "spent" in capsys.readouterr().err
    assert not (tmp_path / "metrics.json").exists()


def test_the_loop_scenario_refuses_a_spent_seed_for_a_full_run(tmp_path, capsys):
    """sim_to_real_loop's full run is a scoring run: a seed any set has spent (the shared registry,
    heavecomp.benchmark.seeds) is refused before anything is generated; its default is fresh."""
    from heavecomp.benchmark.seeds import spent

    spec = importlib.util.spec_from_file_location("sim_to_real_loop", ROOT / "scenarios" / "sim_to_real_loop.py")
    loop = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(loop)
    assert loop.main(["--seed", "570000", "--out", str(tmp_path)]) == 2
    assert "570000+" in capsys.readouterr().err and not (tmp_path / "metrics.json").exists()
    # the calibration validation's and the loop's defaults are fresh, and the two sets do not overlap
    cv = _scenario()
    assert spent(c.seed for c in cv.cases(seed0=cv.SEED0)) == [] and spent(range(loop.SEED0, loop.SEED0 + 100)) == []
    assert loop.SEED0 > max(c.seed for c in cv.cases(seed0=cv.SEED0))


def test_transfer_is_one_for_the_true_model_and_zero_for_the_nominal(tmp_path):
    """Check (d)'s arithmetic on a 120 s parameter-error case: on the second log (another sea), the true
    model's own file (the nominal with the planted values) carries the true model's gap closure, the
    nominal file none; the true model's own gap gives exactly 1, the nominal's exactly 0 (an unchanged
    file scores its 0); a no-effect truth and a log the true model does not improve give no transfer."""
    from heavecomp.benchmark import benchmark_case, generate
    from heavecomp.report.provenance import write_params

    cv = _scenario()
    case = benchmark_case("parameter_mismatch", seed=7, duration=120.0)
    first, other = generate(case, other_sea=True)
    planted = first.truth["parameters"]["parameter_mismatch"]
    changes = {}
    for path, value in planted.items():
        table, key = path.split(".")
        changes.setdefault(table, {})[key] = value
    nom = write_params(tmp_path, first.nominal, "nominal.toml")
    true = write_params(tmp_path, first.nominal.replace(**changes), "true.toml")
    ch = max(("wob", "stroke", "pressure"), key=lambda c: first.truth["gap_channels"]["parameter_mismatch"][c])
    tf = cv.other_sea_gaps(other, nom, true, ch, tmp_path)
    g = tf["gap_to_noise_validate"]
    assert tf["sea"] != tf["first_sea"] and not tf["unchanged"] and not tf["truth_none"]
    assert g["nominal"] > 2 * g["true"], g  # the planted error shows on the other sea
    # by the definition's arithmetic
    assert cv.transfer(g["nominal"], g["true"], g["true"]) == 1.0
    assert cv.transfer(g["nominal"], g["nominal"], g["true"]) == 0.0
    assert cv.transfer(g["true"], g["true"], g["nominal"]) is None
    # the true model's own file, replayed as the diagnosis replays, closes the gap the generator's truth does
    assert abs(cv.transfer(g["nominal"], g["calibrated"], g["true"]) - 1.0) < 0.01, g
    # the nominal file replayed as calibrated: the same replay, transfer 0 exactly
    same = cv.other_sea_gaps(other, nom, nom, ch, tmp_path)
    assert same["unchanged"] and cv.rescore({"transfer": same})["transfer"]["transfer"] == 0.0
    assert cv.rescore({"transfer": dict(same, truth_none=True)})["transfer"]["transfer"] is None


def test_the_summary_scores_transfer_median_and_least_against_the_goals():
    """The two transfer goals read the right verdicts' transfers (a no-effect truth's left out and
    counted); a metrics.json from before the check reads 'not measured', never FAIL."""
    cv = _scenario()

    def row(g, none=False):
        tf = {"gap_to_noise_validate": dict(zip(("nominal", "calibrated", "true"), g)), "truth_none": none}
        return {"label": "x", "seed": 0, "judged": {"right": True}, "full": {"verdict": "flow_loss"},
                "checks": cv.rescore({"transfer": tf})}

    rows = [row((10.0, 1.9, 1.0)), row((10.0, 1.0, 1.0)), row((5.0, 3.0, 1.0)), row((3.0, 3.0, 3.0), True)]
    s = cv.summarize(rows)
    assert s["transfer"]["n"] == 3 and s["transfer"]["n_right_without"] == 1
    assert s["transfer"]["median"] == pytest.approx(0.9) and s["transfer"]["min"] == 0.5
    goals = {g["goal"].split(" (")[0]: g["result"] for g in s["goals"]}
    assert goals["median transfer to another sea >= 0.85"] == "PASS"
    assert goals["no transfer to another sea under 0.6"] == "FAIL"
    old = cv.summarize([dict(r, checks={k: v for k, v in r["checks"].items() if k != "transfer"}) for r in rows])
    assert old["transfer"]["not_measured"] and {g["result"] for g in old["goals"][-2:]} == {"not measured"}
