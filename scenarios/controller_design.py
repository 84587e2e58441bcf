"""Can an active cylinder with MPC cancel the WOB variation that the gas spring and the main-cylinder friction leave, within 60 kN and 300 kN/s?

Paper A's CMC (full static friction eq. 4, reduced static friction eq. 7, no friction) under paper A's
sine (1 m, 12 s) and a JONSWAP sea (H_s 2 m, T_p 12 s), with the rig's measurements noisy (stroke 1 mm,
pressure 5 kPa, WOB 0.5 kN, heave 5 mm) and the heave preview predicted online (direct multi-step least
squares): passive vs PID vs linear MPC (osqp) vs nonlinear MPC (casadi SQP + qrqp); the frame of the MPCs'
prediction model (earth vs stroke) against a perfect heave preview; effect of horizon, weights and actuator
size; robustness to a +-30 % wrong friction model and a wrong gas stiffness in both seas.
"""

from __future__ import annotations

import sys

from heavecomp.closed_loop import design as D
from heavecomp.report import controllers as RC
from heavecomp.report.figures import save
from heavecomp.report.scenario import md_table, parse_args, run, write_metrics, write_report


def build(quick: bool = False) -> dict:
    dur = {"sine": 40.0, "jonswap": 120.0} if quick else {"sine": 240.0, "jonswap": 420.0}
    regimes = ("stribeck",) if quick else D.REGIMES
    seas = ("sine",) if quick else tuple(D.SEAS)
    nl = {"nonlinear-mpc": {"horizon": 10}} if quick else {}
    table, kept = D.compare(regimes, seas, D.CONTROLLERS, dur, nl)
    T = dur["sine"]
    lin = ("linear-mpc",) if quick else ("linear-mpc", "nonlinear-mpc")
    pick = (lambda v: v[-1:]) if quick else (lambda v: v)
    sw = {
        "horizon N": ("intervals of 50 ms", {c: D.sweep("stribeck", "sine", c, T, "horizon", pick([5, 10, 20, 40]) if c == "linear-mpc" else pick([10, 20])) for c in lin}),
        "weight r_du": ("1/N^2", {"linear-mpc": D.sweep("stribeck", "sine", "linear-mpc", T, "r_du", pick([3e-8, 3e-7, 3e-6]))}),
        "u_max": ("N", {"linear-mpc": D.sweep("stribeck", "sine", "linear-mpc", T, "u_max", pick([30e3, 45e3, 60e3, 80e3, 100e3]))}),
        "rate_max": ("N/s", {"linear-mpc": D.sweep("stribeck", "sine", "linear-mpc", T, "rate_max", pick([100e3, 200e3, 300e3, 600e3]))}),
    }
    robust = D.robustness(seas, lin, dur, (1.3,) if quick else (0.7, 1.3))
    # the prediction model's frame, and what a perfect heave preview would give (the irregular sea)
    fsea = "jonswap" if "jonswap" in seas else seas[0]
    frames = D.frame_study(fsea, lin, dur[fsea])
    return {"table": table, "kept": kept, "sweeps": sw, "robust": robust, "frames": frames, "frame_sea": fsea,
            "durations": dur}


