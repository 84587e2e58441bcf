"""Speed of the gap diagnosis: a 600 s run at 50 Hz, every candidate, both cores.

Goal (issue 4): <= 120 s on a 2-core machine; issue 12 item 8: <= 10 s (equation-error pre-screen); issue 32:
<= 4 s wall, <= 6 s CPU, <= 200 foundation simulations.  Peer: the foundation's ``simulate()`` of the same
600 s (how many nominal simulations the whole diagnosis costs), as a ratio of wall time, of CPU time and,
deterministic, of the replayed steps (``diagnosis_in_foundation_simulations_count``: every replay's steps,
from the prepared replay's ledger, over the peer's steps).  Usage::

    python benchmarks/diagnosis/bench_600s.py [--effect dwell_stiction] [--jobs 2]

Besides the wall time it records the process CPU time of the diagnosis (all threads) and the
1-minute load average at the end: on a shared machine compare the CPU time and the ratio to the
peer, measured in the same process at the same moment.
"""

from __future__ import annotations

import argparse
import json
import math
import os
from pathlib import Path
import sys
import time


def by_configuration(ledger, peer_steps) -> dict:
    """Replays and their work in foundation simulations per configuration (its effect names joined by
    '+'; 'nominal' for none), costliest first."""
    out = {}
    for _key, n, cost, names in ledger.rows:
        row = out.setdefault("+".join(names) or "nominal", {"replays": 0, "foundation_simulations": 0.0})
        row["replays"] += 1
        row["foundation_simulations"] += n * cost / peer_steps
    return dict(sorted(((k, dict(v, foundation_simulations=round(v["foundation_simulations"], 1)))
                        for k, v in out.items()), key=lambda kv: -kv[1]["foundation_simulations"]))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--effect", default="flow_loss")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--duration", type=float, default=600.0)
    args = ap.parse_args(argv)

    from heavecomp.diagnosis.estimator import GapDiagnoser
    from heavecomp.benchmark import benchmark_case, generate
    from heavecomp.simulate import simulate
    from heavecomp.simulate.core import default_dt

    tr = generate(benchmark_case(args.effect, seed=11, duration=args.duration, rate=50.0))
    run = tr.to_run()
    simulate(tr.nominal, 10.0, rate=50.0)  # compile / load caches outside the timing
    GapDiagnoser(tr.nominal, ["flow_loss"], n_jobs=1, second=0).fit(generate(benchmark_case("none", duration=30.0)).to_run())
    t0, c0 = time.perf_counter(), time.process_time()
    simulate(tr.nominal, args.duration, rate=50.0)
    t_sim, cpu_sim = time.perf_counter() - t0, time.process_time() - c0
    peer_steps = math.ceil(args.duration / default_dt(tr.nominal, 50.0) - 1e-9)
    t0, c0 = time.perf_counter(), time.process_time()
    d = GapDiagnoser(tr.nominal, n_jobs=args.jobs,
                     progress=lambda f, m: print(f"  [{time.perf_counter() - t0:6.1f} s] {m}", file=sys.stderr)).fit(run)
    t_diag, cpu_diag = time.perf_counter() - t0, time.process_time() - c0
    ledger = d.context_.replay.ledger
    out = {"replays": ledger.count, "replayed_steps_plain": ledger.steps, "duplicate_replays":
           sum(n - 1 for n in ledger.duplicates().values()), "foundation_steps": peer_steps,
           # the deterministic count: the diagnosis' replayed work in simulations of the peer (a library-stepper
           # step counts 1.5 plain steps, replay.LIBRARY_STEP_COST)
           "diagnosis_in_foundation_simulations_count": ledger.steps / peer_steps,
           "foundation_simulate_600s_cpu_s": cpu_sim, "diagnosis_cpu_in_foundation_simulations": cpu_diag / cpu_sim,
           "duration_s": args.duration, "rate_hz": 50.0, "n_samples": int(run.t.size), "candidates": len(d.candidates),
           "jobs": args.jobs, "diagnosis_wall_s": t_diag,
           "diagnosis_cpu_s": cpu_diag, "load_average_1min": os.getloadavg()[0], "goal_s": 4.0, "ratio_to_goal": t_diag / 4.0,
           "goal_cpu_s": 6.0, "goal_foundation_simulations": 200,
           "foundation_simulate_600s_wall_s": t_sim, "diagnosis_in_foundation_simulations": t_diag / t_sim,
           "replays_by_configuration": by_configuration(ledger, peer_steps),
           "withheld": args.effect, "verdict": d.verdict_["effect"], "shrink": d.verdict_["shrink"],
           "component": d.verdict_.get("component"), "where_components": d.where_["components"],
           "replayed": [n for n, p in d.prescreen_.items() if p["replay"]],
           "not_replayed": [n for n, p in d.prescreen_.items() if not p["replay"]]}
    text = json.dumps(out, indent=2)
    print(text)
    (Path(__file__).with_name("result_600s.json")).write_text(text + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
