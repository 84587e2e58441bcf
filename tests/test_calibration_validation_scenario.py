"""The calibration validation's scoring guards (issue 22): fresh seeds only, frozen diagnosis settings."""

from __future__ import annotations

import importlib.util

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
