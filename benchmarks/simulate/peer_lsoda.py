"""Peer for the speed benchmark: the CMC with tanh-smoothed friction, integrated by
``scipy.integrate.solve_ivp(method="LSODA")``.

This is the "straightforward" way to simulate the model: the right-hand side is
built from the SAME equation functions as heavecomp (``heavecomp.plants.cmc`` and
``heavecomp.friction.laws.friction_smooth``, evaluated on numpy floats) — nothing
is restated — and the same sine heave with its sin^2 fade-in (plain scalar ``math``
for speed, checked against ``heavecomp.simulate.excitation.sine`` at start-up).  Only the friction differs: the
sign of the velocity is replaced by ``tanh(v / eps)`` (no exact stiction), which
is what a general-purpose ODE solver needs.

Usage (one whole process, timed by ``bench_simulate.py``)::

    python benchmarks/simulate/peer_lsoda.py PARAMS.toml --duration 3600 \
        --eps 1e-4 --rtol 1e-6 --atol 1e-9 --out peer.npz

Writes ``t`` and ``wob`` (and the stroke) at ``--rate`` Hz plus the solver
statistics (nfev, njev, nlu) into the ``.npz`` file.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np


def build_rhs(params, eps):
    """f(t, x) for x = [s, v, y_b, v_b] from the heavecomp equation functions."""
    from heavecomp.friction.laws import FrictionLaw, friction_smooth
    from heavecomp.plants import cmc
    from heavecomp.simulate.excitation import sine

    law = FrictionLaw.from_params(params.friction)
    code, FP = law.code, law.FP
    PP = cmc.plant_vector(params)
    hv = params.heave
    a, w, ramp = hv.amplitude, 2.0 * math.pi / hv.period, hv.ramp

    def heave(t):
        # the contract's sine with sin^2 fade-in, in plain scalar math (the vectorised
        # excitation.ramp_factor costs ~9 us per call on a scalar, a third of the rhs);
        # checked against heavecomp.simulate.excitation.sine below
        if t < ramp:
            x = math.pi * t / ramp
            r, dr, ddr = math.sin(0.5 * x) ** 2, math.pi / (2 * ramp) * math.sin(x), math.pi ** 2 / (2 * ramp ** 2) * math.cos(x)
        else:
            r, dr, ddr = 1.0, 0.0, 0.0
        sn, cs = math.sin(w * t), math.cos(w * t)
        z, dz, ddz = a * sn, a * w * cs, -a * w * w * sn
        return r * z, dr * z + r * dz, ddr * z + 2.0 * dr * dz + r * ddz

    ref = sine(a, hv.period, ramp, 2.0 * ramp + 1.0, 0.01)
    mine = np.array([heave(t) for t in ref.t])
    if np.max(np.abs(mine - np.column_stack([ref.z, ref.dz, ref.ddz]))) > 1e-12:
        raise AssertionError("peer heave differs from heavecomp.simulate.excitation.sine")

    def rhs(t, x):
        s, v, yb, vb = x
        zh, dzh, ddzh = heave(t)
        p = cmc.gas_pressure(s, PP)
        Ff = friction_smooth(code, v, p, FP, eps)
        dv = cmc.stroke_accel(s, v, yb, vb, zh, dzh, ddzh, 0.0, Ff, PP)
        dvb = cmc.lower_accel(s, v, yb, vb, zh, dzh, PP)
        return [v, dv, vb, dvb]

    return rhs, PP


def run(params, duration, *, eps, rtol, atol, rate=20.0):
    """Integrate from rest at the operating point; returns (t, wob, stroke, sol)."""
    from scipy.integrate import solve_ivp

    from heavecomp.plants import cmc

    rhs, PP = build_rhs(params, eps)
    n = int(round(duration * rate))
    t_eval = np.arange(n + 1) / rate
    # atol per state: stroke/displacements [m] and velocities [m/s]
    sol = solve_ivp(rhs, (0.0, duration), np.zeros(4), method="LSODA", t_eval=t_eval, rtol=rtol, atol=atol)
    if not sol.success:
        raise RuntimeError(f"LSODA failed: {sol.message}")
    s, v, yb, vb = sol.y
    wob = cmc.wob(yb, vb, PP)
    return sol.t, wob, s, sol


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("params")
    ap.add_argument("--duration", type=float, required=True)
    ap.add_argument("--eps", type=float, required=True, help="tanh width of the friction's sign [m/s]")
    ap.add_argument("--rtol", type=float, required=True)
    ap.add_argument("--atol", type=float, required=True)
    ap.add_argument("--rate", type=float, default=20.0)
    ap.add_argument("--out", required=True, help="output .npz")
    a = ap.parse_args(argv)
    from heavecomp.params import load

    t0 = time.perf_counter()
    t, wob, s, sol = run(load(a.params), a.duration, eps=a.eps, rtol=a.rtol, atol=a.atol, rate=a.rate)
    wall = time.perf_counter() - t0
    np.savez(a.out, t=t, wob=wob, stroke=s, nfev=sol.nfev, njev=sol.njev, nlu=sol.nlu, solve_time=wall)
    print(f"LSODA eps={a.eps:g} rtol={a.rtol:g} atol={a.atol:g}: nfev {sol.nfev}, njev {sol.njev}, "
          f"solve {wall:.2f} s -> {a.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
