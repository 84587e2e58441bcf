"""Closed-loop simulation: the exact stick-slip CMC with an active cylinder and a controller.

The plant is the foundation's compiled stepper (:mod:`heavecomp.simulate.stepper`),
called one RK4 step at a time so that the active force can change between
steps.  Per control interval (``[active].control_rate``, 20 Hz by default):

1. the rig's measurements (stroke, pressure, WOB, heave; as the true plant's channel effects
   read them, e.g. a WOB load cell ``sensor_gain``, plus Gaussian noise, seeded) and the
   actuator's force are handed to ``controller.step``;
2. the command, as the controller decided it, is checked against the limits
   (``violations_u_max``: ``|u_cmd| > u_max``; ``violations_rate``: the clipped
   command is further than ``rate_max / control_rate`` from the force the
   actuator has now), each with a relative tolerance :data:`LIMIT_TOL`;
3. the actuator applies the limits, here and only here: the command is held
   for the interval (sample-and-hold) and clipped to ``|u| <= u_max``, and
   before each RK4 step of size h the force moves towards it by at most
   ``rate_max h`` and is constant within the step (the stepper holds u
   constant within a call).

A controller is a name or any object with ``step(t, measurement, preview=None)
-> u`` (``reset()`` is called first if it has one); see ``docs/control.md``.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import time
from pathlib import Path

import numpy as np

from heavecomp.controllers import ControllerConfig, Measurement, make
from heavecomp.errors import InputError, ParameterError
from heavecomp.params.budget import check_run_size
from heavecomp.params.cmc import active
from heavecomp.effects.registry import split_effects
from heavecomp.effects.spec import effects_for
from heavecomp.plants.cmc import eigen_rate, plant_vectors
from heavecomp.simulate import excitation
from heavecomp.simulate import layout as L
from heavecomp.simulate.core import CSV_COLUMNS, SimulationResult, default_dt
from heavecomp.simulate.layout import Drive
from heavecomp.simulate.stepper import heave_at, plant_stepper

log = logging.getLogger(__name__)

#: relative tolerance when counting commands beyond a limit: a QP solver meets its
#: constraints to its own accuracy (osqp, eps_abs + eps_rel |bound| = 1e-4 kN + 1e-4 x 25 kN
#: = 2.6 N, measured up to 4.7e-4 of a 5 kN rate step); 0.1 % of the limit counts as within
LIMIT_TOL = 1e-3

#: timeseries.csv columns of a closed-loop run
CL_CSV_COLUMNS = CSV_COLUMNS + ("u_active",)


@dataclasses.dataclass(frozen=True)
class Noise:
    """Measurement noise std (Gaussian, white at the control rate).

    Attributes
    ----------
    stroke : float [m]
    pressure : float [Pa]
    wob : float [N]
    heave : float [m]
    seed : int
    """

    stroke: float = 1e-3
    pressure: float = 5e3
    wob: float = 500.0
    heave: float = 5e-3
    seed: int = 0


@dataclasses.dataclass
class ClosedLoopResult(SimulationResult):
    """A :class:`SimulationResult` (20 Hz rows) plus the controller's bookkeeping."""

    controller: str = "passive"
    control: dict = dataclasses.field(default_factory=dict)

    def metrics(self, start: float | None = None) -> dict:
        """Plant metrics plus ``u_active_max``, solve-time percentiles [ms], limit
        violations, solver failures, fallbacks and the heave-preview error."""
        m = super().metrics(start)
        w = self.window(start)
        u = self["u_active"]
        m.update(self.control)
        m["controller"] = self.controller
        m["u_active_max"] = float(np.max(np.abs(u))) if u.size else 0.0
        m["u_active_rms"] = float(np.sqrt(np.mean(u[w] ** 2))) if np.any(w) else 0.0
        return m

    def to_csv(self, path, columns=CL_CSV_COLUMNS, every: int = 1) -> Path:
        """Write the CSV with every ``every``-th row (rows are at the control rate)."""
        if every == 1:
            return super().to_csv(path, columns)
        full = self.data
        try:
            self.data = full[::every]
            return super().to_csv(path, columns)
        finally:
            self.data = full


