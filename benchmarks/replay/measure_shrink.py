"""The diagnosis' reported shrink against the shrink ``replay`` and ``simulate --heave-file`` give with its
``calibrated.toml`` (issue 31), and one calibrated model checked on a second log of the same truth plant in
another sea.

    nice -n 5 python benchmarks/replay/measure_shrink.py [--out DIR] [--seed0 700000] [--duration 300] [--rate 25]

Part 1: five logs of the benchmark generator (``heavecomp.benchmark``, fresh seeds ``--seed0`` + i; not
added to ``heavecomp.benchmark.seeds.SPENT``: nothing is scored or tuned on them), each with one planted
effect.  For each: ``heavecomp diagnose`` (``--jobs 1``), then ``heavecomp replay LOG --params nominal
--params calibrated`` and ``heavecomp simulate FILE --heave-file LOG`` with each file; the shrink of each is
1 - held-out WOB rms with calibrated.toml / with the nominal.

Part 2: the truth plant of a user's rig (the nominal's seal friction, static and Coulomb, x 1.3) logged in
two seas (JONSWAP H_s 2 m, T_p 10 s and H_s 3 m, T_p 13 s, other phases); the first log is diagnosed and
its ``calibrated.toml`` replayed on the second next to the nominal: gap/noise before and after.

Every command runs as a user's: ``python -m heavecomp ...`` in a fresh process, one at a time.  Writes
``DIR/results.json`` and prints a table.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))  # this tree's heavecomp, not an installed one
LABELS = ("string_damping", "pressure_friction", "flow_loss", "parameter_mismatch", "sensor_gain")
#: the two seas of part 2 (JONSWAP)
SEAS = ({"hs": 2.0, "tp": 10.0}, {"hs": 3.0, "tp": 13.0})


def heavecomp(*args) -> str:
    """``python -m heavecomp ARGS`` from this tree, as a user runs it; its stdout (exit 0 required)."""
    r = subprocess.run([sys.executable, "-m", "heavecomp", *map(str, args)], cwd=ROOT, capture_output=True,
                       text=True, env={**os.environ, "PYTHONPATH": str(ROOT)})
    if r.returncode:
        raise RuntimeError(f"heavecomp {' '.join(map(str, args))}: exit {r.returncode}: {r.stderr.strip()[-400:]}")
    return r.stdout


def check(log: Path, nominal: Path, out: Path, rate: float) -> dict:
    """Diagnose ``log``; the calibrated file's shrink as the diagnosis reports it, as replay and simulate give it."""
    diag = out / "diag"
    heavecomp("diagnose", log, "--params", nominal, "--out", diag, "--jobs", 1, "--quiet")
    d = json.loads((diag / "diagnosis.json").read_text())
    cal = diag / "calibrated.toml"
    heavecomp("replay", log, "--params", nominal, "--params", cal, "--out", out / "replay", "--quiet")
    rep = json.loads((out / "replay" / "replay.json").read_text())
    dur = math.floor(json.loads((out / "replay" / "replay.json").read_text())["span"]["duration_s"])
    sim = {}
    for name, f in (("nominal", nominal), ("calibrated", cal)):
        heavecomp("simulate", f, "--heave-file", log, "--duration", dur, "--rate", rate, "--out", out / f"sim_{name}",
                  "--quiet")
        sim[name] = json.loads((out / f"sim_{name}" / "metrics.json").read_text())["against_log"]
    ch = d["verdict"].get("shrink_channel", "wob")
    s_nom, s_cal = sim["nominal"]["rms_validate"][ch], sim["calibrated"]["rms_validate"][ch]
    m_nom, m_cal = rep["models"]
    return {"verdict": d["verdict"]["effect"], "confidence": d["verdict"]["confidence"], "channel": ch,
            "reported": d.get("calibrated", {}).get("expected_shrink", d["verdict"]["shrink"]),
            "verdict_shrink": d["verdict"]["shrink"],
            "diagnosis_rms_validate": d["gap"]["channels"][ch]["rms_validate"],
            "replay": {"shrink": m_cal["shrink_validate"], "rms_validate": [m_nom["rms_validate"][ch],
                                                                             m_cal["rms_validate"][ch]],
                       "gap_to_noise_validate": [m_nom["gap_to_noise_validate"][ch],
                                                 m_cal["gap_to_noise_validate"][ch]]},
            "simulate": {"shrink": 1.0 - s_cal / s_nom if s_nom > 0 else 0.0, "rms_validate": [s_nom, s_cal]}}


