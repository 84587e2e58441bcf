"""Simulate the CMC with exact stick-slip: ``simulate(params, duration) -> SimulationResult``."""

from __future__ import annotations

import dataclasses
import logging
import math
import time
from pathlib import Path
from typing import Callable

import numpy as np

from heavecomp.effects.registry import split_effects
from heavecomp.effects.spec import effects_for
from heavecomp.errors import InputError
from heavecomp.params.budget import check_run_size
from heavecomp.plants.cmc import eigen_rate, plant_vectors
from heavecomp.simulate import excitation, layout
from heavecomp.simulate.layout import CHANNELS, NCH, STATS, STUCK, Drive
from heavecomp.simulate.stepper import heave_at, nominal, plant_stepper  # noqa: F401 (plant_stepper: re-exported)

log = logging.getLogger(__name__)


class SimulationError(InputError):
    """The integration failed (e.g. diverged for a step too large for the parameters)."""


#: columns written to timeseries.csv (contract columns first)
CSV_COLUMNS = ("t", "heave", "stroke", "pressure", "wob", "stroke_velocity", "friction", "tension", "stuck")
#: unit of every channel (SI; ``stuck`` is 1 while the main cylinder sticks, else 0)
CHANNEL_UNITS = {"t": "s", "heave": "m", "stroke": "m", "pressure": "Pa", "wob": "N", "stroke_velocity": "m/s",
                 "friction": "N", "tension": "N", "lower_displacement": "m", "lower_velocity": "m/s", "stuck": "-",
                 "u_active": "N"}


def default_dt(params, rate: float | None = None) -> float:
    """Default RK4 step [s]: ``h * lambda_max <= 0.6`` and at most 50 ms (and a
    divisor of the output interval 1/rate when ``rate`` is given).

    ``lambda_max`` is :func:`heavecomp.plants.cmc.eigen_rate` (fastest mode of the plant's
    linear model, including the steepest friction slope).  RK4 is stable to h lambda ~ 2.8; at 0.6 the
    paper-A case with full static friction is within 15 N rms of WOB (1 h, vs
    dt = 1 ms), ~0.03 % of its WOB std (``docs/numerics.md``).  Pass ``dt``
    explicitly for more accuracy: the scheme converges with order 4.

    Parameters
    ----------
    params : CMCParams
        Validated parameter set (:mod:`heavecomp.params`).
    rate : float [Hz], optional
        Output sampling rate; the step is made a divisor of its interval 1/rate (None: no such
        constraint).
    """
    h = min(0.05, 0.6 / eigen_rate(params))
    if rate:
        interval = 1.0 / rate
        h = interval / math.ceil(interval / h - 1e-9)
    return h


def write_csv(path, data: np.ndarray, columns, fmt: str = "%.10g", block: int = 8192,
              progress: Callable[[float], None] | None = None) -> Path:
    """CSV with a header row; formats whole blocks of rows at once (~2x np.savetxt).

    Parameters
    ----------
    path : str or Path
        File to write (overwritten).
    data : (n, ncol) array
        Rows to write, one column per entry of ``columns`` (units as the caller's channels).
    columns : sequence of str
        Header names.
    fmt : str
        printf-style format of one value.
    block : int
        Rows formatted at once.
    progress : callable(fraction), optional
        Called as ``progress(fraction)`` after each block (the CLI draws a bar for large files).
    """
    path = Path(path)
    ncol = data.shape[1]
    n = data.shape[0]
    row = ",".join([fmt] * ncol) + "\n"
    with path.open("w") as fh:
        fh.write(",".join(columns) + "\n")
        for i in range(0, n, block):
            blk = data[i:i + block]
            fh.write((row * blk.shape[0]) % tuple(blk.ravel().tolist()))
            if progress is not None:
                progress(min(i + block, n) / n)
    if progress is not None and n == 0:
        progress(1.0)
    return path


