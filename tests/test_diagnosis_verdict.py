"""Verdicts end to end: the quick withheld-effect benchmark (the benchmark's run_benchmark; the tuning
and scoring sets of scenarios/diagnosis_validation.py are the full benchmark), the CLI on a generated run with
dropouts and jittered sampling, and the Python API's contract fields."""

import json
import math
import runpy
from pathlib import Path

import pytest

from _cli import run as run_cli  # in this process: these tests check what the command writes

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_withheld_effects_quick(tmp_path):
    from heavecomp.benchmark.run import run_benchmark

    rows, summary = run_benchmark(quick=True)
    m = {"runs": rows, "summary": summary}
    runs = {x["truth"]: x for x in m["runs"]}
    # no effect -> the gap is at the noise floor
    assert runs["none"]["verdict"] == "none"
    # a withheld dwell stiction is planted where the compensator sticks, well above the noise floor,
    # and the diagnosis sees a gap there (not `none`)
    dw = runs["dwell_stiction"]
    assert dw["planted_gap"]["dwell_stiction"] >= 3.0 and dw["stuck_share"] >= 0.15
    assert dw["verdict"] != "none" and dw["gap_to_noise"] > 1.2
    # a withheld orifice loss is named and the held-out gap really shrinks
    assert runs["flow_loss"]["verdict"] == "flow_loss"
    assert runs["flow_loss"]["shrink"] > 0.2
    # the laminar candidate's resistance is the orifice's equivalent at the run's stroke velocity:
    # describing function of K v|v| at amplitude V is 8 K V / (3 pi); V ~ heave velocity pi Hs / Tp
    fl = runs["flow_loss"]
    V = math.pi * fl["sea"]["hs"] / fl["sea"]["tp"]
    r_eq = 8.0 * fl["truth_parameters"]["flow_loss"]["K"] * V / (3.0 * math.pi)
    assert 0.5 * r_eq < fl["fitted_parameters"]["resistance"] < 2.0 * r_eq
    from heavecomp.report.diagnosis import fig_confusion
    from heavecomp.report.figures import save

    save(fig_confusion(summary), tmp_path / "confusion.png", dpi=90)
    assert (tmp_path / "confusion.png").stat().st_size > 5000


@pytest.mark.slow
def test_cli_diagnose_contract_json(tmp_path):
    from heavecomp.benchmark import benchmark_case, corrupt, generate
    from heavecomp.params import dumps

    tr = corrupt(generate(benchmark_case("sensor_delay", seed=5, duration=90.0)), jitter=True, dropouts=True)
    f = tr.to_csv(tmp_path / "run.csv")
    toml = tmp_path / "nom.toml"
    toml.write_text(dumps(tr.nominal))
    r = run_cli("diagnose", str(f), "--params", str(toml), "--out",
                str(tmp_path / "out"), "--candidates", "sensor_delay,flow_loss,string_damping")
    assert r.returncode == 0, r.stderr[-2000:]
    d = json.loads((tmp_path / "out" / "diagnosis.json").read_text())
    assert d["schema"] == 4
    v = d["verdict"]
    # schema 3: the sensor set and what it can tell apart; a named verdict carries its group
    assert d["sensors"] == ["heave", "stroke", "pressure", "wob"]
    assert set(d["isolability"]) >= {"detectable", "groups"}
    if v["effect"] not in ("none", "inconclusive", "discovered"):
        sg = v["structural_group"]
        assert any(set(sg) == set(g) for g in d["isolability"]["groups"]) or sg == [v["effect"]]
        # schema 4: the group this log cannot split, led by the verdict, with its test and what would split it
        assert v["group"][0] == v["effect"] and len(v["group"]) <= 3
        assert v["distinguishable"]["false_alarm_rate"] == 0.01 and isinstance(v["separate_by"], list)
    # schema 2: where the gap lives by model component, the start state, warnings
    comps = d["gap"]["where"]["components"]
    assert set(comps) == {"friction", "gas_spring", "flow_line", "string_formation", "sensors", "heave_input"}
    assert v["component"] == "sensors" and {"stroke", "stroke_velocity"} <= set(d["initial_state"])
    assert isinstance(d["warnings"], list)
    assert {"effect", "confidence", "parameters", "shrink"} <= set(v)
    assert v["confidence"] in ("high", "medium", "low")
    # the lagged channel is found and the delay is of the order of the generated sensor lag
    lag = tr.truth["parameters"]["sensor_delay"]
    assert v["effect"] == "sensor_delay" and v["parameters"]["channel"] == lag["channel"]
    assert 0.5 * lag["lag_time"] < v["parameters"]["delay"] < 1.5 * lag["lag_time"]
    assert v["shrink"] > 0.3
    g = d["gap"]
    assert set(g["channels"]) == {"wob", "stroke", "pressure"}
    assert all({"rms", "nrmse"} <= set(g["channels"][c]) for c in g["channels"])
    assert set(g["where"]["regimes"]) == {"stuck", "breakaway", "sliding_accelerating", "sliding_decelerating"}
    assert set(g["where"]["bands"]) == {"below_wave", "wave", "resonance", "above"}
    assert sum(g["where"]["bands"].values()) == pytest.approx(1.0, abs=0.02)
    assert [c["score"] for c in d["candidates"]] == sorted((c["score"] for c in d["candidates"]), reverse=True)
    for c in d["candidates"]:
        assert {"effect", "parameters", "rms_before", "rms_after", "shrink", "score"} <= set(c)
    assert d["split"]["fit"][1] == pytest.approx(d["split"]["validate"][0])
    assert any("non-uniform" in w for w in d["warnings"]) and any("missing" in w for w in d["warnings"])
    for name in ("report.md", "where.png", "spectra.png", "overlay.png"):
        assert (tmp_path / "out" / name).is_file()


@pytest.mark.slow
def test_diagnosis_example_scenario_quick(tmp_path):
    """Withheld quadratic string drag: the linear-dashpot candidate fits a positive damping that
    shrinks the held-out WOB residual, and the report files are written."""
    main = runpy.run_path(str(ROOT / "scenarios" / "diagnosis_example.py"), run_name="scenario")["main"]
    assert main(["--quick", "--out", str(tmp_path)]) == 0  # in this process: the script's own work only
    m = json.loads((tmp_path / "metrics.json").read_text())
    sd = next(c for c in m["candidates"] if c["effect"] == "string_damping")
    assert sd["parameters"]["damping"] > 1e3
    assert sd["channels"]["wob"]["rms_after"] < sd["channels"]["wob"]["rms_before"]
    assert m["verdict"]["effect"] == "string_damping"
    d = json.loads((tmp_path / "diagnosis.json").read_text())
    assert d["schema"] == 4 and (tmp_path / "overlay.png").is_file()
    assert d["verdict"]["component"] == "string_formation" and "components" in d["gap"]["where"]
    # a re-run leaves git clean: the fit wall times are in the untracked timings.json only
    assert "wall" not in json.dumps({k: v for k, v in d.items() if k != "units"})
    t = json.loads((tmp_path / "timings.json").read_text())["diagnosis.json"]
    assert all(c["fit_wall_time"] > 0 for c in t["candidates"])
