"""The monitor's gap level where it must read about 1, and where it must stand out (issue 31 item 4).

    python benchmarks/monitor/gap_levels.py [--seeds 2] [--quick] [--out benchmarks/monitor/result_gap_levels.json]

A. no-effect logs (the project's generator, ``heavecomp.benchmark.long_logs.long_log``: JONSWAP sea, the
   generator's noise) at 5, 10, 25 and 50 Hz, 10 min and 2 h: every segment's gap/noise per component
   (goal: all within [0.7, 1.5]) and the changes raised (none expected);
B. a 130 s log at 10 Hz with a 30 kN WOB step at 104 s (a load cell that steps): found, and the note of
   the shortened reference;
C. a fleet of four nominal logs and one whose seal friction (static and Coulomb levels) is 30 % high
   from start to end (20 min at 10 Hz each, ``simulate`` plus the generator's noise): the ranking by gap
   level and the diagnose command the report ends in.

``--quick``: 10-min logs only in A, one seed.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from heavecomp.benchmark.long_logs import long_log
from heavecomp.diagnosis import monitor as M
from heavecomp.diagnosis.data import MeasuredRun

HERE = Path(__file__).resolve().parent
RATES = (5.0, 10.0, 25.0, 50.0)
DURATIONS = (600.0, 7200.0)
NOISE = (("heave", 2e-3), ("stroke", 2e-3), ("pressure", 2e3), ("wob", 400.0))  # as the generator's logs


def no_effect(seeds, durations):
    rows = []
    for dur in durations:
        for rate in RATES:
            for seed in seeds:
                tr = long_log([], seed=seed, duration=dur, rate=rate)
                t0 = time.perf_counter()
                res = M.monitor(tr.to_run(), tr.nominal)
                wall = time.perf_counter() - t0
                gaps = [g for s in res.segments for g in s["gap_to_noise"].values()]
                worst = max(((c, g) for s in res.segments for c, g in s["gap_to_noise"].items()), key=lambda x: x[1])
                rows.append({"duration_s": dur, "rate_hz": rate, "seed": seed, "min": min(gaps), "max": max(gaps),
                             "max_component": worst[0], "changes": len(res.changes), "segments": len(res.segments),
                             "gap_level": res.gap_level()["gap_to_noise"], "monitor_wall_s": round(wall, 2),
                             "within": bool(all(0.7 <= g <= 1.5 for g in gaps))})
                print(f"A {dur:6.0f} s {rate:4.0f} Hz seed {seed}: gap/noise {min(gaps):.2f}..{max(gaps):.2f} "
                      f"(max {worst[0]}), {len(res.changes)} change(s), monitor {wall:.1f} s", flush=True)
    return rows


def wob_step(seeds):
    rows = []
    for seed in seeds:
        tr = long_log([], seed=seed, duration=130.0, rate=10.0)
        run = tr.to_run()
        cols = dict(run.columns)
        cols["wob"] = np.where(run.t >= 104.0, cols["wob"] + 3e4, cols["wob"])
        res = M.monitor(MeasuredRun(run.t, cols, source="130 s, 30 kN WOB step at 104 s"), tr.nominal)
        eff = [c for c in res.changes if c["kind"] == "effect"]
        rows.append({"seed": seed, "changes": [{k: c[k] for k in ("t", "onset", "component", "size_to_noise")}
                                               for c in res.changes],
                     "found": bool(eff and eff[0]["t"] >= 100.0), "notes": res.notes, "learn_blocks": res.learn})
        print(f"B seed {seed}: " + ("; ".join(f"{c['component']} at {c['t']:.0f} s (onset {c['onset']:.0f} s, "
                                              f"{c['size_to_noise']:.0f} sigma)" for c in res.changes) or "nothing")
              + f"; reference {res.learn} blocks", flush=True)
    return rows


def _friction_log(path, nominal, scale, seed, duration, rate=10.0):
    from heavecomp.simulate import simulate

    f = nominal.friction
    p = nominal.replace(friction={"static_force": scale * f.static_force, "coulomb_force": scale * f.coulomb_force})
    r = simulate(p, duration, rate=rate)
    rng = np.random.default_rng(seed)
    t = np.asarray(r["t"], float)
    cols = [t] + [np.asarray(r[k], float) + rng.normal(0.0, s, t.size) for k, s in NOISE]
    np.savetxt(path, np.column_stack(cols), delimiter=",", header="t,heave,stroke,pressure,wob", comments="",
               fmt="%.10g")


def fleet(duration):
    from heavecomp.campaign import fleet as F
    from heavecomp.params import save
    from heavecomp.params.sets import paper_a
    from heavecomp.report.fleet import run_and_report

    nominal = paper_a("stribeck")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        (tmp / "logs").mkdir()
        for i, scale in enumerate((1.0, 1.0, 1.3, 1.0, 1.0)):
            _friction_log(tmp / "logs" / f"rig{i}{'_friction130' if scale != 1.0 else ''}.csv", nominal, scale,
                          seed=i, duration=duration)
        prm = save(nominal, tmp / "p.toml")
        _, summary = run_and_report(F.plan(tmp / "logs", prm), tmp / "f", F.Settings(), workers=1,
                                    final_out=tmp / "f")
        with open(tmp / "f" / "fleet.csv", newline="") as fh:
            rows = sorted(csv.DictReader(fh), key=lambda r: int(r["gap rank [-]"]))
        out = [{k: r[k] for k in ("gap rank [-]", "log", "gap level [-]", "gap component", "friction gap/noise [-]",
                                  "effect changes [-]")} for r in rows]
        for r in out:
            print("C", r, flush=True)
        cmds = [c.replace(str(tmp), "<tmp>") for c in summary["what_next"]]
        print("C what next:", cmds, flush=True)
        return {"ranking": out, "what_next": cmds}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=2, help="seeds per rate and length (A) and of B")
    ap.add_argument("--quick", action="store_true", help="10-min logs only, one seed")
    ap.add_argument("--fleet-duration", type=float, default=1200.0, help="length of each fleet log [s] (C)")
    ap.add_argument("--out", default=str(HERE / "result_gap_levels.json"))
    a = ap.parse_args(argv)
    seeds = list(range(710001, 710001 + (1 if a.quick else a.seeds)))
    t0 = time.perf_counter()
    result = {"no_effect": no_effect(seeds, DURATIONS[:1] if a.quick else DURATIONS), "wob_step_130s": wob_step(seeds),
              "fleet": fleet(a.fleet_duration)}
    result["all_within"] = all(r["within"] for r in result["no_effect"])
    result["wall_s"] = round(time.perf_counter() - t0, 1)
    Path(a.out).write_text(json.dumps(result, indent=2) + "\n")
    print(f"no-effect logs all within [0.7, 1.5]: {result['all_within']}; {result['wall_s']} s -> {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
