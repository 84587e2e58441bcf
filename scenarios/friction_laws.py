"""What do paper A's friction laws look like against velocity (the shape of paper A Fig. 3),
and what does the smooth form used for optimisation change?

Paper-A main-cylinder parameters at the operating pressure p_0; eq. 4 (Stribeck + pressure),
eq. 6 and eq. 7 (rotating piston, v_t = 0.05 m/s), the hydromechanical efficiency model (eqs. 1-3,
eta = 0.98 at the operating force), and eq. 4 regularised with tanh(v/eps); beside them paper B's
three-regime law of the pneumatic seal (heavecomp.pneumatic.plant defaults).
"""

from __future__ import annotations

import sys

import numpy as np

from heavecomp.friction.laws import FrictionLaw, hydromechanical_friction
from heavecomp.params import paper_a
from heavecomp.report import figures as fig
from heavecomp.report.scenario import md_table, parse_args, run, write_metrics, write_report

EPS = 1e-3  # m/s, regularisation width shown


def build(n: int = 2001) -> dict:
    p = paper_a("rotating_eq7")
    v = np.linspace(-0.1, 0.1, n)
    v = v[v != 0.0]
    laws = {m: FrictionLaw.from_params(p.replace(friction={"model": m}).friction)
            for m in ("stribeck", "rotating_eq6", "rotating_eq7")}
    curves = {
        "eq. 4 Stribeck + pressure (full static friction)": (v, laws["stribeck"].force(v, p.p0), "r-"),
        "eq. 6 rotating piston": (v, laws["rotating_eq6"].force(v, p.p0), "m-"),
        "eq. 7 rotating piston (reduced static friction)": (v, laws["rotating_eq7"].force(v, p.p0), "C1-"),
        f"eq. 4 smooth, tanh(v/eps), eps = {EPS * 1e3:g} mm/s": (v, laws["stribeck"].smooth(v, p.p0, eps=EPS), "k:"),
        "eqs. 1-3 hydromechanical efficiency 0.98": (v, hydromechanical_friction(p.p0 * p.area, v, 0.98), "b--"),
    }
    limits = {m: float(law.static_limit(p.p0)) for m, law in laws.items()}
    from heavecomp.pneumatic.friction import smooth_friction
    from heavecomp.pneumatic.plant import default

    tb = default().friction
    vb = np.linspace(-0.15, 0.15, n)
    vb = vb[vb != 0.0]
    pneumatic = {
        "static -> dynamic (after breakaway from F_s1)": (vb, tb.accelerating(vb), "r-"),
        "dynamic -> static (decelerating)": (vb, tb.decelerating(vb), "b--"),
        f"smooth static -> dynamic, eps = {EPS * 1e3:g} mm/s": (
            vb, smooth_friction(vb, tb.stick_static_force, tb.FPB, EPS), "k:"),
    }
    limits["paper_b_stick"] = float(tb.stick_static_force)
    return {"curves": curves, "static_limits": limits, "p0": p.p0, "pneumatic": pneumatic}


def main(argv=None) -> int:
    args = parse_args(argv, "friction_laws", __doc__)
    res = build(401 if args.quick else 4001)
    fig.save(fig.plot_friction_laws(res["curves"], pneumatic=res["pneumatic"]), args.out / "friction_laws.png")
    write_metrics(args.out, {"static_limit_N": res["static_limits"], "p0_Pa": res["p0"], "eps_m_per_s": EPS})
    write_report(args.out, "Friction laws of paper A", [
        __doc__, "![laws](friction_laws.png)",
        md_table(["law", "static limit [kN] (CMC at p_0; paper B seal)"],
                 [(k, v / 1e3) for k, v in res["static_limits"].items()], fmt="{:.4g}"),
        "Eq. 6 lowers the static peak (jump 2) but keeps the sign jump (jump 1); eq. 7 removes the "
        "Stribeck part of the jump — only the pressure term C_p|p| can still hold the piston.",
    ])
    print(f"wrote {args.out}/report.md")
    return 0


if __name__ == "__main__":
    sys.exit(run(main))