def sample_time_check(name: str, solve_times, Tc: float) -> dict:
    """Whether the controller kept its sample time: its p99 solve time [s in ``solve_times``] within the
    control interval ``Tc`` [s].  The loop applies each command at the sample instant (no computation delay,
    docs/control.md), so a controller that computes longer than an interval gives figures a rig could not
    reach: a WARNING line says so and the metrics carry ``sample_time_missed`` (with the interval and the share
    of steps over it).

    Parameters
    ----------
    name : str
        The controller's name (for the warning).
    solve_times : sequence of float [s]
        Wall time of each control step.
    Tc : float [s]
        The control interval.
    """
    st = np.asarray(solve_times, dtype=float)
    if not st.size:
        return {}
    p99 = float(np.percentile(st, 99))
    over = float(np.mean(st > Tc))
    missed = p99 > Tc
    if missed:
        log.warning("controller %s missed its %.4g ms sample time: solve time p99 %.4g ms, max %.4g ms (%.1f %% of "
                    "the steps over); the run applies each command at once, a rig would apply it late", name, Tc * 1e3,
                    p99 * 1e3, float(st.max()) * 1e3, 100 * over)
    return {"sample_time_missed": bool(missed), "control_interval_ms": Tc * 1e3, "solve_time_share_over_interval": over}


def _percentile_ms(x, q):
    return float(np.percentile(np.asarray(x) * 1e3, q)) if len(x) else 0.0