@dataclasses.dataclass
class SimulationResult:
    """Named channels of a simulation plus bookkeeping.

    ``res["wob"]`` gives a channel; ``res.metrics()`` the summary statistics;
    ``res.to_csv(path)`` the contract CSV.  Channels: :data:`CHANNELS`.
    """

    data: np.ndarray  # (n, len(CHANNELS))
    params: object
    dt: float
    stats: dict
    heave_info: dict
    wall_time: float = 0.0
    stats_start: float = 0.0

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self.data[:, CHANNELS.index(name)]
        except ValueError:
            raise KeyError(f"no channel {name!r}; channels: {', '.join(CHANNELS)}") from None

    @property
    def t(self) -> np.ndarray:
        return self["t"]

    def window(self, start: float | None = None) -> np.ndarray:
        """Boolean mask of samples at t >= start (default: after the fade-in)."""
        return self.t >= (self.stats_start if start is None else start) - 1e-12

    #: unit of each entry of :meth:`metrics`, declared beside it (metrics.json's units come from here)
    METRIC_UNITS = {"wob_mean": "N", "wob_std": "N", "wob_min": "N", "wob_max": "N", "wob_p2p": "N",
                    "wob_setpoint": "N", "stick_fraction": "-", "stick_fraction_total": "-", "n_stick": "count",
                    "n_breakaway": "count", "n_reversal": "count", "event_cap_hits": "count",
                    "event_cap_first_t": "s", "friction_power_min": "W", "n_negative_friction_power": "count",
                    "stroke_max": "m", "pressure_min": "Pa", "pressure_max": "Pa", "heave_std": "m",
                    "k_eff_eq14": "N/m", "stats_window": "s", "duration": "s", "dt": "s", "friction_model": "",
                    "wall_time_s": "s"}

    def metrics(self, start: float | None = None) -> dict:
        """WOB statistics over t >= start (default: after the heave fade-in) [N, m, -];
        units in :attr:`METRIC_UNITS`."""
        m = self.window(start)
        w = self["wob"][m]
        duration = float(self.t[-1])
        st = self.stats
        return {
            "wob_mean": float(np.mean(w)),
            "wob_std": float(np.std(w)),
            "wob_min": float(np.min(w)),
            "wob_max": float(np.max(w)),
            "wob_p2p": float(np.ptp(w)),
            "wob_setpoint": float(self.params.operating_point.wob_setpoint),
            "stick_fraction": float(np.mean(self["stuck"][m])),
            "stick_fraction_total": st["stuck_time"] / duration if duration > 0 else 0.0,
            "n_stick": int(st["n_stick"]),
            "n_breakaway": int(st["n_breakaway"]),
            "n_reversal": int(st["n_reversal"]),
            "event_cap_hits": int(st.get("event_cap_hits", 0)),
            "event_cap_first_t": st["event_cap_first_t"] if st.get("event_cap_hits", 0) else None,
            "friction_power_min": float(np.min(self.friction_power())) + 0.0 if len(self.data) else 0.0,  # no -0.0
            "n_negative_friction_power": int(np.count_nonzero(self.friction_power() < 0.0)),
            "stroke_max": float(np.max(np.abs(self["stroke"][m]))),
            "pressure_min": float(np.min(self["pressure"][m])),
            "pressure_max": float(np.max(self["pressure"][m])),
            "heave_std": float(np.std(self["heave"][m])),
            "k_eff_eq14": float(self.params.k_eff),
            "stats_window": [float(self.t[m][0]), duration],
            "duration": duration,
            "dt": self.dt,
            "friction_model": self.params.friction.model,
            "wall_time_s": self.wall_time,
        }

    def friction_power(self) -> np.ndarray:
        """Friction power F_f v [W] at each sample: >= 0 (friction only dissipates), exactly 0 while stuck."""
        return self["friction"] * self["stroke_velocity"]

    @property
    def event_cap_hits(self) -> int:
        """Steps that hit the stepper's event cap (finished without event location; should be 0)."""
        return int(self.stats.get("event_cap_hits", 0))

    def to_csv(self, path, columns=CSV_COLUMNS, progress: Callable[[float], None] | None = None) -> Path:
        idx = [CHANNELS.index(c) for c in columns]
        return write_csv(path, self.data[:, idx], columns, progress=progress)

    def to_dict(self) -> dict[str, np.ndarray]:
        return {c: self.data[:, i] for i, c in enumerate(CHANNELS)}

    def to_pandas(self, columns=None, *, time_index: bool = True):
        """The channels as a ``pandas.DataFrame`` (pandas imported only here).

        Follows python-control's ``TimeResponseData.to_pandas``: one column per signal, named
        by the signal, time labelled ``"time"`` — here the index (``time_index=False`` gives
        python-control's layout with ``time`` as the first column).  Units are in
        ``df.attrs["units"]`` (column -> unit, SI; :data:`CHANNEL_UNITS`); ``stuck`` is a bool.

        Parameters
        ----------
        columns : sequence of str, optional
            Channels to include (default every channel of :data:`CHANNELS` but ``t``).
        time_index : bool
            Index the frame by time [s] (default) or keep ``time`` as a column.
        """
        import pandas as pd

        cols = [c for c in (columns or CHANNELS) if c != "t"]
        for c in cols:
            if c not in CHANNELS:
                raise KeyError(f"no channel {c!r}; channels: {', '.join(CHANNELS)}")
        data = {c: (self[c] > 0.5) if c == "stuck" else self[c] for c in cols}
        df = pd.DataFrame(data, index=pd.Index(self.t, name="time"))
        units = {"time": CHANNEL_UNITS["t"], **{c: CHANNEL_UNITS[c] for c in cols}}
        if not time_index:
            df = df.reset_index()
        df.attrs["units"] = units
        return df


