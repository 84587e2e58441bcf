"""One log replayed under several parameter files, exactly as the diagnosis replays it (``heavecomp replay``).

>>> from heavecomp.diagnosis import replay_files                                  # doctest: +SKIP
>>> cmp = replay_files("rig.csv", ["nominal.toml", "diag/calibrated.toml"])        # doctest: +SKIP
>>> cmp.ranking(), cmp.to_json()["models"][1]["gap_to_noise_validate"]             # doctest: +SKIP

Each file reads the log with its own ``[measurement]`` mapping (``columns``/``units`` override it key by
key) and its own reading effects, and is replayed by :func:`heavecomp.diagnosis.replay.prepare`, the
diagnosis' own preparation: the same span of a long log (:mod:`heavecomp.diagnosis.span`), the same
heave pre-processing (gap-filled, uniform, zero-phase low-pass at ``HEAVE_CUTOFF``), the same start-state
estimate, the file's plant effects, the same fit / held-out split and the same noise floor (the output
noise and what the heave noise makes of the replay).  Each prediction is read as the rig's sensors read it
under that file (:func:`heavecomp.diagnosis.calibrate.as_recorded`) and compared with the log as it was
recorded, so every file is measured against the same samples; a file without reading effects gives the
held-out rms and noise floor its ``diagnosis.json`` reports (``gap.channels.<c>.rms_validate``,
``noise_floor``).

A calibrated model is tested on a log it was not fitted on: another day, another sea state
(docs/diagnosis.md, "Replay a log under several files").
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from heavecomp.diagnosis import replay as R
from heavecomp.diagnosis import span as SP
from heavecomp.diagnosis.calibrate import as_recorded
from heavecomp.diagnosis.data import load_run
from heavecomp.diagnosis.estimator import GapDiagnoser
from heavecomp.diagnosis.policy import VerdictPolicy
from heavecomp.effects.spec import load, reading_effects
from heavecomp.errors import InputError

#: SI units of the compared channels (replay.json ``units``)
UNITS = {"wob": "N", "stroke": "m", "pressure": "Pa"}


@dataclasses.dataclass
class ModelReplay:
    """One file's replay of the log: per channel the rms of prediction minus log after the settling window
    (``rms``) and on the held-out part (``rms_validate``) [SI], the noise floor [SI] and their ratios."""

    name: str
    rms: dict
    rms_validate: dict
    noise_floor: dict
    pred: dict
    initial_state: dict
    warnings: list

    @property
    def gap_to_noise(self) -> dict:
        return {c: self.rms[c] / self.noise_floor[c] for c in self.rms}

    @property
    def gap_to_noise_validate(self) -> dict:
        return {c: self.rms_validate[c] / self.noise_floor[c] for c in self.rms_validate}


@dataclasses.dataclass
class ReplayComparison:
    """The log and its replays under every file (:func:`replay_files`)."""

    source: str
    t: np.ndarray
    measured: dict
    models: list
    split: dict
    span: dict
    channels: tuple
    measurement: dict
    #: the figure's zoom (start, end) [s] within the span, checked against it (None: the whole span)
    window: tuple | None = None

    @property
    def primary(self) -> str:
        """The channel the files are ranked on: WOB, else the first of stroke, pressure the log has."""
        return self.channels[0]

    def ranking(self) -> list:
        """File names, best first: the smallest held-out gap over the noise floor on :attr:`primary`."""
        return [m.name for m in sorted(self.models, key=lambda m: m.gap_to_noise_validate[self.primary])]

    def shrink(self, model: ModelReplay) -> float:
        """Held-out shrink of ``model`` against the first file on :attr:`primary`: 1 - rms / rms of the first
        (the diagnosis' ``shrink`` when the first is the nominal and ``model`` its calibrated file)."""
        ref = self.models[0].rms_validate[self.primary]
        return 1.0 - model.rms_validate[self.primary] / ref if ref > 0 else 0.0

    def to_json(self) -> dict:
        """``replay.json`` (contract schema 4) plus ``rms_validate``, ``noise_floor``, ``shrink_validate`` per
        model, the ``span``, ``channel`` (the primary) and how the log was read."""
        return {"schema": 4, "log": self.source, "channel": self.primary,
                "models": [{"params": m.name, "gap_to_noise": m.gap_to_noise,
                            "gap_to_noise_validate": m.gap_to_noise_validate, "rms": m.rms,
                            "rms_validate": m.rms_validate, "noise_floor": m.noise_floor,
                            "shrink_validate": self.shrink(m), "initial_state": m.initial_state,
                            "warnings": m.warnings} for m in self.models],
                "ranking": self.ranking(),
                "split": self.split, "span": self.span,
                "units": {"rms": {c: UNITS[c] for c in self.channels},
                          "rms_validate": {c: UNITS[c] for c in self.channels},
                          "noise_floor": {c: UNITS[c] for c in self.channels}},
                "measurement": self.measurement}


def _read(log, params, name, columns, units, span):
    """The log read under ``params`` (its mapping, its reading effects) and cut to the diagnosis' span."""
    try:
        run = load_run(log, params, columns=columns, units=units)
    except InputError as exc:
        raise type(exc)(f"reading the log with {name}: {exc}") from None
    SP.check_length(run, "replay", "log")
    sp = SP.choose(run.duration, span)
    return SP.cut(run, sp), sp


def replay_files(log, params, *, names=None, columns=None, units=None, split=0.67, settle=None, span=None,
                 window=None, progress=None) -> ReplayComparison:
    """Replay the log ``log`` under each parameter file of ``params`` as the diagnosis does (module docstring).

    Parameters
    ----------
    log : str or Path, or pandas.DataFrame
        The measured log, as :func:`heavecomp.diagnosis.data.load_run` takes it.
    params : sequence of str, Path or CMCParams
        The parameter files (paths are read with their ``[[effects]]`` checked).
    names : sequence of str, optional
        Names of the files in the results (default: the paths as given; ``model_<i>`` for a parameter set).
    columns, units : dict, optional
        Contract name -> the log's column / unit; override each file's ``[measurement]`` key by key.
    split : float [-]
        Fraction of the (span of the) log in the fit part; the rest is held out (the diagnosis' default 0.67).
    settle : float [s] or None
        Start-up window left out (None: the diagnosis' default, min(30 s, 10 % of the log)).
    span : tuple (start, end) [s] or None
        The stretch replayed (:func:`heavecomp.diagnosis.span.parse`); None: the diagnosis' default
        (a log up to 1200 s whole, a longer one its last 600 s).
    window : tuple (start, end) [s] or None
        A zoom of the replayed span for the figure (either end None: the span's), checked against the span
        before any replay; None: the whole span.
    progress : callable(fraction, message), optional

    Returns
    -------
    ReplayComparison
    """
    params = list(params)
    if not params:
        raise InputError("give at least one parameter file", option="params")
    names = [str(p) if isinstance(p, (str, Path)) else f"model_{i + 1}" for i, p in enumerate(params)] \
        if names is None else [str(n) for n in names]
    seen = [n for i, n in enumerate(names) if n in names[:i]]
    if seen:
        raise InputError(f"{seen[0]} given twice: give each file once", option="params")
    files = [load(p, heave_file=False) if isinstance(p, (str, Path)) else p for p in params]
    d = GapDiagnoser(files[0])  # the diagnosis' own replay settings
    models, first = [], None
    for k, (name, P) in enumerate(zip(names, files)):
        if progress:
            progress(k / len(files), f"replaying under {name}")
        run, sp = _read(log, P, name, columns, units, span)
        raw = run if not reading_effects(P) else _read(log, P.replace(effects=[]), name, columns, units, span)[0]
        if first is None:
            first = (raw, sp, run)
            window = _window(window, float(run.t[-1]))
        elif raw.t.size != first[0].t.size:
            raise InputError(f"{name} reads {raw.t.size} samples of the log, {names[0]} {first[0].t.size}: "
                             "give the files the same [measurement] mapping, or the mapping for all of them",
                             option=("columns", "units"))
        ctx = R.prepare(run, P, split=split, settle=settle, stuck_speed=d.stuck_speed, segment=d.segment,
                        reinit=d.reinit, input_draws=d.input_draws, policy=VerdictPolicy())
        pred = {c: as_recorded(P, run.t, ctx.nominal_pred, c, run["heave"]) for c in ctx.channels}
        rms, rms_v = {}, {}
        for c in ctx.channels:
            y = raw[c]
            for out, mask in ((rms, ctx.allmask), (rms_v, ctx.valmask)):
                m = mask & np.isfinite(y) & np.isfinite(pred[c])
                out[c] = float(np.sqrt(np.mean((pred[c][m] - y[m]) ** 2))) if m.any() else math.nan
        models.append(ModelReplay(name, rms, rms_v, {c: float(ctx.noise_floor[c]) for c in ctx.channels}, pred,
                                  ctx.replay.initial.to_json(), R.start_warnings(ctx.replay.initial, P)))
        split_ = ctx.split
        chans = ctx.channels
    raw, sp, run0 = first
    if progress:
        progress(1.0, "done")
    return ReplayComparison(raw.source, raw.t, {c: raw[c] for c in ("heave",) + chans}, models, split_,
                            sp.to_json(), chans, run0.measurement or {}, window)


def _window(window, end: float):
    """``window`` (start, end) [s] (either None) within a span ending at ``end`` [s]; one-line error."""
    if window is None:
        return None
    lo = 0.0 if window[0] is None else float(window[0])
    hi = end if window[1] is None else min(float(window[1]), end)
    if lo >= end:
        raise InputError(f"window START {lo:g} s is past the replayed span's end ({end:.6g} s)", option="window")
    return (lo, hi)


def against_log(t, channels: dict, log, params, *, split=0.67, settle=None) -> dict | None:
    """A simulation driven by a measured log's heave (``[heave] kind = "file"``) compared with the log's own
    output channels: per channel the rms of simulation minus log after the settling window and on the
    diagnosis' held-out part (the last ``1 - split`` of the simulated span of the log, as the diagnosis splits
    its span) [SI].  The log is read as recorded (its
    ``[measurement]`` mapping, no reading effect undone) and the simulation as the rig's sensors read it under
    the file (its ``[[effects]]`` readings applied: ``simulate`` records the plant's true channels), as
    :func:`replay_files` compares.  None when the heave file holds none of wob, stroke, pressure.

    Parameters
    ----------
    t : numpy.ndarray [s]
        The simulation's output times (from 0 at the log's first sample).
    channels : dict
        The simulation's channels {heave, wob, stroke, pressure: array} [SI] (its heave and stroke: the string
        top's motion a reading may read).
    log : str or Path
        The heave file, a measured run.
    params : CMCParams
        The simulated file (its ``[measurement]`` mapping).
    split : float [-]
        Fraction of the log in the fit part (the diagnosis' default).
    settle : float [s] or None
        Start-up window left out (None: the diagnosis' default).
    """
    try:
        raw = load_run(log, params.replace(effects=[]))
    except InputError:
        return None  # a heave record, not a measured run: nothing to compare with
    chans = R.present(raw)
    if not chans:
        return None
    end = min(float(t[-1]), raw.duration)  # the simulated span: a shorter simulation is split on its own length
    if end < raw.duration:
        raw = SP.cut(raw, SP.Span(0.0, end, raw.duration, "simulated", f"the simulated 0-{end:g} s"))
    sp = R.split_of(raw, split, settle)
    tl = raw.t - raw.t[0]
    inside = tl <= t[-1] + 1e-9
    out = {"log": str(log), "channel": chans[0], "split": sp, "rms": {}, "rms_validate": {},
           "units": {c: UNITS[c] for c in chans}}
    read = [e for e in reading_effects(params) if getattr(e, "channel", None) in chans]
    motion = np.asarray(channels["heave"]) + np.asarray(channels["stroke"]) if read else None
    for c in chans:
        y = raw[c]
        pred = np.interp(tl, t, channels[c])
        mine = [e for e in read if e.channel == c]
        if mine:  # the file's readings (a gain, a lag, ...): the simulation read as the rig's sensors read it
            pred = mine[0].measure(tl, t, channels[c], motion=motion)
            for e in mine[1:]:
                pred = e.measure(tl, tl, pred, motion=np.interp(tl, t, motion))
        for key, mask in (("rms", tl >= sp["settle"]), ("rms_validate", tl >= sp["validate"][0])):
            m = mask & inside & np.isfinite(y)
            out[key][c] = float(np.sqrt(np.mean((pred[m] - y[m]) ** 2))) if m.any() else math.nan
    return out


__all__ = ["ModelReplay", "ReplayComparison", "against_log", "replay_files"]