def simulate_closed_loop(params, controller="passive", duration: float = 120.0, *, dt: float | None = None,
                         heave=None, noise: Noise | None = Noise(), preview: str = "predicted",
                         stats_start: float | None = None, progress=None, effects=None, controller_effects=None,
                         **options) -> ClosedLoopResult:
    """Simulate the CMC with an active cylinder under ``controller``.

    Parameters
    ----------
    params : heavecomp.params.CMCParams
        Plant parameters; ``[active]`` gives u_max [N], rate_max [N/s] and the control rate [Hz].
    controller : str or Controller
        ``passive``, ``pid``, ``linear-mpc``, ``nonlinear-mpc`` or an instance.
    duration : float [s]
        Simulated time.
    dt : float [s], optional
        RK4 step (default: the plant's, made a divisor of the control interval).
    heave : HeaveSamples or (t, z), optional
        Overrides ``params.heave``.
    noise : Noise or None
        Measurement noise (None: exact measurements).
    preview : {"predicted", "perfect"}
        ``predicted``: the controller predicts heave from its measurements (AR);
        ``perfect``: it is given the true future heave (an upper bound).
    stats_start : float [s], optional
        Start of the span the metrics are computed on; None: the end of the heave ramp-in (0 for a
        given ``heave``), at most half the run.
    progress : callable(fraction), optional
        Called with the fraction done every 200 control steps and at the end.
    effects : sequence, optional
        The true plant's effects (:mod:`heavecomp.effects`: instances, names or ``(name, values)``;
        None: the plant effects of ``params``' ``[[effects]]``): plant effects act at its hooks; a
        channel effect (``sensor_gain``, ``sensor_offset``, ``sensor_delay``, each with its
        ``channel``) changes the measurement the controller receives (before the noise): a sensor
        fault of the rig.  A heave effect is refused (ParameterError).
    controller_effects : sequence, optional
        The effects a named MPC's model knows (:func:`heavecomp.controllers.make`'s ``effects``):
        its plant effects enter the prediction, its channel effects how it reads the measurement
        (the calibrated correction of a sensor fault).  None: the plant effects of ``params``'
        ``[[effects]]`` (``passive`` and ``pid`` have no model).
    **options : dict
        :class:`~heavecomp.controllers.ControllerConfig` overrides (when
        ``controller`` is a name).

    Returns
    -------
    ClosedLoopResult
        Rows at the control rate; ``metrics()`` has ``wob_std``, ``wob_p2p``,
        ``u_active_max``, ``solve_time_ms_p50``/``_p99``, ``violations_*``,
        ``solver_failures``, ``fallbacks``, ``preview_rmse_m``.
    """

    if not (duration > 0 and math.isfinite(duration)):
        raise InputError(f"duration must be a positive number of seconds, got {duration}", option="duration")
    if preview not in ("predicted", "perfect"):
        raise InputError(f"preview {preview!r}: not one of predicted, perfect")
    act = active(params)
    plant_fx, heave_fx, sensor_fx = split_effects(effects_for(params, effects))
    if heave_fx:
        raise ParameterError(f"effect {heave_fx[0].name}: a heave effect is not modelled in the closed loop "
                             "(the plant would see another heave than the controller measures)")
    ctrl = make(controller, params, effects=controller_effects, **options)
    name = getattr(ctrl, "name", type(ctrl).__name__)
    cfg = getattr(ctrl, "config", None)
    if not isinstance(cfg, ControllerConfig):  # a user's own controller: the preview horizon of the defaults
        cfg = ControllerConfig.from_params(params)
    Tc = 1.0 / act.control_rate
    h = dt if dt is not None else default_dt(params, act.control_rate)
    if not (h > 0 and math.isfinite(h)):
        raise InputError(f"dt must be a positive number of seconds, got {dt}", option="dt")
    n_sub = max(1, int(round(Tc / h)))
    if dt is not None and abs(n_sub * dt - Tc) > 1e-9 * Tc:
        log.warning("dt = %g s does not divide the control interval %g s; using %g s", dt, Tc, Tc / n_sub)
    h = Tc / n_sub
    n_ctrl = int(math.ceil(duration / Tc - 1e-9))
    check_run_size(params, duration=duration, h=h, n_steps=n_ctrl * n_sub, n_rows=n_ctrl + 1, n_cols=L.NCH, dt=dt, rate=act.control_rate, rate_fn=eigen_rate)
    sp = 0.5 * h
    # the true future heave is only needed for a perfect preview (a record must then reach past the end)
    horizon_t = (cfg.horizon + 2) * Tc if preview == "perfect" else 0.0
    if heave is None:
        hs = excitation.make_heave(params.heave, n_ctrl * Tc + horizon_t, sp, params.base_dir,
                                     measurement=params.extra.get("measurement"))
    elif isinstance(heave, excitation.HeaveSamples):
        if abs(heave.spacing - sp) > 1e-12 * sp:
            raise ValueError(f"heave samples must be spaced dt/2 = {sp:g} s, got {heave.spacing:g} s")
        hs = heave
    else:
        t_in, z_in = heave
        hs = excitation.from_series(t_in, z_in, n_ctrl * Tc + horizon_t, sp, src="heave")
    plant = plant_vectors(params)  # the one params -> vectors conversion
    advance, state, args = plant_stepper(plant, plant_fx)  # the compiled stepper (loaded on first use)
    reads = _channel_readers(sensor_fx, n_ctrl + 1, Tc)
    rng = np.random.default_rng(noise.seed if noise else 0)
    sig = np.array([noise.stroke, noise.pressure, noise.wob, noise.heave]) if noise else np.zeros(4)

    mode_dir = np.array([float(L.STUCK), 1.0])
    stats = np.zeros(len(L.STATS))
    rows = np.empty((n_ctrl + 1, L.NCH))
    rec = np.empty((1, L.NCH))
    none_out = np.empty((0, L.NCH))
    u = 0.0
    du_step = act.rate_max * h
    du_max = act.rate_max * Tc
    u_cmd_prev = 0.0
    over_u = over_rate = fallbacks = 0
    u_cmd_max = 0.0
    previews = []
    step_times = []
    if callable(getattr(ctrl, "reset", None)):
        ctrl.reset()
    t_wall = time.perf_counter()
    for k in range(n_ctrl + 1):
        t = k * Tc
        advance(state, mode_dir, t, 0, h, args, Drive(u, sp, hs.z, hs.dz, hs.ddz), rec, 1, 0, stats)
        rows[k] = rec[0]
        if k == n_ctrl:
            break
        noisy = reads(k, rec[0, MEASURED]) + sig * rng.standard_normal(4)
        meas = Measurement(t=t, stroke=noisy[0], pressure=noisy[1], wob=noisy[2], heave=noisy[3], u_active=u)
        pv = None
        if preview == "perfect":
            tt = t + Tc * np.arange(cfg.horizon + 1)
            pv = np.array([heave_at(ti, sp, hs.z, hs.dz, hs.ddz) for ti in tt])
        t_step = time.perf_counter()
        try:
            u_cmd = float(ctrl.step(t, meas, pv))
        except Exception as exc:  # a controller must never stop the run
            log.warning("controller %s raised %s at t = %.2f s; holding the last command", name, exc, t)
            fallbacks += 1
            u_cmd = u_cmd_prev
        step_times.append(time.perf_counter() - t_step)
        if not math.isfinite(u_cmd):
            fallbacks += 1
            u_cmd = 0.0
        # the controller's own command, counted before the actuator clips it
        u_cmd_max = max(u_cmd_max, abs(u_cmd))
        over_u += abs(u_cmd) > act.u_max * (1 + LIMIT_TOL)
        u_cmd_prev = u_cmd
        u_cmd = min(max(u_cmd, -act.u_max), act.u_max)
        over_rate += abs(u_cmd - u) > du_max * (1 + LIMIT_TOL)
        lp = getattr(ctrl, "last_preview", None)
        if lp is not None and preview == "predicted":
            previews.append(lp)
        for j in range(n_sub):
            u = u + min(max(u_cmd - u, -du_step), du_step)
            advance(state, mode_dir, t + j * h, 1, h, args, Drive(u, sp, hs.z, hs.dz, hs.ddz), none_out, 1, 0, stats)
        if progress is not None and k % 200 == 0:
            progress(k / n_ctrl)
    wall = time.perf_counter() - t_wall
    if progress is not None:
        progress(1.0)

    st = getattr(ctrl, "solve_times", None)
    st = step_times if st is None else st
    cstats = getattr(ctrl, "stats", None) or {}
    control = {
        "u_max": act.u_max, "rate_max": act.rate_max, "control_rate": act.control_rate,
        "violations_u_max": int(over_u), "violations_rate": int(over_rate), "u_command_max": float(u_cmd_max),
        "solve_time_ms_p50": _percentile_ms(st, 50), "solve_time_ms_p99": _percentile_ms(st, 99),
        "solve_time_ms_max": _percentile_ms(st, 100), "n_control_steps": len(st),
        "solver_failures": int(cstats.get("solver_failures", 0)),
        "fallbacks": int(cstats.get("fallbacks", 0)) + fallbacks,
        "saturated_steps": int(cstats.get("saturated_steps", 0)),
        "preview": preview,
        "noise": dataclasses.asdict(noise) if noise else None,
        "config": dataclasses.asdict(cfg),
    }
    control.update(_preview_error(previews, hs, sp, Tc, heave_at))
    control.update(sample_time_check(name, st, Tc))
    if stats_start is None:
        stats_start = (params.heave.ramp or 0.0) if (heave is None and params.heave is not None) else 0.0
        stats_start = min(stats_start, 0.5 * duration)
    return ClosedLoopResult(data=rows, params=params, dt=h, stats=dict(zip(L.STATS, stats.tolist())),
                            heave_info=hs.info, wall_time=wall, stats_start=stats_start,
                            controller=name, control=control)