def simulate(params, duration: float, *, dt: float | None = None, rate: float = 20.0, heave=None,
             progress: Callable[[float], None] | None = None, stats_start: float | None = None,
             u_active: float = 0.0, effects=None) -> SimulationResult:
    """Simulate the CMC from rest at the operating point with exact stick-slip.

    Parameters
    ----------
    params : CMCParams
        Validated parameter set (:mod:`heavecomp.params`).
    duration : float [s]
        Simulated time.
    dt : float [s], optional
        RK4 step; default :func:`default_dt`.
    rate : float [Hz]
        Output sampling rate (the step is made a divisor of 1/rate).
    heave : HeaveSamples or (t, z) arrays, optional
        Overrides ``params.heave`` (e.g. measured heave).
    progress : callable(fraction), optional
        Called as the run advances (the CLI draws a bar with it).
    stats_start : float [s], optional
        Start of the window for :meth:`SimulationResult.metrics`; default the
        heave fade-in (``heave.ramp``) or 0.
    u_active : float [N]
        Constant active-cylinder force (closed loops use :mod:`heavecomp.controllers`).
    effects : sequence, optional
        Effects at the plant's hooks (:mod:`heavecomp.effects`): instances
        (``FlowLoss(resistance=2e5)``), registered names (default parameters) or
        ``(name, {parameter: value})`` pairs.  None: the plant effects of ``params``' ``[[effects]]``
        (none: the nominal CMC, the ahead-of-time stepper; :func:`heavecomp.effects.spec.effects_for`).
        A heave effect (``heave_reference``) changes the heave the plant sees (the recorded
        ``heave`` stays the measured one); a channel effect (``sensor_gain``, ``sensor_offset``,
        ``sensor_delay``, each with its ``channel``) changes the recorded channel.
    """
    if not (duration > 0 and math.isfinite(duration)):
        raise InputError(f"duration must be a positive number of seconds, got {duration}", option="duration")
    if not (rate > 0 and math.isfinite(rate)):
        raise InputError(f"rate must be a positive number of Hz, got {rate}", option="rate")
    h = dt if dt is not None else default_dt(params, rate)
    if not (h > 0 and math.isfinite(h)):
        raise InputError(f"dt must be a positive number of seconds, got {dt}", option="dt")
    out_every = max(1, int(round(1.0 / (rate * h))))
    if dt is not None and abs(out_every * h * rate - 1.0) > 1e-6:
        log.warning("output interval 1/rate = %g s is not a multiple of dt = %g s; output every %d steps",
                    1 / rate, h, out_every)
    n_steps = int(math.ceil(duration / h - 1e-9))
    check_run_size(params, duration=duration, h=h, n_steps=n_steps, n_rows=n_steps // out_every + 1, n_cols=NCH, dt=dt, rate=rate, rate_fn=eigen_rate)
    sp = 0.5 * h
    if heave is None:
        hs = excitation.make_heave(params.heave, n_steps * h, sp, params.base_dir,
                                     measurement=params.extra.get("measurement"))
    elif isinstance(heave, excitation.HeaveSamples):
        if abs(heave.spacing - sp) > 1e-12 * sp:
            raise ValueError("heave samples must be spaced dt/2")
        hs = heave
    else:
        t_in, z_in = heave
        hs = excitation.from_series(t_in, z_in, n_steps * h, sp, src="heave")
    plant_fx, heave_fx, sensor_fx = split_effects(effects_for(params, effects))
    measured = hs
    for e in heave_fx:  # the heave the plant sees is not the measured one
        hs = e.transform(hs)
    own_step = h <= default_dt(params, rate) * (1 + 1e-9)  # stable for the plant without its effects
    result = run_kernel(plant_vectors(params), hs, h, n_steps, out_every, u_active=u_active, progress=progress,
                        effects=plant_fx, labels=effect_labels(params if effects is None else effects, plant_fx),
                        step_advice=not own_step)
    data, stats, wall = result
    if heave_fx:  # the recorded heave is the measured one (interpolated as the stepper does)
        data[:, CHANNELS.index("heave")] = [heave_at(ti, measured.spacing, measured.z, measured.dz, measured.ddz)[0]
                                            for ti in data[:, 0]]
    for e in sensor_fx:  # a recorded channel that misreads
        k = CHANNELS.index(e.channel)
        data[:, k] = e.measure(data[:, 0], data[:, 0], data[:, k])
    if stats_start is None:
        stats_start = (params.heave.ramp or 0.0) if (heave is None and params.heave is not None) else 0.0
        stats_start = min(stats_start, 0.5 * duration)
    return SimulationResult(data=data, params=params, dt=h, stats=stats, heave_info=hs.info,
                            wall_time=wall, stats_start=stats_start)


def effect_labels(given, effects) -> list:
    """``effects[i] (name)`` for each instance of ``effects``, ``i`` its place in ``given`` (the file's
    ``[[effects]]``: a CMCParams, or the sequence of effects passed), so a message points at the entry to fix.

    Parameters
    ----------
    given : CMCParams or sequence
        Where the effects came from: a parameter set (its ``effects`` specs) or the effects passed.
    effects : sequence of Effect
        The instances (a subset of ``given``'s, in its order).
    """
    entries = list(getattr(given, "effects", given) or ())
    names = [e[0] if isinstance(e, tuple) else (e if isinstance(e, str) else getattr(e, "name", str(e)))
             for e in entries]
    out, i = [], 0
    for e in effects:
        name = getattr(e, "name", str(e))
        j = next((k for k in range(i, len(names)) if names[k] == name), None)
        out.append(f"effects[{j}] ({name})" if j is not None else name)
        i = i if j is None else j + 1
    return out


def run_kernel(plant, hs, h, n_steps, out_every, *, u_active=0.0, progress=None, chunk_steps=200_000, effects=(),
               labels=None, step_advice=True):
    """Run the compiled stepper from rest (stuck) at the operating point.

    Returns ``(data, stats, wall)``: the output rows (columns :data:`CHANNELS`), the stepper's
    counters (:data:`STATS`) and the wall time [s] of the run.

    Parameters
    ----------
    plant : PlantVectors
        The plant (:func:`heavecomp.plants.cmc.plant_vectors`).
    hs : HeaveSamples
        Heave samples spaced h/2 covering the run (:func:`heavecomp.simulate.excitation.make_heave`).
    h : float [s]
        RK4 step.
    n_steps : int
        Number of steps.
    out_every : int
        Steps between output rows.
    u_active : float [N]
        Constant active-cylinder force.
    progress : callable(fraction), optional
        Called after each chunk of steps.
    chunk_steps : int
        Steps per call of the compiled stepper (between progress calls).
    effects : sequence of Effect
        Effect instances at the plant's hooks (:func:`heavecomp.simulate.stepper.plant_stepper`).
    labels : sequence of str, optional
        How a divergence names each effect (:func:`effect_labels`; default their names).
    step_advice : bool
        A divergence with effects also advises a smaller step (False: the step is the plant's own stable
        default, so the effects are the cause).
    """
    n_out = n_steps // out_every + 1
    out = np.empty((n_out, NCH))
    mode_dir = np.array([float(STUCK), 1.0])
    stats = np.zeros(len(STATS))
    advance, state, args = plant_stepper(plant, effects)

    def step(t0, n, Z, DZ, DDZ, pos):
        return advance(state, mode_dir, t0, n, h, args, Drive(float(u_active), 0.5 * h, Z, DZ, DDZ), out,
                       int(out_every), int(pos), stats)

    t0 = time.perf_counter()
    pos = drive(step, hs, h, n_steps, out_every, progress=progress, chunk_steps=chunk_steps)
    wall = time.perf_counter() - t0
    data = out[:pos]
    if not np.isfinite(data).all():
        row = int(np.argmax(~np.isfinite(data).all(axis=1)))
        t_div = data[max(row - 1, 0), 0]
        spike = heave_accel_outlier(hs, data[row, 0] + 1.0)  # + 1 s: a spline rings ahead of a spike
        if spike is not None:  # the input, not the step: a smaller step would integrate the same garbage
            raise SimulationError(f"the stepper diverged near t = {t_div:g} s (non-finite state): the heave input "
                                  f"({hs.info.get('source', hs.info.get('kind', 'heave'))}) accelerates at "
                                  f"{spike[0]:.3g} m/s^2 at t = {spike[1]:g} s, beyond the {HEAVE_ACCEL_MAX:g} m/s^2 "
                                  f"a rig floor can reach: check the heave input for a spike or a gap there")
        if effects:  # the terms the file adds are the likeliest cause: name them, not only the step
            names = ", ".join(labels or dict.fromkeys(getattr(e, "name", str(e)) for e in effects))
            one = len(effects) == 1
            raise SimulationError(f"the stepper diverged near t = {t_div:g} s (non-finite state) with "
                                  f"{names} at the plant's hooks: check {'its size' if one else 'their sizes'} "
                                  f"([[effects]])" + (f", or reduce the step dt (now {h:g} s)" if step_advice else
                                                      f" (the step {h:g} s is stable for the plant without "
                                                      f"{'it' if one else 'them'})"),
                                  option="dt" if step_advice else "effects")
        raise SimulationError(f"the stepper diverged near t = {t_div:g} s (non-finite state); "
                              f"reduce the step dt (now {h:g} s) or check the parameters", option="dt")
    spike = heave_accel_outlier(hs, data[-1, 0] if len(data) else 0.0)
    if spike is not None:
        log.warning("the heave input accelerates at %.3g m/s^2 at t = %g s, beyond the %g m/s^2 a rig floor can "
                    "reach: check it for a spike or a gap there", spike[0], spike[1], HEAVE_ACCEL_MAX)
    st = dict(zip(STATS, stats.tolist()))
    check_events(data, st)
    return data, st, wall


#: largest heave acceleration of a rig floor [m/s^2]: g (a floating rig's heave stays far below;
#: beyond it the input, e.g. a spike in a heave record, is not a platform motion)
HEAVE_ACCEL_MAX = 9.81


def heave_accel_outlier(hs, t_end: float):
    """``(|d2z_h/dt2|, t)`` of the largest heave acceleration [m/s^2, s] of the samples ``hs``
    up to ``t_end`` when it exceeds :data:`HEAVE_ACCEL_MAX`, else None.

    Parameters
    ----------
    hs : HeaveSamples
        Heave samples (:mod:`heavecomp.simulate.excitation`).
    t_end : float [s]
        Last time looked at (the samples beyond it are not checked).
    """
    n = min(hs.ddz.size, int(t_end / hs.spacing) + 2)
    if n <= 0:
        return None
    a = np.abs(hs.ddz[:n])
    k = int(np.argmax(a))
    return (float(a[k]), k * hs.spacing) if a[k] > HEAVE_ACCEL_MAX else None


def check_events(data, stats: dict) -> int:
    """The stepper's own diagnostics: log a warning when a step hit the event cap (more
    than 8 mode switches in one step, finished without event location) or when a recorded
    sample has friction power F_f v < 0 (friction driving the stroke: a stepper fault).
    Returns the number of such samples.

    Parameters
    ----------
    data : (n, len(CHANNELS)) array
        Output rows of the stepper (columns :data:`CHANNELS`, SI).
    stats : dict
        The stepper's counters by name (:data:`STATS`).
    """
    if stats.get("event_cap_hits", 0) > 0:
        log.warning("stepper event cap hit in %d step(s), first at t = %.6g s: more than 8 stick-slip/contact "
                    "events inside one step, finished without event location (please report)",
                    int(stats["event_cap_hits"]), stats["event_cap_first_t"])
    power = data[:, CHANNELS.index("friction")] * data[:, CHANNELS.index("stroke_velocity")]
    bad = np.flatnonzero(power < 0.0)
    if bad.size:
        i = int(bad[np.argmin(power[bad])])
        log.warning("friction power F_f v < 0 at %d recorded sample(s), down to %.3g W at t = %.6g s: "
                    "friction opposed by the stroke velocity (stepper fault, please report)",
                    bad.size, power[i], data[i, 0])
    return int(bad.size)


def drive(step, hs, h, n_steps, out_every, *, progress=None, chunk_steps=200_000) -> int:
    """Call ``step(t0, n, Z, DZ, DDZ, out_pos) -> out_pos`` (a compiled ``advance`` bound to its
    state and output) over ``n_steps`` steps of ``h`` in chunks; returns the rows written.

    The fade-in's end, where d2z/dt2 jumps, is made a step boundary: the steps up to it get
    the heave samples up to it with the left-limit ``ddz`` there, so no RK4 step straddles the
    jump (only when it falls on the step and output grids).

    Parameters
    ----------
    step : callable
        ``step(t0, n, Z, DZ, DDZ, out_pos) -> out_pos``: runs ``n`` steps from time ``t0`` [s].
    hs : HeaveSamples
        Heave samples spaced h/2 covering the run.
    h : float [s]
        RK4 step.
    n_steps : int
        Number of steps.
    out_every : int
        Steps between output rows (chunks are whole multiples of it).
    progress : callable(fraction), optional
        Called after each chunk.
    chunk_steps : int
        Steps per call of ``step`` (at most).
    """
    done, pos = 0, 0
    if hs.kink is not None and hs.kink[0] % 2 == 0:
        k, ddz_left = hs.kink
        n1 = k // 2
        if 0 < n1 <= n_steps and n1 % out_every == 0:
            ddz1 = hs.ddz[:k + 1].copy()
            ddz1[k] = ddz_left
            pos = step(0.0, n1, hs.z[:k + 1], hs.dz[:k + 1], ddz1, 0)
            done = n1
    while done < n_steps:
        n = min(chunk_steps - chunk_steps % out_every or out_every, n_steps - done)
        pos = step(done * h, n, hs.z, hs.dz, hs.ddz, pos)
        done += n
        if progress is not None:
            progress(done / n_steps)
    return pos


#: the nominal stepper (ahead of time when built, else the JIT): :func:`heavecomp.simulate.stepper.nominal`
stepper = nominal
