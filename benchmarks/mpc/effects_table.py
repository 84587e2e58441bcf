"""Every registered effect in both MPCs: built, or refused in one line; WOB std over 60 s of closed loop.

For each registered effect at its Params defaults: build the linear and the nonlinear MPC knowing it
(a refusal is printed with its one line).  For each plant effect: 60 s of closed loop against the exact
plant with the effect (paper A, full static friction, 1 m / 12 s sine; noisy sensors, predicted preview:
the defaults), passive and both MPCs; WOB std and RMS about the set-point after the fade-in, the share of
control steps with the actuator at u_max, limit violations and the wall time of each run.  The same
runs as the slow tier of ``tests/test_controllers_effects.py``.

    python benchmarks/mpc/effects_table.py            # ~2-4 min on 2 cores; prints a markdown table
"""

from __future__ import annotations

import time

import numpy as np

from heavecomp.closed_loop import simulate_closed_loop
from heavecomp.controllers import CONTROLLERS, ControllerConfig
from heavecomp.effects.registry import library
from heavecomp.errors import ParameterError
from heavecomp.params import paper_a

MPCS = ("linear-mpc", "nonlinear-mpc")


def _row(p, name, cls):
    cells = {}
    for mpc in MPCS:
        try:
            CONTROLLERS[mpc](p, ControllerConfig.from_params(p), effects=[cls()])
            cells[mpc] = "built"
        except ParameterError as exc:
            cells[mpc] = f"refused: {exc}"
    if cls.kind != "plant" or any(c != "built" for c in cells.values()):
        return cells, None
    eff = [cls()]
    runs = {}
    for label in ("passive",) + MPCS:
        ctrl = "passive" if label == "passive" else CONTROLLERS[label](p, ControllerConfig.from_params(p), effects=eff)
        t0 = time.perf_counter()
        res = simulate_closed_loop(p, ctrl, 60.0, effects=eff)
        wall = time.perf_counter() - t0
        m = res.metrics()
        w = res.window(None)
        u = res["u_active"][w]
        runs[label] = {"std": m["wob_std"] / 1e3,
                       "rms": float(np.sqrt(np.mean((res["wob"][w] - p.operating_point.wob_setpoint) ** 2))) / 1e3,
                       "sat": float(np.mean(np.abs(u) > 0.99 * m["u_max"])), "u_mean": float(np.mean(u)) / 1e3,
                       "viol": m.get("violations_u_max", 0) + m.get("violations_rate", 0), "wall": wall}
    return cells, runs


def main():
    p = paper_a("stribeck")
    print("| effect | kind | linear MPC | nonlinear MPC | WOB std passive | linear | nonlinear | RMS about W_0 "
          "passive / linear / nonlinear | mean u [kN] / at u_max, lin; nl | violations | wall passive / lin / nl [s] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name, cls in library().items():
        cells, runs = _row(p, name, cls)
        built = [cells[m] for m in MPCS]
        if runs is None:
            print(f"| {name} | {cls.kind} | {built[0]} | {built[1]} | | | | | | | |", flush=True)
            continue
        r = runs
        print(f"| {name} | {cls.kind} | built | built | {r['passive']['std']:.2f} | {r['linear-mpc']['std']:.2f} | "
              f"{r['nonlinear-mpc']['std']:.2f} | {r['passive']['rms']:.1f} / {r['linear-mpc']['rms']:.1f} / "
              f"{r['nonlinear-mpc']['rms']:.1f} | {r['linear-mpc']['u_mean']:.0f} / {100 * r['linear-mpc']['sat']:.0f} %; "
              f"{r['nonlinear-mpc']['u_mean']:.0f} / {100 * r['nonlinear-mpc']['sat']:.0f} % | {r['linear-mpc']['viol']} / {r['nonlinear-mpc']['viol']} | "
              f"{r['passive']['wall']:.1f} / {r['linear-mpc']['wall']:.1f} / {r['nonlinear-mpc']['wall']:.1f} |",
              flush=True)


if __name__ == "__main__":
    main()