def main(argv=None) -> int:
    args = parse_args(argv, "controller_design", __doc__)
    r = build(args.quick)
    table, kept = r["table"], r["kept"]
    passive = table["sine"]["stribeck"]["passive"]["wob_std"]
    T = r["durations"]["sine"]
    save(RC.plot_wob_controllers({c: kept[("sine", "stribeck", c)] for c in D.CONTROLLERS}, (T - 36, T),
                                title="Full static friction, paper A sine: MPC holds the WOB where passive and PID "
                                      "let gas spring and friction through"), args.out / "wob_controllers.png", dpi=100)
    sections = ["## Findings", "\n".join(D.findings(table, r["sweeps"], r["robust"], r["frames"], r["frame_sea"])),
                "Solve times are wall-clock and depend on the machine, so they are kept out of this report and "
                "metrics.json (a re-run must leave git clean): a run writes them to timings.json (not tracked); "
                "see `benchmarks/mpc/README.md` for the dedicated measurement and the peer comparison."]
    for sea in table:
        save(RC.plot_std_table(table, sea, title=f"WOB std per friction regime and controller ({sea})"),
             args.out / f"wob_std_{sea}.png", dpi=100)
        rows = [(reg, c, m["wob_std"] / 1e3, 100 * m["wob_std"] / table[sea][reg]["passive"]["wob_std"],
                 m["wob_p2p"] / 1e3, m["u_active_max"] / 1e3,
                 m["violations_u_max"] + m["violations_rate"], m["fallbacks"],
                 m["preview_rmse_end_m"] if m["preview_rmse_end_m"] is not None else "-")
                for reg, cs in table[sea].items() for c, m in cs.items()]
        sections += [f"## {sea}: WOB per controller and friction regime ({r['durations'][sea]:g} s, stats after the fade-in)",
                     md_table(["regime", "controller", "WOB std [kN]", "% of passive", "WOB p2p [kN]", "max abs(u) [kN]",
                               "limit violations", "fallbacks",
                               "preview RMSE at 1 s [m]"], rows, fmt="{:.3g}")]
    save(RC.plot_sweeps(r["sweeps"], passive, title="Full static friction, sine: WOB std against horizon, "
                       "force-rate weight and actuator size"), args.out / "sweeps.png", dpi=100)
    sw_rows = [(label, c, row["value"], row["wob_std"] / 1e3)
               for label, (unit, rows) in r["sweeps"].items() for c, rr in rows.items() for row in rr]
    pas = {sea: table[sea]["stribeck"]["passive"]["wob_std"] for sea in table}
    rb_rows = [(c, k, m["wob_std"] / 1e3, 100 * m["wob_std"] / pas[D.label_sea(k)])
               for c, d in r["robust"].items() for k, m in d.items()]
    fsea = r["frame_sea"]
    fr_rows = [(c, k, m["wob_std"] / 1e3, 100 * m["wob_std"] / pas[fsea],
                m["preview_rmse_end_m"] if m["preview_rmse_end_m"] is not None else "-")
               for c, d in r["frames"].items() for k, m in d.items()]
    sections += ["## Horizon, weights and actuator size (full static friction, sine)",
                 md_table(["option", "controller", "value", "WOB std [kN]"], sw_rows, fmt="{:.3g}"),
                 f"## Frame of the prediction model and the value of the heave preview (full static friction, {fsea})",
                 "The plant is written relative to the heaving cylinder (stroke s); the MPCs predict with the top "
                 "mass in the earth frame (X = z_h + s) by default, where the heave acceleration drops out and a "
                 "heave-preview error moves the predicted WOB through the gas spring only "
                 "(`heavecomp.controllers.model`). A perfect preview (the true future heave) bounds what a better "
                 "predictor could still win.",
                 md_table(["controller", "model", "WOB std [kN]", "% of passive", "preview RMSE at 1 s [m]"], fr_rows,
                          fmt="{:.3g}"),
                 "## Robustness: the controller's friction model x0.7 / x1.3, its gas stiffness x0.7 / x1.3 (full static friction)",
                 md_table(["controller", "model error", "WOB std [kN]", "% of passive"], rb_rows, fmt="{:.3g}")]
    metrics = {"table": table, "sweeps": {k: v[1] for k, v in r["sweeps"].items()}, "robust": r["robust"],
               "frames": r["frames"],
               "durations": r["durations"], "quick": args.quick,
               "goal": {"passive_wob_std": passive, "target_wob_std": 0.2 * passive}}
    write_metrics(args.out, metrics)
    write_report(args.out, "Active heave compensation: controller design", [__doc__.strip()] + sections)
    return 0


if __name__ == "__main__":
    sys.exit(run(main))
