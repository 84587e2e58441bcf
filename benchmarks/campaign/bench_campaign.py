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


def peer_loop(camp, n: int) -> tuple[float, float]:
    """(wall, CPU) seconds per run of heavecomp.simulate.simulate() in a plain loop (n runs spread over the grid)."""
    from heavecomp.simulate import simulate

    runs = camp.runs()
    pick = [runs[i] for i in np.linspace(0, len(runs) - 1, n).astype(int)]
    simulate(camp.params_for(pick[0]), 10.0)  # compile / load cache
    t0, c0 = time.perf_counter(), time.process_time()
    for r in pick:
        res = simulate(camp.params_for(r), camp.settings.duration)
        res.metrics()
    return (time.perf_counter() - t0) / n, (time.process_time() - c0) / n


def _children_cpu() -> float:
    import resource

    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def local(camp, workers: int) -> tuple[float, float]:
    """(wall, CPU of all processes) seconds for the whole campaign, pool start-up included."""
    from heavecomp.campaign.execute import run_campaign

    with tempfile.TemporaryDirectory() as d:
        t0, c0, k0 = time.perf_counter(), time.process_time(), _children_cpu()
        info = run_campaign(camp, d, workers=workers)
        wall = time.perf_counter() - t0
        cpu = time.process_time() - c0 + _children_cpu() - k0
        assert info.complete
    return wall, cpu


def _worker_cpu() -> float:
    return time.process_time()


def dask_scaling(camp, n_workers: int) -> tuple[float, float]:
    """(wall, CPU summed over the workers) seconds for the campaign on a local loopback cluster."""
    import dataclasses

    from distributed import Client, LocalCluster

    from heavecomp.campaign.execute import run_campaign

    warm = dataclasses.replace(camp, settings=dataclasses.replace(camp.settings, duration=20.0))
    with LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None) as cluster, Client(cluster) as client:
        with tempfile.TemporaryDirectory() as d:  # warm-up: imports + numba cache on every worker
            run_campaign(warm, Path(d) / "w", client=client)
            c0 = sum(client.run(_worker_cpu).values())
            t0 = time.perf_counter()
            info = run_campaign(camp, Path(d) / "r", client=client)
            wall = time.perf_counter() - t0
            cpu = sum(client.run(_worker_cpu).values()) - c0
        assert info.complete and info.workers == n_workers
    return wall, cpu


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n-states", type=int, default=1000)
    ap.add_argument("--duration", type=float, default=600.0)
    ap.add_argument("--regime", default="stribeck")
    ap.add_argument("--peer-runs", type=int, default=100)
    ap.add_argument("--dask-runs", type=int, default=200)
    ap.add_argument("--dask-repeats", type=int, default=2)
    ap.add_argument("--workers", type=int, default=os.cpu_count())
    ap.add_argument("--json", default=str(HERE / "results.json"))
    a = ap.parse_args(argv)
    camp = grid_campaign(a.n_states, a.duration, a.regime, 8)
    out = {"machine_cores": os.cpu_count(), "n_states": a.n_states, "duration_s": a.duration, "regime": a.regime,
           "load_avg_before": os.getloadavg()}
    wall, cpu = local(camp, a.workers)
    out.update(campaign_wall_s=wall, campaign_cpu_s=cpu, campaign_workers=a.workers,
               campaign_cpu_ms_per_run=1e3 * cpu / a.n_states)
    print(f"campaign: {a.n_states} sea states x {a.duration:g} s ({a.regime}) on {a.workers} processes: "
          f"wall {wall:.1f} s, CPU {cpu:.1f} s ({1e3 * cpu / a.n_states:.1f} ms/run)")
    per, per_cpu = peer_loop(camp, a.peer_runs)
    out.update(peer_s_per_run=per, peer_cpu_s_per_run=per_cpu, peer_runs_timed=a.peer_runs,
               peer_extrapolated_s=per * a.n_states,
               ratio_wall=per * a.n_states / wall,
               ratio_cpu_per_run=per_cpu * a.n_states / cpu)
    print(f"peer simulate() loop: wall {per * 1e3:.1f} ms/run, CPU {per_cpu * 1e3:.1f} ms/run ({a.peer_runs} runs timed)"
          f" -> {per * a.n_states:.1f} s for {a.n_states}; wall ratio {out['ratio_wall']:.2f}x, "
          f"CPU-per-run ratio {out['ratio_cpu_per_run']:.2f}x")
    if a.dask_runs:
        dc = grid_campaign(a.dask_runs, a.duration, a.regime, 4)
        res = {1: [], 2: []}
        for _ in range(a.dask_repeats):  # interleaved; the minimum is the least disturbed by other load
            for nw in (1, 2):
                res[nw].append(dask_scaling(dc, nw))
        best = {nw: min(v) for nw, v in res.items()}
        out.update(dask_runs=a.dask_runs, dask_wall_cpu_1_worker=res[1], dask_wall_cpu_2_workers=res[2],
                   dask_speedup_2_over_1=best[1][0] / best[2][0],
                   dask_cores_used={nw: best[nw][1] / best[nw][0] for nw in best},
                   dask_cpu_ms_per_run={nw: 1e3 * best[nw][1] / a.dask_runs for nw in best})
        print(f"dask local cluster, {a.dask_runs} runs: 1 worker {best[1][0]:.1f} s wall ({best[1][1] / best[1][0]:.2f} "
              f"cores busy), 2 workers {best[2][0]:.1f} s wall ({best[2][1] / best[2][0]:.2f} cores busy); "
              f"speed-up {best[1][0] / best[2][0]:.2f} (min of {a.dask_repeats})")
    out["campaign_projection_idle_s"] = cpu / a.workers
    out["load_avg_after"] = os.getloadavg()
    Path(a.json).write_text(json.dumps(out, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
