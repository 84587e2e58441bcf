"""Benchmark: 40 x 40 grid of nonlinear pneumatic stick-slip simulations (paper B map).

heavecomp: exact stick-slip RK4 stepper compiled by numba, grid run with numba prange
(``heavecomp.pneumatic.stickslip.grid_map``).  Peer: ``scipy.integrate.solve_ivp``
(LSODA) on the same plant equations (the same Python functions of
``heavecomp.pneumatic.plant``) with the friction regularised, ``tanh(v/eps)``
times the accelerating branch from F_s1, eps = 1e-4 m/s — the usual way to
simulate stick-slip without an event-driven stepper.  The peer runs on a
sub-grid (every 8th point in each direction, 25 runs) and its time per run is
extrapolated to 1600 runs; the same windows (8 natural periods) are simulated.

Run:  python benchmarks/stickslip_map/bench.py [--peer-stride 8]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np


def peer_run(q, state, t_end, eps=1e-4):
    from scipy.integrate import solve_ivp

    from heavecomp.pneumatic.friction import smooth_friction
    from heavecomp.pneumatic import plant as pn

    PP, FPB = q.plant_vector(), q.friction.FPB
    peak = q.stick_static_force

    def f(t, s):
        x, v, Pa, Pb = s
        Ff = smooth_friction(v, peak, FPB, eps)
        dPa, dPb = pn.pressure_rates(x, v, Pa, Pb, PP)
        return [v, pn.piston_accel(Pa, Pb, Ff, PP), dPa, dPb]

    sol = solve_ivp(f, (0.0, t_end), state, method="LSODA", rtol=1e-6, atol=[1e-9, 1e-7, 1.0, 1.0])
    v = sol.y[1]
    i = int(np.argmax(v))
    # "sticks again": the regularised velocity falls back to (almost) zero after its first peak
    return bool(np.min(v[i:]) < 1e-3), sol.nfev  # creep below 1 mm/s counts as a stick


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=40)
    ap.add_argument("--peer-stride", type=int, default=8)
    args = ap.parse_args(argv)
    from heavecomp.pneumatic import linear as PL
    from heavecomp.pneumatic import stickslip as SS
    from heavecomp.pneumatic import plant as pn

    p = pn.default()
    xs, ys = np.geomspace(8.0, 250.0, args.n), np.geomspace(1.0, 120.0, args.n)
    SS.grid_map(p, "viscous_coefficient", xs[:2], "friction_drop", ys[:2])  # compile (cached afterwards)
    t0 = time.perf_counter()
    g = SS.grid_map(p, "viscous_coefficient", xs, "friction_drop", ys)
    t_grid = time.perf_counter() - t0
    t0 = time.perf_counter()
    g1 = SS.grid_map(p, "viscous_coefficient", xs, "friction_drop", ys, parallel=False)
    t_serial = time.perf_counter() - t0
    assert (g1["nonlinear"] == g["nonlinear"]).all()
    sub = [(i, j) for i in range(0, args.n, args.peer_stride) for j in range(0, args.n, args.peer_stride)]
    t0 = time.perf_counter()
    agree = 0
    for i, j in sub:
        q = SS.vary(p, {"viscous_coefficient": xs[j], "friction_drop": ys[i]})
        lin = PL.linearise(q)
        sticks, _ = peer_run(q, SS.restart_state(q), SS.window(lin))
        agree += sticks == bool(g["nonlinear"][i, j])
    t_peer = time.perf_counter() - t0
    per_peer = t_peer / len(sub)
    res = {"grid": f"{args.n}x{args.n}", "heavecomp_parallel_s": t_grid, "heavecomp_serial_s": t_serial,
           "peer": "scipy solve_ivp LSODA, tanh-regularised friction (eps 1e-4 m/s)",
           "peer_runs": len(sub), "peer_s_per_run": per_peer, "peer_extrapolated_s": per_peer * args.n ** 2,
           "ratio_peer_over_heavecomp": per_peer * args.n ** 2 / t_grid,
           "peer_classification_agrees_with_exact": f"{agree}/{len(sub)}",
           "agreement_curve_vs_simulation": g["agreement"], "cpus": os.cpu_count(),
           "numba_threads": int(os.environ.get("NUMBA_NUM_THREADS", os.cpu_count()))}
    print(json.dumps(res, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
