"""Stick-slip analysis of paper B's pneumatic meter-out cylinder: linearisation, critical curve, simulation, map."""

from __future__ import annotations

import argparse


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Add the arguments of ``heavecomp stickslip`` to its parser.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The sub-command's parser (:func:`heavecomp.cli.build_parser`).
    """
    p.add_argument("params", metavar="PARAMS.toml|default",
                   help="[pneumatic] parameter file, or 'default' for the documented default cylinder")
    p.add_argument("--dump", action="store_true", help="print the (validated) parameters as TOML and exit")
    p.add_argument("--duration", type=float, default=None, metavar="S",
                   help="also simulate S seconds from paper B's start (exact stick-slip)")
    p.add_argument("--map", type=int, default=None, metavar="N",
                   help="classify an N x N grid (viscous coefficient x friction drop) by the critical curve "
                        "and by simulation; print the agreement")
    p.add_argument("--convention", choices=("paper", "full"), default="paper",
                   help="linearisation: neglect the volume change (paper B) or keep it (full Jacobian)")
    p.add_argument("--out", default=None, metavar="DIR",
                   help="write metrics.json, report.md/.html and the figures (simulation.png, critical_curve.png; "
                        "timeseries.csv with --duration) here")


def run(args) -> int:
    """Run ``heavecomp stickslip``: linearisation and stick-slip prediction of the pneumatic cylinder,
    optionally a simulation (``--duration``) and a map (``--map``); with ``--out`` the figures,
    metrics and report.

    Parameters
    ----------
    args : argparse.Namespace
        The arguments of :func:`add_arguments`; while it runs ``args.out`` is the staging folder and
        ``args.out_final`` the folder the user named.

    Returns
    -------
    int
        Exit code (0).

    Raises
    ------
    heavecomp.errors.InputError
        Bad input (the CLI prints one line and exits 2).
    """
    import math
    import sys
    from pathlib import Path

    import numpy as np

    from heavecomp.pneumatic import linear as PL
    from heavecomp.pneumatic import stickslip as SS
    from heavecomp.errors import InputError, ParameterError
    from heavecomp.pneumatic import plant as pn

    if args.params == "default":
        p = pn.default()
    else:
        if not Path(args.params).exists():
            raise ParameterError(f"{args.params}: no such parameter file (or use 'default')")
        p = pn.load(args.params)
    if args.dump:
        sys.stdout.write(pn.dumps(p))
        return 0
    if args.duration is not None and not (args.duration > 0 and math.isfinite(args.duration)):
        raise InputError(f"--duration must be a positive number of seconds, got {args.duration}")
    if args.map is not None and not (2 <= args.map <= 200):
        raise InputError(f"--map must be a grid size between 2 and 200, got {args.map}")
    sim = grid = None
    lin = PL.linearise(p, convention=args.convention)
    Dcr = SS.critical_D(lin.zeta)
    mv = SS.minimum_velocity(p, convention=args.convention, nonlinear=False)
    m = {"linearisation": lin.as_dict(), "critical_D": Dcr, "stick_slip_predicted": bool(lin.D > Dcr),
         "minimum_velocity_linear_m_s": mv["linear_u0"], "minimum_velocity_exhaust_area_m2": mv["linear_exhaust_area"]}
    print(f"u_0 = {lin.u0 * 1e3:.2f} mm/s, omega_n = {lin.omega_n:.2f} rad/s, zeta* = {lin.zeta:.3f}, "
          f"D* = {lin.D:.3f}, D*_cr = {Dcr:.3f} -> {'STICK-SLIP' if lin.D > Dcr else 'no stick-slip'} after a stick; "
          f"minimum equilibrium velocity {mv['linear_u0'] * 1e3:.2f} mm/s")
    out = Path(args.out) if args.out else None
    if out:
        out.mkdir(parents=True, exist_ok=True)
    if args.duration is not None:
        from heavecomp.pneumatic import stepper as PS

        r = PS.simulate(p, args.duration, rate=1000.0)
        m["simulation"] = r["stats"]
        st = r["stats"]
        sim = r
        print(f"simulation {args.duration:g} s: breakaway {st['t_first_breakaway']:.3f} s, sticks {int(st['n_stick'])}, "
              f"first stick {st['t_first_stick']:.3f} s, restart {st['t_second_breakaway']:.3f} s")
        if out:
            from heavecomp.commands._progress import Progress
            from heavecomp.simulate.core import write_csv

            cols = list(PS.CHANNELS)
            data = np.column_stack([r[c] for c in cols])
            write_csv(out / "timeseries.csv", data, cols,
                      progress=Progress("writing timeseries.csv") if data.shape[0] > 200_000 else None)
    if args.map is not None:
        n = args.map
        g = SS.grid_map(p, "viscous_coefficient", np.geomspace(8.0, 250.0, n), "friction_drop",
                        np.geomspace(1.0, 120.0, n), convention=args.convention)
        m["map"] = {"n": n, "agreement": g["agreement"], "stick_slip_nonlinear": int(g["nonlinear"].sum()),
                    "stick_slip_linear": int(g["linear"].sum())}
        grid = g
        print(f"map {n}x{n}: critical curve and simulation agree on {100 * g['agreement']:.1f} % of the points")
    if out:
        from heavecomp.report.provenance import finish
        from heavecomp.commands._output import final
        from heavecomp.report.scenario import write_metrics

        _figures_and_report(out, p, lin, Dcr, m, sim, grid)
        write_metrics(out, m)
        (out / "params.toml").write_text(pn.dumps(p))
        finish(out, params_file="params.toml", csv_files=("timeseries.csv",) if args.duration is not None else ())
        print(f"-> {final(args)}")
    return 0


def _figures_and_report(out, p, lin, Dcr, m, sim, grid) -> None:
    """``simulation.png`` (with ``--duration``), ``critical_curve.png`` (with ``--map``) and ``report.md``."""
    import numpy as np

    from heavecomp.pneumatic import stickslip as SS
    from heavecomp.report import rigs
    from heavecomp.report.figures import save
    from heavecomp.report.scenario import md_table, write_report

    verdict = "stick-slip" if lin.D > Dcr else "no stick-slip"
    sections = [f"Linearisation: u_0 = {lin.u0 * 1e3:.2f} mm/s, omega_n = {lin.omega_n:.2f} rad/s, "
                f"zeta* = {lin.zeta:.3f}, D* = {lin.D:.3f} against the critical D*_cr = {Dcr:.3f}: **{verdict}** "
                f"predicted after a stick; minimum equilibrium velocity "
                f"{m['minimum_velocity_linear_m_s'] * 1e3:.2f} mm/s."]
    if sim is not None:
        save(rigs.plot_exp2(sim, p, lin), out / "simulation.png", dpi=90)
        st = m["simulation"]
        sections += ["## Simulation (exact stick-slip)", md_table(
            ["first breakaway [s]", "sticks [-]", "first stick [s]", "restart [s]"],
            [[st["t_first_breakaway"], int(st["n_stick"]), st["t_first_stick"], st["t_second_breakaway"]]],
            "{:.3f}"), "![simulation](simulation.png)"]
    if grid is not None:
        zc = np.linspace(0.005, 0.97, 300)
        save(rigs.plot_critical_map(grid, zc, SS.critical_curve(zc), (lin.zeta, lin.D)), out / "critical_curve.png",
             dpi=90)
        n = grid["agree"].size
        sections += ["## Map: critical curve against simulation",
                     f"{grid['zeta'].shape[0]} x {grid['zeta'].shape[1]} cylinders (viscous coefficient 8..250 N s/m "
                     f"x friction drop 1..120 N): the critical curve and the simulation agree on "
                     f"**{100 * grid['agreement']:.1f} %** of the {n} points.", "![map](critical_curve.png)"]
    write_report(out, "Stick-slip of paper B's pneumatic cylinder", sections)