#: kernel columns of the measurements stroke, pressure, wob, heave (the order of :class:`Noise`)
MEASURED = [L.COL_STROKE, L.COL_PRESSURE, L.COL_WOB, L.COL_HEAVE]
MEASURED_NAMES = ("stroke", "pressure", "wob", "heave")


def _channel_readers(sensor_fx, n_rows: int, Tc: float):
    """``reads(k, y) -> y_meas``: the measurements at control instant ``k`` (time k Tc) as the
    channel effects ``sensor_fx`` read the true values ``y`` (stroke, pressure, wob, heave).  Each
    effect reads the history of its channel so far (a delay reads the past), chained in order;
    the identity without effects."""
    if not sensor_fx:
        return lambda k, y: y
    tg = Tc * np.arange(n_rows)
    stages = [(e, MEASURED_NAMES.index(e.channel), np.empty(n_rows)) for e in sensor_fx]

    def reads(k, y):
        out = np.array(y, dtype=float)
        motion = np.array([y[0] + y[3]])  # the string top's motion z_h + s (a sensor_term's *_motion features)
        for e, j, hist in stages:
            hist[k] = out[j]
            out[j] = e.measure(tg[k:k + 1], tg[:k + 1], hist[:k + 1], motion=motion)[0]
        return out

    return reads


def _preview_error(previews, hs, sp, Tc, heave_at) -> dict:
    """RMS error of the heave preview at each horizon step, after the first 30 s [m]."""
    errs = []
    for t0, z in previews:
        if t0 < 30.0:
            continue
        tt = t0 + Tc * np.arange(z.size)
        true = np.array([heave_at(ti, sp, hs.z, hs.dz, hs.ddz)[0] for ti in tt])
        errs.append(z - true)
    if not errs:
        return {}
    E = np.array(errs)
    rms = np.sqrt(np.mean(E ** 2, axis=0))
    return {"preview_predictor": "direct multi-step least squares on the last 8 s of heave (exponential forgetting, re-solved every 2 s; AR block-mean predictor during start-up)",
            "preview_rmse_m": [float(x) for x in rms],
            "preview_rmse_end_m": float(rms[-1]), "preview_horizon_s": float(Tc * (z.size - 1))}


def output_every(rate: float | None, control_rate: float) -> int:
    """Rows per written row for an output ``rate`` [Hz] (None: the control rate).

    Parameters
    ----------
    rate : float [Hz] or None
        Output rate asked for; None: the control rate.
    control_rate : float [Hz]
        The loop's control rate (``[active].control_rate``).
    """
    if rate is None:
        return 1
    ratio = control_rate / rate if rate > 0 else math.inf
    every = int(round(ratio)) if math.isfinite(ratio) else 0
    if not (every >= 1 and abs(ratio - every) < 1e-9):
        raise InputError(f"rate {rate:g} Hz: a closed-loop run writes at the control rate "
                         f"[active].control_rate = {control_rate:g} Hz or an integer fraction of it", option="rate")
    return every