def generated(label: str, seed: int, duration: float, rate: float, out: Path) -> tuple:
    from heavecomp.benchmark import benchmark_case, generate
    from heavecomp.params import dumps

    tr = generate(benchmark_case(label, seed=seed, duration=duration, rate=rate))
    out.mkdir(parents=True, exist_ok=True)
    (out / "nominal.toml").write_text(dumps(tr.nominal))
    return tr.to_csv(out / "run.csv"), out / "nominal.toml", tr.truth["parameters"]


def sea_log(truth, sea: dict, seed: int, duration: float, rate: float, path: Path) -> Path:
    """The truth plant simulated in ``sea`` (JONSWAP, phases from ``seed``) with the benchmark's sensor noise."""
    from heavecomp.benchmark.testbed import NOISE
    from heavecomp.simulate import simulate

    p = truth.replace(heave={"kind": "jonswap", "hs": sea["hs"], "tp": sea["tp"], "seed": seed, "ramp": 20.0,
                             "amplitude": None, "period": None, "path": None})
    res = simulate(p, duration, rate=rate)
    rng = np.random.default_rng(seed)
    t = np.asarray(res["t"], float)
    cols = {c: np.asarray(res[c], float) + rng.normal(0.0, NOISE[c], t.size) for c in ("heave", "stroke", "pressure", "wob")}
    np.savetxt(path, np.column_stack([t] + list(cols.values())), delimiter=",", header="t,heave,stroke,pressure,wob",
               comments="", fmt="%.10g")
    return path


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "replay" / "run"), help="scratch folder")
    ap.add_argument("--seed0", type=int, default=700000)
    ap.add_argument("--duration", type=float, default=300.0)
    ap.add_argument("--rate", type=float, default=25.0)
    ap.add_argument("--only", default=None, help="part1 or part2")
    a = ap.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    res_path = out / "results.json"
    results = json.loads(res_path.read_text()) if res_path.exists() else {}
    if a.only in (None, "part1"):
        rows = results.setdefault("part1", {})
        for i, lab in enumerate(LABELS):
            key = f"{lab}:{a.seed0 + i}"
            if key in rows:
                continue
            where = out / f"{lab}_{a.seed0 + i}"
            log, nom, planted = generated(lab, a.seed0 + i, a.duration, a.rate, where)
            rows[key] = dict(check(log, nom, where, a.rate), planted=planted)
            res_path.write_text(json.dumps(results, indent=2) + "\n")
            r = rows[key]
            print(f"{key}: verdict {r['verdict']} ({r['confidence']}); shrink reported {r['reported']:.3f}, "
                  f"replay {r['replay']['shrink']:.3f}, simulate {r['simulate']['shrink']:.3f}", flush=True)
    if a.only in (None, "part2"):
        from heavecomp.effects.spec import load
        from heavecomp.params import dumps, paper_a

        where = out / "second_sea"
        where.mkdir(parents=True, exist_ok=True)
        nominal = paper_a().replace(heave={"kind": "jonswap", "hs": 2.0, "tp": 10.0, "seed": a.seed0 + 100,
                                           "ramp": 20.0, "amplitude": None, "period": None})
        (where / "nominal.toml").write_text(dumps(nominal))
        p = load(where / "nominal.toml")
        truth = p.replace(friction={"static_force": 1.3 * p.friction.static_force,
                                    "coulomb_force": 1.3 * p.friction.coulomb_force})
        logs = [sea_log(truth, s, a.seed0 + 100 + k, a.duration, a.rate, where / f"sea{k + 1}.csv")
                for k, s in enumerate(SEAS)]
        first = check(logs[0], where / "nominal.toml", where / "sea1", a.rate)
        heavecomp("replay", logs[1], "--params", where / "nominal.toml", "--params", where / "sea1" / "diag" /
                  "calibrated.toml", "--out", where / "sea2_replay", "--quiet")
        rep = json.loads((where / "sea2_replay" / "replay.json").read_text())
        results["part2"] = {"seas": list(SEAS), "first_log": first,
                            "second_log": {k: {"params": m["params"], "gap_to_noise_validate": m["gap_to_noise_validate"],
                                               "gap_to_noise": m["gap_to_noise"], "rms_validate": m["rms_validate"],
                                               "shrink_validate": m["shrink_validate"]}
                                           for k, m in zip(("nominal", "calibrated"), rep["models"])}}
        res_path.write_text(json.dumps(results, indent=2) + "\n")
        print(json.dumps(results["part2"]["second_log"], indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
