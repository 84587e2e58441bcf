"""Simulate the CMC for a parameter file with exact stick-slip; write timeseries.csv, metrics.json and a WOB figure."""

from __future__ import annotations

import argparse


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Add the arguments of ``heavecomp simulate`` to its parser.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The sub-command's parser (:func:`heavecomp.cli.build_parser`).
    """
    p.add_argument("params", metavar="PARAMS.toml", help="CMC parameter file (contract: docs/contracts/parameter-file.md)")
    p.add_argument("--duration", type=float, required=True, metavar="S", help="simulated time [s]")
    p.add_argument("--out", required=True, metavar="DIR", help="output folder")
    p.add_argument("--heave-file", default=None, metavar="LOG",
                   help="drive the plant with a measured heave (the [heave] table becomes kind = \"file\"), "
                        "pre-processed as the diagnosis' replay; a log with a wob column also gets the WOB error "
                        "against it, on its held-out part (metrics.json against_log)")
    p.add_argument("--columns", default=None, metavar="t=NAME,...",
                   help="with a heave file (--heave-file, or [heave] kind = \"file\"): map contract columns to the "
                        "file's, e.g. t=Time,heave=MRU_heave,wob=WOB (overrides [measurement] columns)")
    p.add_argument("--units", default=None, metavar="t=ms,...",
                   help="with a heave file: declare units, e.g. t=ms,stroke=mm (overrides [measurement] units)")
    p.add_argument("--rate", type=float, default=20.0, metavar="HZ", help="output sample rate [Hz] (default 20)")
    p.add_argument("--dt", type=float, default=None, metavar="S",
                   help="RK4 step [s] (default: h * fastest plant rate <= 0.6, at most 50 ms)")
    p.add_argument("--friction", default=None, metavar="MODEL",
                   help="override friction.model (none | stribeck | rotating_eq6 | rotating_eq7)")
    p.add_argument("--controller", default="passive", choices=("passive", "pid", "linear-mpc", "nonlinear-mpc"),
                   help="active-cylinder controller (default passive: no active force); limits from [active]; "
                        "adds u_active to timeseries.csv and solve times / violations to metrics.json")
    p.add_argument("--controller-option", action="append", default=[], metavar="KEY=VALUE",
                   help="controller setting (repeatable), e.g. horizon=30, q_wob=1e-6, model_frame=stroke, "
                        "nlp_solver=ipopt; names: heavecomp.controllers.ControllerConfig (docs/control.md)")
    p.add_argument("--controller-params", default=None, metavar="DESIGN.toml",
                   help="design the controller on this file (its model and [[effects]]) and run it against the plant "
                        "of PARAMS.toml (its [[effects]] the true plant and sensors; its [active] the actuator), e.g. "
                        "the nominal's controller on the calibrated rig (docs/control.md)")
    p.add_argument("--no-noise", action="store_true",
                   help="closed loop: exact measurements (default: Gaussian sensor noise, stroke 1 mm, "
                        "pressure 5 kPa, WOB 0.5 kN, heave 5 mm)")
    p.add_argument("--perfect-preview", action="store_true",
                   help="closed loop: give the controller the true future heave over its horizon "
                        "(default: predicted online from the measured heave)")


def run(args) -> int:
    """Run ``heavecomp simulate``: the parameter file simulated for ``--duration`` [s] (passive, or with
    the active controller of ``--controller`` in the loop), ``timeseries.csv``, ``metrics.json`` and the
    WOB figure written to ``--out`` and the WOB summary printed on one line.

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
    from pathlib import Path

    from heavecomp.commands._progress import Progress
    from heavecomp.effects.spec import load  # the file with its [[effects]] checked
    from heavecomp.report.background import BackgroundFigure
    from heavecomp.report.simulation import write_outputs
    from heavecomp.simulate import simulate

    params = _heave_file(args, load(args.params, heave_file=args.heave_file is None))
    if args.friction:
        params = params.replace(friction={"model": args.friction})
    _need_space(args)
    if args.controller != "passive":
        return _run_closed_loop(args, params, Progress)
    for flag, given in (("--controller-option", args.controller_option), ("--no-noise", args.no_noise),
                        ("--perfect-preview", args.perfect_preview), ("--controller-params", args.controller_params)):
        if given:
            from heavecomp.errors import InputError

            raise InputError(f"{flag} needs --controller pid|linear-mpc|nonlinear-mpc")
    bar = Progress(f"simulate {args.duration:g} s")
    figure = BackgroundFigure()  # imports matplotlib in parallel with the simulation
    try:
        res = simulate(params, args.duration, dt=args.dt, rate=args.rate, progress=bar)
    except BaseException:
        figure.cancel()
        raise
    big = res.data.shape[0] > 200_000  # a bar only where writing takes a noticeable time
    m = write_outputs(res, args.out, title=f"WOB — {Path(args.params).name}, friction: {params.friction.model}",
                      figure=figure, progress=Progress("writing timeseries.csv") if big else None)
    from heavecomp.report.provenance import finish
    from heavecomp.commands._output import final

    log_line = _against_log(res, params, Path(args.out) / "metrics.json")
    finish(args.out, params=params, csv_files=("timeseries.csv",))
    print(f"WOB mean {m['wob_mean'] / 1e3:.2f} kN, std {m['wob_std'] / 1e3:.2f} kN, "
          f"peak-to-peak {m['wob_p2p'] / 1e3:.2f} kN, stuck {100 * m['stick_fraction']:.1f} % of the time"
          f"{log_line} -> {final(args)}")
    return 0


