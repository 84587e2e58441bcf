"""Fleet throughput: ``heavecomp fleet`` on a folder of generated logs, 1 worker against 2 Dask workers.

    python benchmarks/fleet/bench_fleet.py                      # 20 logs of 1-2 h at 10 Hz, in /tmp
    python benchmarks/fleet/bench_fleet.py --logs 4 --hours 0.3 # smoke

1. Generates ``--logs`` logs (once; kept in ``--data``, not in the repository) with
   :func:`heavecomp.benchmark.long_logs.long_log`: durations spread over 1-2 h at 10 Hz, every other log
   with one planted change (pressure friction, gas leak, softer formation, a new WOB set-point, a WOB
   channel that misreads) at 40-60 % of the log, the others without any.
2. Runs the command a user runs, in a fresh interpreter, timed from start to exit (reading, checks,
   monitoring, report):
   - ``heavecomp fleet DIR --params P --out OUT --workers 1`` (in this process);
   - ``heavecomp fleet DIR --params P --out OUT --scheduler ADDRESS`` on a ``distributed.LocalCluster`` of
     2 worker processes, 1 thread each, started and warmed up (each worker monitors the shortest log
     once: imports, numba cache) before the clock starts, as a cluster that is already running;
   - ``--workers 2`` (local spawn processes) for comparison.
   Each run writes a new folder (no resume); the fleet's ``fleet.csv`` must be the same for all.
   ``--repeats`` rounds of the three, interleaved; the minimum wall time of each is kept.
3. Writes ``results.json`` to ``--data`` and prints a Markdown table and the load average (``uptime``).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

#: planted change of the logs with one (cycled), label of heavecomp.benchmark.long_logs
CHANGES = ("pressure_friction", "gas_leak", "formation", "operating", "sensor_gain")


def generate(data: Path, n: int, hours: float) -> Path:
    """``n`` logs in ``data/logs`` (skipped when there), the nominal parameter file ``data/p.toml``."""
    import numpy as np

    from heavecomp.benchmark.long_logs import long_log
    from heavecomp.params import dumps

    logs = data / "logs"
    logs.mkdir(parents=True, exist_ok=True)
    truth = {}
    for i in range(n):
        seed = 250000 + i
        rng = np.random.default_rng(seed)
        dur = 3600.0 * hours * (1.0 + i / max(1, n - 1))  # hours .. 2 x hours
        changes = [] if i % 2 == 0 else [(float(rng.uniform(0.4, 0.6)) * dur, CHANGES[(i // 2) % len(CHANGES)])]
        name = f"log{i:02d}_" + (changes[0][1] if changes else "none")
        path = logs / f"{name}.csv"
        if not path.exists():
            t0 = time.perf_counter()
            r = long_log(changes, seed=seed, duration=dur, rate=10.0)
            r.to_csv(path.with_suffix(".part"))
            os.replace(path.with_suffix(".part"), path)
            (data / "p.toml").write_text(dumps(r.nominal))
            print(f"generated {path.name}: {dur / 3600:.2f} h in {time.perf_counter() - t0:.0f} s", flush=True)
        truth[name] = {"duration_s": dur, "changes": changes}
    (data / "truth.json").write_text(json.dumps(truth, indent=2))
    return logs


def found(data: Path, out: Path) -> dict:
    """What the fleet found against what was planted (context for the timing, not a validation of the
    monitor: docs/monitoring.md scores it): per log with a change, the first change detected at or after
    it and its component; per log without, the number of changes (false alarms)."""
    import csv

    from heavecomp.benchmark.long_logs import COMPONENT

    truth = json.loads((data / "truth.json").read_text())
    with (out / "changes.csv").open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    right, planted, alarms, hours_none = 0, 0, 0, 0.0
    for name, tr in truth.items():
        mine = [r for r in rows if r["log"] == name]
        if not tr["changes"]:
            alarms += len(mine)
            hours_none += tr["duration_s"] / 3600.0
            continue
        t, label = tr["changes"][0]
        after = [r for r in mine if float(r["t [s]"]) >= t]
        planted += 1
        right += bool(after) and after[0]["component"] == COMPONENT[label]
    return {"planted": planted, "first_named_right": right, "alarms_without_change": alarms,
            "hours_without_change": hours_none}


def uptime() -> str:
    return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()


def fleet(logs: Path, data: Path, out: Path, *extra) -> dict:
    """Run the command in a fresh interpreter; wall time from start to exit."""
    cmd = [sys.executable, "-m", "heavecomp", "fleet", str(logs), "--params", str(data / "p.toml"), "--out", str(out),
           "--quiet", *map(str, extra)]
    load0 = os.getloadavg()
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if r.returncode:
        raise SystemExit(f"{' '.join(cmd)} failed ({r.returncode}): {r.stderr.strip()}")
    timings = json.loads((out / "timings.json").read_text()) if (out / "timings.json").exists() else {}
    doc = json.loads((out / "fleet.json").read_text())
    tasks = [json.loads(f.read_text()) for f in sorted((out / "logs").glob("*/task.json"))]
    return {"task_wall_sum_s": sum(t["wall_s"] for t in tasks), "task_cpu_sum_s": sum(t["cpu_s"] for t in tasks),
            "failed": sum(t["status"] != "done" for t in tasks),
            "command": " ".join(cmd), "wall_s": wall, "executor_wall_s": timings.get("fleet.json", {})
            .get("run", {}).get("wall_time_s"), "executor": doc["run"]["executor"], "workers": doc["run"]["workers"],
            "load_before": load0, "load_after": os.getloadavg(), "table": (out / "fleet.csv").read_text()}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--logs", type=int, default=20, help="number of logs")
    ap.add_argument("--hours", type=float, default=1.0, help="shortest log [h]; the longest is twice it")
    ap.add_argument("--data", default="/tmp/heavecomp_fleet_bench", help="folder of the logs and the results")
    ap.add_argument("--repeats", type=int, default=2, help="interleaved repeats; the minimum wall time of each is kept")
    ap.add_argument("--generate-only", action="store_true")
    args = ap.parse_args(argv)
    data = Path(args.data)
    logs = generate(data, args.logs, args.hours)
    if args.generate_only:
        return 0
    import distributed

    res = {"uptime_before": uptime(), "n_logs": args.logs, "repeats": args.repeats,
           "hours_of_log": sum(v["duration_s"] for v in json.loads((data / "truth.json").read_text()).values()) / 3600}
    runs = {"one": [], "dask2": [], "proc2": []}
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        from heavecomp.campaign import fleet as F

        first = min(F.plan(logs, data / "p.toml"), key=lambda t: Path(t.path).stat().st_size)
        t0 = time.perf_counter()
        client.run(F.run_log, F.Settings(), first)  # both workers warm: imports, numba cache, as a running cluster
        res["dask_warmup_s"] = time.perf_counter() - t0
        for rep in range(args.repeats):  # interleaved: a change of the machine's load hits all three alike
            runs["one"].append(fleet(logs, data, data / f"out_1_{rep}", "--workers", "1"))
            runs["dask2"].append(fleet(logs, data, data / f"out_dask2_{rep}", "--scheduler", cluster.scheduler_address))
            runs["proc2"].append(fleet(logs, data, data / f"out_proc2_{rep}", "--workers", "2"))
    res["uptime_after"] = uptime()
    tables = {r.pop("table") for rs in runs.values() for r in rs}
    res["same_table"] = same = len(tables) == 1
    res["runs"] = runs
    for k, rs in runs.items():
        res[k] = min(rs, key=lambda r: r["wall_s"])
    res["found"] = found(data, data / "out_1_0")
    res["ratio_dask2"] = res["one"]["wall_s"] / res["dask2"]["wall_s"]
    res["ratio_proc2"] = res["one"]["wall_s"] / res["proc2"]["wall_s"]
    res["median_wall_s"] = {k: sorted(r["wall_s"] for r in rs)[len(rs) // 2] for k, rs in runs.items()}
    (data / "results.json").write_text(json.dumps(res, indent=2) + "\n")
    print(f"{args.logs} logs, {res['hours_of_log']:.1f} h of log at 10 Hz; the same fleet.csv from every run: {same}; "
          f"minimum of {args.repeats} interleaved repeats")
    print("| run | wall (command) | wall (executor) | sum of the tasks' wall | tasks' CPU | cores busy (tasks' CPU / "
          "executor wall) | load avg (1 min) before -> after |")
    print("|---|---|---|---|---|---|---|")
    for k, lab in (("one", "--workers 1 (in-process)"), ("dask2", "Dask LocalCluster, 2 workers"),
                   ("proc2", "--workers 2 (local processes)")):
        r = res[k]
        print(f"| {lab} | {r['wall_s']:.1f} s | {r['executor_wall_s']} s | {r['task_wall_sum_s']:.1f} s | "
              f"{r['task_cpu_sum_s']:.1f} s | {r['task_cpu_sum_s'] / r['executor_wall_s']:.2f} | "
              f"{r['load_before'][0]:.2f} -> "
              f"{r['load_after'][0]:.2f} |")
    print(f"ratio 1 worker / 2 Dask workers: {res['ratio_dask2']:.2f}; / 2 processes: {res['ratio_proc2']:.2f} "
          "(minimum wall of each)")
    print("every run's command wall [s]: " + "; ".join(f"{k} " + ", ".join(f"{r['wall_s']:.1f}" for r in rs)
                                                     for k, rs in runs.items()))
    f = res["found"]
    print(f"found: {f['first_named_right']} of {f['planted']} planted changes first named right; "
          f"{f['alarms_without_change']} changes in the {f['hours_without_change']:.1f} h of logs without one")
    print(f"uptime before: {res['uptime_before']}\nuptime after:  {res['uptime_after']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
