"""Speed benchmark: the monitor pass over a 24 h log at 10 Hz against the project's own ``simulate()``
of the same 24 h (issue 23 item 2: goal <= 60 s on 2 cores).

One run, side by side:

1. ``simulate(paper_a("stribeck"), 86400, rate=10)`` (the JONSWAP sea of the parameter set), timed
   after a warm-up call (numba cache loaded): the peer;
2. the log: its heave, stroke, pressure and WOB plus the generator's white measurement noise,
   checked as a measured run (``check_run``);
3. ``heavecomp.diagnosis.monitor.monitor`` on it, timed (window by window; what
   ``heavecomp monitor`` does after reading the file);
4. the ratio monitor / simulate, the peak RSS of the process and the load average, written to
   ``result_24h.json``.

Run from the repository root::

    python benchmarks/monitor/bench_24h.py          # ~1-2 min on an idle machine
"""

from __future__ import annotations

import json
import os
import platform
import resource
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
DURATION = 86400.0
RATE = 10.0
NOISE = {"heave": 0.002, "stroke": 0.002, "pressure": 2e3, "wob": 400.0}  # the generator's 1-sigma noise [SI]


def main() -> int:
    from heavecomp.diagnosis import monitor as M
    from heavecomp.diagnosis.data import check_run
    from heavecomp.params import paper_a
    from heavecomp.simulate import simulate

    p = paper_a("stribeck")
    simulate(p, 60.0, rate=RATE)  # warm-up: numba cache
    t0 = time.perf_counter()
    sim = simulate(p, DURATION, rate=RATE)
    t_sim = time.perf_counter() - t0
    rng = np.random.default_rng(0)
    cols = {c: sim[c] + rng.normal(0.0, s, sim.t.size) for c, s in NOISE.items()}
    run = check_run(sim.t, cols, params=p, source="bench:24h")
    del sim, cols
    t0 = time.perf_counter()
    res = M.monitor(run, p)
    t_mon = time.perf_counter() - t0
    out = {"duration_s": DURATION, "rate_hz": RATE, "samples": int(run.t.size),
           "simulate_s": round(t_sim, 2), "monitor_s": round(t_mon, 2), "ratio_monitor_over_simulate": round(t_mon / t_sim, 2),
           "goal_monitor_s": 60.0, "changes_found": len(res.changes),
           "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, 1),
           "load_average": [round(x, 2) for x in os.getloadavg()], "cpu": platform.processor() or platform.machine(),
           "cores": os.cpu_count()}
    (HERE / "result_24h.json").write_text(json.dumps(out, indent=2) + "\n")
    print(json.dumps(out, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