def _heave_file(args, params):
    """``params`` with ``--heave-file`` as its ``[heave]`` (kind ``file``) and ``--columns``/``--units`` over its
    ``[measurement]``; the flags' one-line errors before any work."""
    from pathlib import Path

    from heavecomp.errors import InputError
    from heavecomp.io.series import check_spec, parse_mapping
    from heavecomp.params.cmc import check_heave_path
    from heavecomp.params.measurement import used

    columns, units = check_spec(parse_mapping(args.columns, "--columns"), parse_mapping(args.units, "--units"),
                                "cli")
    if args.heave_file is None:
        if (columns or units) and (params.heave is None or params.heave.kind != "file"):
            raise InputError("--columns/--units map a heave file's columns: give --heave-file LOG (or a parameter "
                             "file with [heave] kind = \"file\")")
        return used(params, columns, units)
    path = str(Path(args.heave_file).resolve())
    gone = {k: None for k in ("amplitude", "period", "hs", "tp", "gamma", "seed", "ramp")}
    params = used(params.replace(heave={**gone, "kind": "file", "path": path}), columns, units)
    try:
        check_heave_path(params.heave, None)
    except InputError as exc:
        raise InputError(str(exc).replace("heave.path", "--heave-file", 1)) from None
    return params


def _against_log(res, params, metrics_path) -> str:
    """With a heave file (``[heave] kind = "file"``) that is a measured run: the simulation's error against its
    output channels (:func:`heavecomp.diagnosis.compare.against_log`), added to ``metrics.json``; returns the
    summary's words."""
    import json
    import math

    heave = params.heave
    if heave is None or heave.kind != "file":
        return ""
    from pathlib import Path

    from heavecomp.diagnosis.compare import against_log
    from heavecomp.report.diagnosis import CH_UNITS

    d = json.loads(metrics_path.read_text(encoding="utf-8"))  # its "heave" block says how the heave was pre-processed
    ch = {c: res[c] for c in ("heave", "wob", "stroke", "pressure")}
    got = against_log(res["t"], ch, Path(params.base_dir or ".") / heave.path, params)
    words = ""
    if got is not None:
        d["against_log"] = got
        c = got["channel"]
        unit, sc = CH_UNITS[c]
        words = "".join(f"{label} {v * sc:.3g} {unit}" for label, v in (
            (f"; {c} error against the log", got["rms"][c]),
            (", held-out", got["rms_validate"][c])) if math.isfinite(v))  # no sample compared: no number
        if math.isfinite(got["rms_validate"][c]):
            words += f" (after {got['split']['validate'][0]:.0f} s)"
    metrics_path.write_text(json.dumps(d, indent=2) + "\n", encoding="utf-8")
    return words


