"""Campaign throughput: 1000 sea states x 600 s on this machine, against the single-run simulator in a loop,
and the speed-up with 1 -> 2 Dask workers on a local (loopback) cluster.

    python benchmarks/campaign/bench_campaign.py [--n-states 1000] [--peer-runs 100] [--dask-runs 200]

Writes benchmarks/campaign/results.json (or --json PATH).  See README.md.
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def grid_campaign(n_states: int, duration: float, regime: str, chunk: int):
    """n_states sea states on an H_s x T_p grid (equal probabilities), one seed, one regime."""
    from heavecomp.campaign import spec

    n_tp = 25 if n_states >= 100 else max(1, n_states // 4)
    n_hs = int(np.ceil(n_states / n_tp))
    hs = np.round(np.linspace(0.2, 2.0, n_hs), 4)
    tp = np.round(np.linspace(6.0, 18.0, n_tp), 4)
    P = np.zeros((n_hs, n_tp))
    P.flat[:n_states] = 1.0
    P /= P.sum()
    rows = ",\n".join("[" + ", ".join(repr(float(x)) for x in r) + "]" for r in P)
    text = f"""
[campaign]
name = "bench"
duration = {duration}
seeds = 1
regimes = ["{regime}"]
chunk_size = {chunk}
[scatter]
hs = [{", ".join(map(str, hs))}]
tp = [{", ".join(map(str, tp))}]
probability = [{rows}]
[band]
tolerance = 20e3
[outputs]
figures = false
"""
    camp = spec.loads(text)
    assert len(camp.runs()) == n_states, len(camp.runs())
    return camp


def peer_loop(camp, n: int) -> float:
    """Seconds per run of heavecomp.simulate.simulate() in a plain loop (n runs spread over the grid)."""
    from heavecomp.simulate import simulate

    runs = camp.runs()
    pick = [runs[i] for i in np.linspace(0, len(runs) - 1, n).astype(int)]
    simulate(camp.params_for(pick[0]), 10.0)  # compile / load cache
    t0 = time.perf_counter()
    for r in pick:
        res = simulate(camp.params_for(r), camp.settings.duration)
        res.metrics()
    return (time.perf_counter() - t0) / n


def local(camp, workers: int) -> float:
    from heavecomp.campaign.execute import run_campaign

    with tempfile.TemporaryDirectory() as d:
        t0 = time.perf_counter()
        info = run_campaign(camp, d, workers=workers)
        wall = time.perf_counter() - t0
        assert info.complete
    return wall


def dask_scaling(camp, n_workers: int) -> float:
    import dataclasses

    from distributed import LocalCluster

    from heavecomp.campaign.execute import run_campaign

    warm = dataclasses.replace(camp, settings=dataclasses.replace(camp.settings, duration=20.0))
    with LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None) as cluster:
        with tempfile.TemporaryDirectory() as d:  # warm-up: imports + numba cache on every worker
            run_campaign(warm, Path(d) / "w", scheduler=cluster.scheduler_address)
            t0 = time.perf_counter()
            info = run_campaign(camp, Path(d) / "r", scheduler=cluster.scheduler_address)
            wall = time.perf_counter() - t0
        assert info.complete and info.workers == n_workers
    return wall


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n-states", type=int, default=1000)
    ap.add_argument("--duration", type=float, default=600.0)
    ap.add_argument("--regime", default="stribeck")
    ap.add_argument("--peer-runs", type=int, default=100)
    ap.add_argument("--dask-runs", type=int, default=200)
    ap.add_argument("--workers", type=int, default=os.cpu_count())
    ap.add_argument("--json", default=str(HERE / "results.json"))
    a = ap.parse_args(argv)
    camp = grid_campaign(a.n_states, a.duration, a.regime, 8)
    out = {"machine_cores": os.cpu_count(), "n_states": a.n_states, "duration_s": a.duration, "regime": a.regime,
           "load_avg_before": os.getloadavg()}
    wall = local(camp, a.workers)
    out["campaign_wall_s"] = wall
    out["campaign_workers"] = a.workers
    print(f"campaign: {a.n_states} sea states x {a.duration:g} s ({a.regime}) on {a.workers} processes: {wall:.1f} s")
    per = peer_loop(camp, a.peer_runs)
    out["peer_s_per_run"] = per
    out["peer_runs_timed"] = a.peer_runs
    out["peer_extrapolated_s"] = per * a.n_states
    out["speedup_vs_simulate_loop"] = per * a.n_states / wall
    print(f"peer simulate() loop: {per * 1e3:.1f} ms/run ({a.peer_runs} runs timed) -> {per * a.n_states:.1f} s for "
          f"{a.n_states}; ratio {out['speedup_vs_simulate_loop']:.2f}x")
    if a.dask_runs:
        dc = grid_campaign(a.dask_runs, a.duration, a.regime, 4)
        t1 = dask_scaling(dc, 1)
        t2 = dask_scaling(dc, 2)
        out.update(dask_runs=a.dask_runs, dask_1_worker_s=t1, dask_2_workers_s=t2, dask_speedup_2_over_1=t1 / t2)
        print(f"dask local cluster, {a.dask_runs} runs: 1 worker {t1:.1f} s, 2 workers {t2:.1f} s, "
              f"speed-up {t1 / t2:.2f}")
    out["load_avg_after"] = os.getloadavg()
    Path(a.json).write_text(json.dumps(out, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
