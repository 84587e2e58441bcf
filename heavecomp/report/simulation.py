"""Outputs of ``heavecomp simulate`` (open and closed loop): the contract CSV, metrics and the WOB figure."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Callable

from heavecomp.closed_loop.loop import ClosedLoopResult, output_every
from heavecomp.report.figures import plot_wob, plot_wob_run, save
from heavecomp.report.provenance import declare_units, table_units
from heavecomp.simulate.core import SimulationResult


def write_outputs(res: SimulationResult, out_dir, *, title: str | None = None, figure=None,
                  progress: Callable[[float], None] | None = None) -> dict:
    """Write ``timeseries.csv``, ``metrics.json`` and ``wob.png`` into ``out_dir``.

    ``figure`` may be a :class:`heavecomp.report.background.BackgroundFigure`
    started before the simulation (the CLI does), so the figure is drawn in
    parallel with the CSV.  ``progress(fraction)`` follows the CSV being written.

    Parameters
    ----------
    res : heavecomp.simulate.SimulationResult
        The simulation.
    out_dir : str or os.PathLike
        Output folder (created if missing).
    title : str or None
        Title of the figure.
    figure : heavecomp.report.background.BackgroundFigure or None
        A figure process already started (None: drawn here after the CSV).
    progress : callable or None
        ``progress(fraction)`` [-] while the CSV is written.

    Returns
    -------
    dict
        The metrics as written to ``metrics.json`` (with their units and the ``heave`` block).
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    if figure is not None:
        figure.draw(plot_wob_run, res, title=title, path=out_dir / "wob.png", save_kwargs={"tight": False, "dpi": 100})
    res.to_csv(out_dir / "timeseries.csv", progress=progress)
    metrics = declare_units(res.metrics(), res.METRIC_UNITS)
    metrics["heave"] = heave_block(res.heave_info)
    (out_dir / "metrics.json").write_text(json.dumps(metrics, indent=2) + "\n")
    if figure is None:
        save(plot_wob_run(res, title=title), out_dir / "wob.png", tight=False, dpi=100)
    else:
        figure.wait()
    return metrics

#: units of heave entries that are not keys of the [heave] table (made by heavecomp.simulate.excitation)
HEAVE_INFO_UNITS = {"repeat_period": "s", "kind": "", "source": ""}


def heave_block(info: dict) -> dict:
    """The heave's description for metrics.json, each number with the unit of its ``[heave]`` key.

    Parameters
    ----------
    info : dict
        The heave's description (``SimulationResult.heave_info``).

    Returns
    -------
    dict
        Its numbers and strings, units declared.
    """
    block = {k: v for k, v in info.items() if isinstance(v, (int, float, str))}
    units = {**table_units("heave"), **HEAVE_INFO_UNITS}
    return declare_units(block, {k: units[k] for k in block if k in units})


def write_closed_loop_outputs(res: ClosedLoopResult, out_dir, *, title: str | None = None,
                              rate: float | None = None) -> dict:
    """Write ``timeseries.csv`` (with ``u_active``; at ``rate`` [Hz], which must divide
    the control rate; default the control rate), ``metrics.json`` and ``wob.png``.

    Parameters
    ----------
    res : heavecomp.closed_loop.ClosedLoopResult
        The closed-loop run.
    out_dir : str or os.PathLike
        Output folder (created if missing).
    title : str or None
        Title of the figure.
    rate : float or None [Hz]
        Output rate of the CSV.

    Returns
    -------
    dict
        The metrics as written to ``metrics.json``.
    """
    every = output_every(rate, res.control["control_rate"])
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    res.to_csv(out_dir / "timeseries.csv", every=every)
    metrics = res.metrics()  # the controller's entries: units by name until ClosedLoopResult declares them
    declare_units(metrics, {k: u for k, u in res.METRIC_UNITS.items() if k in metrics})
    metrics["heave"] = heave_block(res.heave_info)
    (out_dir / "metrics.json").write_text(json.dumps(metrics, indent=2) + "\n")
    save(plot_wob({res.controller: res}, title=title, force=res.controller != "passive"), out_dir / "wob.png")
    return metrics