def _run_closed_loop(args, params, Progress) -> int:
    """Active heave compensation: controller in the loop (heavecomp.closed_loop.loop)."""
    from pathlib import Path

    from heavecomp.controllers.base import parse_options
    from heavecomp.params.cmc import active
    from heavecomp.closed_loop.loop import Noise, output_every, simulate_closed_loop
    from heavecomp.report.simulation import write_closed_loop_outputs

    output_every(args.rate, active(params).control_rate)  # bad --rate fails before the run
    options = parse_options(args.controller_option)
    plant_fx, ctrl, design_name = _plant_and_controller(args, params, options)
    bar = Progress(f"simulate {args.duration:g} s, {args.controller}")
    res = simulate_closed_loop(params, ctrl, args.duration, dt=args.dt, progress=bar, effects=plant_fx,
                               noise=None if args.no_noise else Noise(),
                               preview="perfect" if args.perfect_preview else "predicted")
    design = f", designed on {design_name}" if args.controller_params else ""
    m = write_closed_loop_outputs(res, args.out, title=f"WOB — {Path(args.params).name}, friction: "
                                  f"{params.friction.model}, controller: {args.controller}{design}", rate=args.rate)
    from heavecomp.report.provenance import finish
    from heavecomp.commands._output import final

    finish(args.out, params=params, csv_files=("timeseries.csv",))
    print(f"WOB std {m['wob_std'] / 1e3:.2f} kN, peak-to-peak {m['wob_p2p'] / 1e3:.2f} kN, "
          f"|u_active| max {m['u_active_max'] / 1e3:.1f} kN, solve p50/p99 {m['solve_time_ms_p50']:.2f}/"
          f"{m['solve_time_ms_p99']:.2f} ms, fallbacks {m['fallbacks']} -> {final(args)}")
    return 0


def _plant_and_controller(args, params, options):
    """``(the true plant's effects, the controller, the design file's name)`` of a closed-loop run.

    The plant is PARAMS.toml with all its ``[[effects]]`` but the heave's: its plant terms at their hooks and its
    reading effects on the measurements the controller receives (the rig's sensors misread so).  The controller
    is designed on ``--controller-params`` (default the same file): its parameters, its plant effects in the
    model and its reading effects in how it reads them (docs/control.md: a ``sensor_lag`` is read through its
    factor with a warning, a bare ``sensor_delay`` is refused); the actuator (``[active]``) is the plant's.
    """
    import dataclasses
    import logging
    from pathlib import Path

    from heavecomp.controllers.registry import make, takes_effects
    from heavecomp.effects.spec import check, load
    from heavecomp.errors import ParameterError
    from heavecomp.params.cmc import active

    log = logging.getLogger("heavecomp")
    fx = check(params)
    for i, e in enumerate(fx):
        if e.kind == "heave":  # the closed loop runs one heave for the plant and the controller's measurement
            log.warning("%s: effects[%d] %s: the heave the compensator sees is not modelled in the closed loop; the "
                        "plant runs on the heave as measured", Path(args.params).name, i, e.name)
    plant_fx = [e for e in fx if e.kind != "heave"]
    design, design_name = params, Path(args.params).name
    if args.controller_params:
        design_name = Path(args.controller_params).name
        design = load(args.controller_params, heave_file=False)
        if design.extra.get("active") and active(design) != active(params):
            log.warning("%s: [active] differs from %s's; the actuator is the plant's", design_name,
                        Path(args.params).name)
        design = design.replace(active=dataclasses.asdict(active(params)))
    model_fx = check(design) if takes_effects(args.controller) else None
    try:
        ctrl = make(args.controller, design, effects=model_fx, **options)
    except ParameterError as exc:
        if model_fx is None or str(exc).startswith(design_name):
            raise
        raise ParameterError(f"{design_name} [[effects]]: {exc}") from None
    return plant_fx, ctrl, design_name


#: bytes per value of timeseries.csv, a low estimate (``%.10g`` and a comma take 8-18)
CSV_BYTES_PER_VALUE = 8


def _need_space(args) -> None:
    """Refuse before the run when timeseries.csv cannot fit on the output's file system."""
    import math

    from heavecomp.commands._output import final
    from heavecomp.params.budget import MAX_BYTES
    from heavecomp.report.output import need_space
    from heavecomp.simulate.core import CSV_COLUMNS

    if not (math.isfinite(args.duration) and math.isfinite(args.rate)) or args.duration <= 0 or args.rate <= 0:
        return  # the simulation's own checks name these
    rows = args.duration * args.rate + 1
    if 8 * rows * (len(CSV_COLUMNS) + 1) > MAX_BYTES:
        return  # over the run-size budget: the simulation refuses it, naming --duration and --rate
    need_space(args.out, rows * (len(CSV_COLUMNS) + 1) * CSV_BYTES_PER_VALUE, "--out", final(args))
