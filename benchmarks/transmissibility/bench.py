"""Benchmark: heave -> WOB transmissibility over 1000 frequencies for 100 parameter variations.

Ours: heavecomp.analysis.linear.batch_matrices (all variations at once) +
heavecomp.analysis.frequency.freqresp_batch (stacked (jwI - A)^-1 B solves).
Peers (python-control 0.10, same matrices):
  naive     - one control.StateSpace per variation, evaluated point by point (sys(1j w), i.e. evalfr);
  per-sys   - one control.frequency_response(sys, omega) call per variation.

Usage: python benchmarks/transmissibility/bench.py [--variations 100] [--points 1000]
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np


def variations(n, seed=0):
    rng = np.random.default_rng(seed)
    return dict(gas_stiffness=rng.uniform(2e4, 1e5, n), moving_mass=rng.uniform(5e4, 1e5, n),
                lower_mass=rng.uniform(1e4, 6e4, n), string_stiffness=rng.uniform(2e5, 5e6, n),
                formation_stiffness=10 ** rng.uniform(4, 7, n), area=0.407,
                string_damping=rng.uniform(0, 5e4, n), formation_damping=rng.uniform(0, 5e4, n),
                friction_slope=rng.uniform(0, 2e4, n))


def best_of(f, repeat):
    times, out = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t)
    return min(times), out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variations", type=int, default=100)
    ap.add_argument("--points", type=int, default=1000)
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args(argv)

    import control as ct

    from heavecomp.analysis.frequency import freqresp_batch
    from heavecomp.analysis.linear import batch_matrices

    kw = variations(a.variations)
    w = np.logspace(-3, 2, a.points)

    def ours():
        A, B, C, D = batch_matrices(**kw)
        return freqresp_batch(A, B[..., :1], C[..., :1, :], D[..., :1, :1], w)[:, 0, 0, :]

    A, B, C, D = batch_matrices(**kw)
    systems = [ct.ss(A[i], B[i, :, :1], C[i, :1], D[i, :1, :1]) for i in range(a.variations)]

    def naive():
        return np.array([[complex(s(1j * wi)) for wi in w] for s in systems])

    def per_sys():
        return np.array([ct.frequency_response(s, w).frdata[0, 0] for s in systems])

    ours()  # warm-up
    t_ours, H = best_of(ours, a.repeat)
    t_naive, Hn = best_of(naive, 1)
    t_sys, Hs = best_of(per_sys, min(a.repeat, 3))
    err = max(np.max(np.abs(H - Hn) / np.abs(Hn)), np.max(np.abs(H - Hs) / np.abs(Hs)))
    res = {"variations": a.variations, "points": a.points, "ours_s": t_ours, "naive_evalfr_s": t_naive,
           "per_system_frequency_response_s": t_sys, "ratio_naive_over_ours": t_naive / t_ours,
           "ratio_per_system_over_ours": t_sys / t_ours, "max_rel_difference": float(err)}
    print(json.dumps(res, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
