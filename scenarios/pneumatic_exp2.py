"""Does paper B's pneumatic meter-out cylinder (our documented parameters) stick once near 1.3 s,
restart near 1.7 s and then move steadily (Exp. 2), and can the friction be measured back from
pressures and an encoder with paper B's zero-phase FIR method?
"""

from __future__ import annotations

import sys

from heavecomp.pneumatic import measurement as PF
from heavecomp.pneumatic import linear as PL
from heavecomp.report import rigs as PLT
from heavecomp.pneumatic import stepper as PS
from heavecomp.pneumatic import plant as pn
from heavecomp.report.figures import save
from heavecomp.report.scenario import md_table, parse_args, run, write_metrics, write_report


def build(duration: float = 3.0) -> dict:
    p = pn.default()
    r = PS.simulate(p, duration, rate=1000.0)
    return {"p": p, "run": r, "lin": PL.linearise(p, 0.05), "meas": PF.synthetic_validation(p, duration=duration)}


def main(argv=None) -> int:
    args = parse_args(argv, "pneumatic_exp2", __doc__)
    res = build(2.2 if args.quick else 3.0)
    p, r, lin, meas = res["p"], res["run"], res["lin"], res["meas"]
    st = r["stats"]
    save(PLT.plot_exp2(r, p, lin), args.out / "exp2_response.png", dpi=100)
    save(PLT.plot_friction_velocity(meas["velocity_measured"], meas["friction_true"], meas["friction_measured"],
                                    meas["sliding"], "Friction measured from pressures + 12.5 um encoder "
                                    f"(RMS error {meas['rms_error_N']:.2f} N) vs the model's"),
         args.out / "friction_measured.png", dpi=100)
    metrics = {"stats": st, "equilibrium_velocity_m_s": lin.u0, "omega_n_rad_s": lin.omega_n, "zeta": lin.zeta,
               "D": lin.D, "measurement": {k: v for k, v in meas.items() if isinstance(v, float)},
               "params": p.to_dict()["pneumatic"]}
    write_metrics(args.out, metrics)
    write_report(args.out, "Paper B Exp. 2: stick-slip of a pneumatic meter-out cylinder", [
        __doc__, "![response](exp2_response.png)",
        md_table(["event", "time [s]"], [("first breakaway (F_0)", st["t_first_breakaway"]),
                                         ("stick", st["t_first_stick"]),
                                         ("restart (F_s1)", st["t_second_breakaway"])]),
        f"Sticks after the restart: {int(st['n_stick']) - 1}. Equilibrium velocity u_0 = {lin.u0 * 1e3:.1f} mm/s; "
        f"linearised omega_n = {lin.omega_n:.1f} rad/s, zeta* = {lin.zeta:.2f}, D*(F_s1) = {lin.D:.2f}.",
        "![measured](friction_measured.png)",
        f"Paper B's method on synthetic data (encoder 12.5 um, pressure noise {meas['pressure_noise_Pa']:.0f} Pa, "
        f"FIR cutoff {meas['cutoff_Hz']:.0f} Hz forward-backward): RMS friction error "
        f"{meas['rms_error_N']:.3f} N over a friction span of {meas['friction_span_N']:.1f} N while sliding "
        "(30 ms around stick and branch events excluded: the true friction jumps there).",
        "All parameter values are our assumptions (paper B's table 1 is illegible): see docs/stickslip.md.",
    ])
    return 0


if __name__ == "__main__":
    sys.exit(run(main))
