"""The replay of a measured run, prepared once: grid, filtered heave, start, noise floors, masks.

:func:`prepare` reads the run once -- the heave gap-filled, made uniform and low-passed into one spline
(:func:`heavecomp.diagnosis.data.heave_filtered`), the output noise of every channel
(:func:`heavecomp.diagnosis.data.noise_floor`), the initial state
(:func:`heavecomp.diagnosis.start.estimate`), the heave samples on the stepper grid -- replays the
nominal model, measures what the heave noise alone makes of that replay, and returns a frozen
:class:`ReplayContext`: the masks of the fit and held-out parts, the channel weights, the noise floors
and the nominal prediction.  Fitting strategies (:mod:`heavecomp.diagnosis.fitting`) and the verdict
(:mod:`heavecomp.diagnosis.verdict`) only read it.
"""

from __future__ import annotations

import concurrent.futures as cf
import dataclasses
import hashlib
import math
import threading

import numpy as np

from heavecomp.diagnosis import start as S
from heavecomp.diagnosis.data import (ANGLES, HEAVE_CUTOFF, MeasuredRun, heave_filtered, heave_samples,
                                      lowpass_zero_phase, noise_floor, uniform)
from heavecomp.diagnosis.policy import VerdictPolicy
from heavecomp.effects.candidates import ParameterMismatch, get
from heavecomp.diagnosis.stepper import CHANNELS as SC, replay_dt, run_segments
from heavecomp.effects.compose import composition, composition_for, library_composition
from heavecomp.effects.spec import plant_effects, reading_effects
from heavecomp.errors import InputError
from heavecomp.params.budget import MAX_REPLAY_STEPS
from heavecomp.plants.cmc import D0, KF, plant_vectors
from heavecomp.signals import flat_zero_phase

#: the measured channels a replay is compared on (wob first: the primary channel); a run compares those of
#: them it has (:attr:`ReplayContext.channels`, :func:`present`)
CH = ("wob", "stroke", "pressure")
#: seed of the heave-noise draws of the input-noise envelope (the same draws on every run)
NOISE_SEED = 12345
#: cost of one step of the library composition's stepper (every effect's hooks and states compiled in) in
#: steps of the plain stepper (benchmarks/diagnosis/README.md: ~1.5, measured on the bench case)
LIBRARY_STEP_COST = 1.5


class Ledger:
    """Every replay a :class:`Replay` runs: a digest of its inputs (the configuration, the replayed span
    and the heave it is driven by) and its cost in plain-stepper steps, in the order run (thread-safe).

    A diagnosis prepares one replay per log; ``duplicates`` lists the inputs replayed more than once (a
    replay whose result was already at hand), ``steps`` the replayed work (benchmarks/diagnosis)."""

    def __init__(self):
        self.rows = []
        self._lock = threading.Lock()
        self._heave = {}  # id(heave samples) -> (the samples, their digest): each array hashed once

    def heave_digest(self, hs) -> str:
        """Digest of heave samples ``hs`` (z, dz, ddz, the angle), computed once per object."""
        got = self._heave.get(id(hs))
        if got is None or got[0] is not hs:
            h = hashlib.blake2b(digest_size=12)
            for a in (hs.z, hs.dz, hs.ddz) + tuple(hs.angle or ()):
                h.update(np.ascontiguousarray(a).tobytes())
            h.update(repr((hs.spacing, hs.kink)).encode())
            got = (hs, h.hexdigest())
            with self._lock:
                self._heave[id(hs)] = got
        return got[1]

    def key(self, config, n_steps, hs) -> str:
        """Digest of a replay's inputs: ``config`` over ``n_steps`` steps driven by ``hs``."""
        return hashlib.blake2b(repr((sorted_config(config), int(n_steps), self.heave_digest(hs))).encode(),
                               digest_size=12).hexdigest()

    def add(self, config, n_steps, hs, cost) -> str:
        """Record one replay of ``config`` over ``n_steps`` steps driven by ``hs``; ``cost`` per step."""
        key = self.key(config, n_steps, hs)
        with self._lock:
            self.rows.append((key, int(n_steps), float(cost), tuple(n for n, _ in config)))
        return key

    @property
    def count(self) -> int:
        return len(self.rows)

    @property
    def steps(self) -> float:
        """Replayed steps, in plain-stepper steps."""
        return float(sum(r[1] * r[2] for r in self.rows))

    def duplicates(self) -> dict:
        """{digest: times run} of the inputs replayed more than once."""
        seen = {}
        for k, *_ in self.rows:
            seen[k] = seen.get(k, 0) + 1
        return {k: n for k, n in seen.items() if n > 1}


def sorted_config(config) -> tuple:
    """A configuration ``[(effect name, values), ...]`` as a hashable, order-free-within-values tuple.

    Parameters
    ----------
    config : list of (str, dict)
        The effects replayed, each by name with its parameter values.
    """
    return tuple((n, tuple(sorted((k, float(v) if isinstance(v, (int, float, np.floating)) else v)
                                  for k, v in dict(v).items()))) for n, v in config)


@dataclasses.dataclass(frozen=True)
class Replay:
    """Everything needed to re-simulate a run quickly: the stepper grid (step ``h`` [s], ``n_steps``),
    the heave samples ``hs``, the nominal ``plant`` vectors, the segments (``bounds``, ``starts``) and
    the samples left out after each restart (``reinit``), the heave ``spline`` and the ``initial``
    state the first segment starts from."""

    run: MeasuredRun
    nominal: object
    h: float
    n_steps: int
    hs: object
    plant: object
    bounds: list
    starts: list
    reinit: np.ndarray
    spline: object
    initial: S.InitialState
    stuck_speed: float
    #: the parameter file's own plant effects (``[[effects]]``), resolved once: part of every replay
    file_effects: tuple = ()
    #: the parameter file's readings with dynamics (``sensor_lag``, ``model_side``): the log cannot be
    #: corrected for their lag, so every replay reads its prediction of their channel through it
    file_readers: tuple = ()
    #: segment starts per stroke/WOB reading (:meth:`start_for`), filled as configurations ask
    cache: dict = dataclasses.field(default_factory=dict, compare=False, repr=False)
    #: every replay run (:class:`Ledger`): a digest of its inputs and its cost
    ledger: Ledger = dataclasses.field(default_factory=Ledger, compare=False, repr=False)
    #: whole replays driven by the replay's own heave, by the digest of their inputs: a shorter replay of
    #: the same configuration is their prefix (:meth:`simulate`), not run again
    whole: dict = dataclasses.field(default_factory=dict, compare=False, repr=False)

    @property
    def t(self) -> np.ndarray:
        return self.run.t

    def simulate(self, config, t_end=None, hs=None) -> dict:
        """Model channels at the run's times (up to ``t_end`` [s]) for a configuration
        ``[(effect name, values), ...]`` (empty: the nominal model), driven by the replay's heave or by
        ``hs`` (heave samples on the same grid).  A stroke or WOB reading in the configuration also
        moves the start (:meth:`start_for`).  Returns {channel: array, ``stroke_velocity``, ``stuck``,
        ``t``, ``_grid`` (the stepper's output)}."""
        hs = self.hs if hs is None else hs
        hs_in = hs
        # a configuration already replayed whole on this heave: its prefix is this replay, bit for bit (the
        # same steps from the same start; a reading, which may filter, is read here as always)
        whole = self.ledger.key(config, self.n_steps, hs) if hs is self.hs and not self.file_readers else None
        if whole is not None and whole in self.whole and not any(get(n).kind == "output" for n, _ in config):
            return self._prefix(self.whole[whole], t_end)
        plant = self.plant
        # the parameter file's own plant effects ([[effects]], e.g. a calibrated model) are part of the
        # model in every replay; a candidate of the same effect refits it
        file_fx = self.file_effects
        effects, sensors = list(file_fx), []
        # a channel that misreads also misled the start estimate: start from its true reading
        shift, starts = self.start_for([(n, v) for n, v in config if get(n).kind == "output"])
        if shift:
            hs = dataclasses.replace(hs, z=hs.z + shift)
        for name, values in config:
            cls = get(name)
            if cls.kind == "plant":
                effects = [e for e in effects if e.name != name] + [cls(**values)]
            elif cls.kind == "nominal":
                plant = plant_vectors(ParameterMismatch.apply(self.nominal, values))
            elif cls.kind == "heave":  # the heave the plant sees (heave_reference)
                hs = cls(**values).transform(hs)
            else:  # a channel that misreads (sensor_delay, sensor_gain, sensor_offset)
                sensors.append(cls(**values))
        # no plant effect on: the plain stepper (the composition of none), bit for bit the library's
        # stepper with every effect off and ~1.5x faster (it integrates no effect states, calls no hooks)
        comp = (composition_for(effects) if file_fx else library_composition() if effects else composition(()))
        EP = comp.ep(effects)
        n = self.n_steps if t_end is None else min(self.n_steps, int(math.ceil(t_end / self.h)) + 2)
        self.ledger.add(config, n, hs_in, 1.0 if not comp.classes else LIBRARY_STEP_COST)
        out = run_segments(plant, comp, EP, hs, self.h, self.bounds, starts, n + 1)
        tg = out[:, 0]
        t = self.t if t_end is None else self.t[self.t <= tg[-1]]
        res = {c: np.interp(t, tg, out[:, SC.index(c)]) for c in CH + ("stroke_velocity", "stuck")}
        done = set()
        for e in self.file_readers:  # the file's sensor lag, read on the model side (the log holds the lagged channel)
            if e.channel in CH:
                res[e.channel] = e.lag(t, tg, out[:, SC.index(e.channel)])
                done.add(e.channel)
        for e in sensors:  # the first on a channel reads the model's grid, the next ones its reading
            c = e.channel
            if c in CH:
                res[c] = e.measure(t, t, res[c]) if c in done else e.measure(t, tg, out[:, SC.index(c)])
                done.add(c)
        res["t"] = t
        res["_grid"] = out
        if whole is not None and n == self.n_steps and len(config) <= 1:
            # the nominal and single candidates: their whole replays are kept anyway (ReplayContext,
            # CandidateFit.pred), so the memo adds no memory (a joint configuration is not kept)
            self.whole[whole] = res
        return res

    def _prefix(self, res, t_end) -> dict:
        """The replay ``res`` (whole) up to ``t_end`` [s], as :meth:`simulate` returns it for ``t_end``."""
        if t_end is None:
            return dict(res)
        n = min(self.n_steps, int(math.ceil(t_end / self.h)) + 2)
        out = res["_grid"][: n + 1]
        m = int(np.count_nonzero(self.t <= out[-1, 0]))
        got = {c: (v[:m] if isinstance(v, np.ndarray) and v.shape[:1] == self.t.shape else v) for c, v in res.items()}
        got["_grid"] = out
        return got

    def start_for(self, readings):
        """Shift of the heave reference [m] and segment starts for a configuration whose ``readings``
        (output candidates, ``[(name, values)]``) misread stroke or WOB: the initial state and the heave
        reference are estimated from what those channels truly read (the measured channel through the
        inverse of the effect's affine reading ``apply``), not from the misread one -- a stroke read 4 cm
        off, or a WOB zero that is off, otherwise starts the replay 4 cm off and leaves a transient and a
        mean shift no reading of the channel can undo.  Delays and channels the start does not read keep
        the run's start.  Cached per configuration."""
        fixes = [(get(n), v) for n, v in readings
                 if get(n).fit.linear and v.get("channel") in ("stroke", "wob")]
        if not fixes:
            return 0.0, self.starts
        key = tuple((cls.name, tuple(sorted(v.items()))) for cls, v in fixes)
        if key not in self.cache:
            run = unlagged(self.run, self.file_readers)  # as the replay's own start (build): the file's lags lifted back
            cols = dict(run.columns)
            for cls, v in fixes:
                c, y = v["channel"], cols[v["channel"]]
                par = [v[f.name] for f in cls.fields()]
                a0 = cls.apply(run.t, run.t, np.zeros_like(y), *par)
                a1 = cls.apply(run.t, run.t, np.ones_like(y), *par) - a0
                cols[c] = (y - a0) / np.where(np.abs(a1) > 1e-9, a1, np.nan)
            st = S.estimate(MeasuredRun(run.t, cols, run.source), self.nominal, self.spline,
                            stuck_speed=self.stuck_speed)
            self.cache[key] = (self.initial.heave_reference - st.heave_reference, [st.start()] + list(self.starts[1:]))
        return self.cache[key]


def present(run) -> tuple:
    """The output channels of :data:`CH` the run has, in that order (the first is the primary channel).

    Parameters
    ----------
    run : heavecomp.diagnosis.data.MeasuredRun
        The measured run.
    """
    return tuple(c for c in CH if c in run.columns)


def output_noise(run) -> dict:
    """Output-noise standard deviation of every channel the run has [SI] (difference estimate, with a
    coarse grid's step^2/12, :func:`heavecomp.diagnosis.data.noise_floor`), and the rms of a reading
    artefact the quality checks found (a hum: ``run.quality.reading_noise``) in quadrature.

    Parameters
    ----------
    run : heavecomp.diagnosis.data.MeasuredRun
        The measured run.
    """
    extra = getattr(getattr(run, "quality", None), "reading_noise", None) or {}  # a hum (quality.assess)
    return {c: math.hypot(noise_floor(run[c], run.t if not run.uniform else None), extra.get(c, 0.0))
            for c in present(run)}


def build(run, nominal, *, stuck_speed=S.STUCK_SPEED, segment=None, reinit=1.5, noise=None) -> Replay:
    """The :class:`Replay` of ``run`` under the ``nominal`` parameters: the stepper grid (refused up front
    beyond the diagnosis budget), the heave spline (made once), the initial state estimated from the
    first seconds (:func:`heavecomp.diagnosis.start.estimate`, ``noise``: output noise per channel) and
    the heave samples from the reference it found; with ``segment`` [s], multiple-shooting segments.

    Parameters
    ----------
    run : heavecomp.diagnosis.data.MeasuredRun
        The measured run.
    nominal : heavecomp.params.CMCParams
        Nominal parameters.
    stuck_speed : float [m/s]
        The start is stuck when the measured stroke speed is below this.
    segment : float [s] or None
        Multiple-shooting segment length; None: one segment.
    reinit : float [s]
        Start of each restarted segment left out of the residuals.
    noise : dict, optional
        Output-noise standard deviation per channel [SI] (:func:`output_noise`) for the start estimate.
    """
    h, n_steps = grid(run, nominal)
    spline = heave_filtered(run)
    readers = tuple(e for e in reading_effects(nominal) if e.model_side)
    initial = S.estimate(unlagged(run, readers), nominal, spline, stuck_speed=stuck_speed, noise=noise)
    hs = heave_samples(run, h, n_steps, reference=initial.heave_reference, spline=spline)
    plant = plant_vectors(nominal)
    bounds, starts, rein = [(0, n_steps)], [initial.start()], np.zeros(run.t.size, bool)
    if segment:
        bounds, starts, rein = _segments(run, h, n_steps, plant.PP, segment, reinit, stuck_speed)
        starts[0] = initial.start()
    return Replay(run, nominal, h, n_steps, hs, plant, bounds, starts, rein, spline, initial, stuck_speed,
                  tuple(plant_effects(nominal)), readers)


#: s of the log's start a sensor lag is lifted from for the start estimate (:func:`unlagged`)
UNLAG_SPAN = 30.0
#: Hz, the zero-phase low-pass of that lift (the lag's inverse differentiates: the start estimate needs no more)
UNLAG_CUTOFF = 1.0


def unlagged(run, readers):
    """The run the start estimate reads when the file reads a stroke or WOB through a sensor lag
    (``sensor_lag``, read on the model side): the log holds the lagged channel, which lags the state the
    replay must start from (a stroke started off moves the gas spring's charge and the whole replay).  Over
    its first :data:`UNLAG_SPAN` s the channel is lifted back, ``y_l + tau dy_l/dt`` on the channel low-passed
    at :data:`UNLAG_CUTOFF` (zero phase); the rest of the log is not read by the start estimate.

    Parameters
    ----------
    run : heavecomp.diagnosis.data.MeasuredRun
        The measured run (read with the file: the lag's factor and delay undone).
    readers : tuple of Effect
        The file's model-side readings (``sensor_lag``).
    """
    lifts = [e for e in readers if e.channel in ("stroke", "wob") and e.channel in run.columns
             and float(e.values["time_constant"]) > 0.0]
    if not lifts:
        return run
    t = run.t
    cols = dict(run.columns)
    for e in lifts:
        y = np.asarray(cols[e.channel], float).copy()
        m = (t <= t[0] + UNLAG_SPAN) & np.isfinite(y)
        if m.sum() < 8:
            continue
        yf, dy, _ = lowpass_zero_phase(t[m], y[m], UNLAG_CUTOFF)
        y[m] = yf + float(e.values["time_constant"]) * dy
        cols[e.channel] = y
    return MeasuredRun(t, cols, run.source)


def grid(run, nominal) -> tuple:
    """The replay's step [s] and number of steps; a log over the diagnosis budget is refused (before any
    work: the diagnosis replays the log hundreds of times).

    Parameters
    ----------
    run : heavecomp.diagnosis.data.MeasuredRun
        The measured run.
    nominal : heavecomp.params.CMCParams
        Nominal parameters. (the replay step, :func:`heavecomp.diagnosis.stepper.replay_dt`).
    """
    # a uniformly sampled log's samples fall on the replay's grid (no interpolation between its steps)
    h = replay_dt(nominal, 1.0 / run.dt if run.uniform and run.t.size > 1 else None)
    n_steps = int(math.ceil(run.t[-1] / h - 1e-9))
    if n_steps > MAX_REPLAY_STEPS:
        raise InputError(f"{run.source}: the log is {run.t[-1] / 3600:.3g} h long, {n_steps:.3g} replay steps of "
                         f"{1e3 * h:.3g} ms, over the diagnosis budget of {MAX_REPLAY_STEPS:.3g} "
                         f"({MAX_REPLAY_STEPS * h / 3600:.3g} h); diagnose a part of it (e.g. the hour of interest)")
    return h, n_steps


def start_warnings(initial, nominal) -> list:
    """A warning when the log does not start at rest at the operating point (issue 12: start anywhere).

    Parameters
    ----------
    initial : heavecomp.diagnosis.start.InitialState
        The initial state estimated from the first seconds of the log.
    nominal : heavecomp.params.CMCParams
        Nominal parameters. (the WOB set-point [N] of the operating point).
    """
    st = initial
    if st.at_rest:
        return []
    return [f"the log does not start at rest at the operating point (stroke {st.stroke:+.4f} m, stroke velocity "
            f"{st.stroke_velocity:+.4f} m/s, WOB {st.wob / 1e3:.1f} kN vs W_0 "
            f"{nominal.operating_point.wob_setpoint / 1e3:.1f} kN, {'stuck' if st.stuck else 'sliding'}): "
            f"the replay starts from the state estimated from its first {st.window:g} s (initial_state)"]


def _segments(run, h, n_steps, PP, length, reinit_s, stuck_speed):
    """Multiple shooting: segments of ``length`` s, each started from the measured state (stroke and its
    zero-phase derivative; lower mass from the low-passed WOB through the formation spring,
    y_b = delta_0 - W/k_F, v_b = -dW/dt / k_F).  The first ``reinit_s`` s of every restarted segment
    are left out of the residuals."""
    t = run.t
    for c in ("stroke", "wob"):
        if c not in run.columns:
            raise InputError(f"{run.source}: multiple-shooting segments start from the measured stroke and WOB; "
                             f"column '{c}' is missing (diagnose without segments)", option="segment")
    n_seg = max(1, int(math.floor(t[-1] / length)))
    bounds, starts = [], []
    tu, su = uniform(t, run["stroke"])
    sf = flat_zero_phase(su, 1.0 / (tu[1] - tu[0]), 1.0)
    _, vs, _ = lowpass_zero_phase(t, run["stroke"], 1.0)
    wf_u = flat_zero_phase(uniform(t, run["wob"])[1], 1.0 / (tu[1] - tu[0]), 3.0)
    _, dw, _ = lowpass_zero_phase(t, run["wob"], 3.0)
    reinit = np.zeros(t.size, bool)
    for k in range(n_seg):
        i0 = int(round(k * length / h))
        i1 = n_steps if k == n_seg - 1 else int(round((k + 1) * length / h))
        bounds.append((i0, i1))
        if k == 0:
            starts.append(None)
            continue
        tk = i0 * h
        s = float(np.interp(tk, tu, sf))
        v = float(np.interp(tk, t, vs))
        W = float(np.interp(tk, tu, wf_u))
        starts.append((s, v, PP[D0] - W / PP[KF], -float(np.interp(tk, t, dw)) / PP[KF], abs(v) < stuck_speed))
        reinit |= (t >= tk) & (t < tk + reinit_s)
    return bounds, starts, reinit


@dataclasses.dataclass(frozen=True)
class ReplayContext:
    """A run prepared for the diagnosis (:func:`prepare`); every fit and the verdict read it.

    ``split`` {fit, validate: [t0, t1], settle} [s]; ``y`` the measured channels; ``fitmask`` /
    ``valmask`` / ``allmask`` the samples of the fit part, the held-out part and everything after the
    settling window; ``output_noise``, ``replay_floor`` (what the heave noise and its pre-processing
    make of the replay), ``noise_floor`` (both) and ``input_envelope`` per channel [SI];
    ``weights`` 1/rms^2 of the nominal fit-part residual; ``nominal_pred`` the nominal replay,
    ``mse_before`` its held-out mean squares; ``hs_pert`` the heave-noise draws a candidate's
    explained share is tested on and ``mse_before_pert`` the nominal's held-out mean squares on them."""

    replay: Replay
    split: dict
    y: dict
    fitmask: np.ndarray
    valmask: np.ndarray
    allmask: np.ndarray
    output_noise: dict
    heave_noise: float
    replay_floor: dict
    noise_floor: dict
    input_envelope: dict
    weights: dict
    nominal_pred: dict
    mse_before: dict
    hs_pert: list
    mse_before_pert: list
    policy: VerdictPolicy
    decimate: int = 1
    n_jobs: int = 1
    #: the output channels the run has (:func:`present`): every loss, floor and share is on these only
    channels: tuple = CH
    #: the nominal's replays on :attr:`hs_pert` (the distinguishability test's pairs equal by construction
    #: read them: kept, not replayed again)
    nominal_pert: tuple = ()
    #: the input envelope's other heave-noise draws (:class:`MoreDraws`: made again the first time a candidate's
    #: draws disagree, not held otherwise) and the nominal's held-out mean squares on them (the envelope replayed them)
    more_draws: object = None
    mse_before_more: tuple = ()

    @property
    def run(self):
        return self.replay.run

    @property
    def primary(self) -> str:
        """The primary channel: WOB, else the first of :data:`CH` the run has."""
        return self.channels[0]

    def simulate(self, config, t_end=None, hs=None) -> dict:
        """:meth:`Replay.simulate`."""
        return self.replay.simulate(config, t_end, hs)

    def mse(self, pred, mask) -> dict:
        """Mean square of prediction minus measurement per channel on ``mask`` (finite samples)."""
        return mse(self.y, pred, mask, self.channels)

    def explained(self, mse_b, mse_a) -> float:
        """Explained share of the held-out gap above the noise floor: per channel
        e_c = (mse_b - mse_a) / max(mse_b - sigma_c^2, ``gap_floor_share`` mse_b), averaged with weights
        g_c = max(mse_b / sigma_c^2 - 1, 0) (the channel with the largest gap over its noise counts most)."""
        num = den = 0.0
        floor_share = self.policy.gap_floor_share
        for c in self.channels:
            f2 = max(self.noise_floor[c] ** 2, 1e-30)
            g = max(mse_b[c] / f2 - 1.0, 0.0)
            e = (mse_b[c] - mse_a[c]) / max(mse_b[c] - f2, floor_share * mse_b[c], 1e-300)
            num += g * e
            den += g
        return num / den if den > 0 else 0.0

    def explained_draws(self, preds) -> list:
        """Explained share of the held-out gap by replays driven by the heave redrawn within its noise
        (``preds``, one per draw: those of :attr:`hs_pert`, then those of :attr:`more_draws`), each
        against the nominal replay with the same draw [-]."""
        bases = list(self.mse_before_pert) + list(self.mse_before_more)
        return [self.explained(b, self.mse(a, self.valmask)) for b, a in zip(bases, preds)]

    def explained_perturbed(self, preds) -> float:
        """The median of :meth:`explained_draws` [-]."""
        return float(np.median(self.explained_draws(preds)))

    def held_out(self, config) -> tuple:
        """A configuration's whole replay and its replays on the heave-noise draws :attr:`hs_pert`."""
        return self.simulate(config), [self.simulate(config, hs=hs) for hs in self.hs_pert]

    def resid_vec(self, pred) -> np.ndarray:
        """The weighted, decimated fit-part residual of all channels (the fits' objective)."""
        m = self.fitmask[: pred["wob"].size]
        parts = []
        for c in self.channels:
            y = self.y[c][: m.size]
            ok = m & np.isfinite(y)
            parts.append((pred[c][ok] - y[ok])[:: self.decimate] * math.sqrt(self.weights[c]))
        r = np.concatenate(parts)
        bad = ~np.isfinite(r)
        if bad.any():  # a diverged simulation: a large, finite penalty keeps the optimisers working
            r[bad] = 1e3
        return r

    def map(self, fn, items) -> list:
        """``[fn(x) for x in items]``, on ``n_jobs`` threads (the stepper releases the GIL)."""
        return parallel_map(fn, items, self.n_jobs)


def mse(y, pred, mask, channels=CH) -> dict:
    """Mean square of ``pred`` minus the measured ``y`` per channel on ``mask`` (finite samples).

    Parameters
    ----------
    y : dict
        Measured channels {channel: array} [SI].
    pred : dict
        Predicted channels {channel: array} [SI] (may be shorter than ``y``).
    mask : numpy.ndarray of bool
        Samples compared.
    channels : tuple of str
        The channels compared (those the run has).
    """
    out = {}
    for c in channels:
        yc = y[c][: pred[c].size]
        m = mask[: pred[c].size] & np.isfinite(yc)
        r = pred[c][m] - yc[m]
        out[c] = float(np.mean(r * r)) if r.size else math.nan
    return out


def parallel_map(fn, items, n_jobs) -> list:
    """``[fn(x) for x in items]``, on ``n_jobs`` threads.

    Parameters
    ----------
    fn : callable
        Function of one item.
    items : sequence
        Items mapped.
    n_jobs : int
        Threads (1: serial).
    """
    if n_jobs > 1 and len(items) > 1:
        with cf.ThreadPoolExecutor(n_jobs) as ex:
            return list(ex.map(fn, items))
    return [fn(x) for x in items]


def split_of(run, split, settle) -> dict:
    """The fit / validate intervals and the settling window [s]; bad settings refused.

    Parameters
    ----------
    run : heavecomp.diagnosis.data.MeasuredRun
        The measured run.
    split : float [-]
        Fraction of the run in the fit part.
    settle : float [s] or None
        Settling window left out at the start; None: min(30 s, 10 % of the run).
    """
    T_end = float(run.t[-1])
    settle = settle if settle is not None else min(30.0, 0.1 * T_end)
    if not 0 <= settle < 0.5 * T_end:
        raise InputError(f"settle {settle:g} s must be >= 0 and shorter than half the run ({T_end:g} s)", option="settle")
    t_split = split * T_end
    return {"fit": [0.0, t_split], "validate": [t_split, T_end], "settle": settle}


def prepare(run, nominal, *, split=0.67, settle=None, stuck_speed=S.STUCK_SPEED, segment=None, reinit=1.5,
            input_draws=8, decimate=1, n_jobs=1, policy=None) -> ReplayContext:
    """Prepare ``run`` once for the diagnosis (see the module docstring); returns the frozen context.

    The settings are the :class:`heavecomp.diagnosis.GapDiagnoser` settings of the same names.

    Parameters
    ----------
    run : heavecomp.diagnosis.data.MeasuredRun
        The measured run.
    nominal : heavecomp.params.CMCParams
        Nominal parameters.
    split : float [-]
        Fraction of the run in the fit part.
    settle : float [s] or None
        Settling window left out at the start; None: min(30 s, 10 % of the run).
    stuck_speed : float [m/s]
        The start (and a restarted segment) is stuck when the stroke speed is below this.
    segment : float [s] or None
        Multiple-shooting segment length; None: one segment.
    reinit : float [s]
        Start of each restarted segment left out of the residuals.
    input_draws : int
        Heave-noise draws of the input-noise envelope.
    decimate : int
        Decimation of the fit residual (every ``decimate``-th sample).
    n_jobs : int
        Threads for the replays.
    policy : heavecomp.diagnosis.policy.VerdictPolicy, optional
        Decision thresholds (its heave-noise draws and pre-filter ratio); None: the defaults.
    """
    policy = policy or VerdictPolicy()
    sp = split_of(run, split, settle)
    grid(run, nominal)  # refused before any work
    noise = output_noise(run)
    rp = build(run, nominal, stuck_speed=stuck_speed, segment=segment, reinit=reinit, noise=noise)
    t = run.t
    keep = ~rp.reinit
    fitmask = (t >= sp["settle"]) & (t < sp["fit"][1]) & keep
    valmask = (t >= sp["fit"][1]) & keep
    allmask = (t >= sp["settle"]) & keep
    nom = rp.simulate([])
    chans = present(run)
    fl = _replay_floor(rp, nom, allmask, valmask, input_draws, n_jobs, policy, chans)
    floor = {c: math.hypot(noise[c], fl["replay_floor"][c]) for c in chans}
    envelope = {c: max(math.hypot(noise[c], math.sqrt(fl["env_ms"][c])), floor[c]) for c in chans}
    y = {c: run[c] for c in chans}
    mse_fit = mse(y, nom, fitmask, chans)
    weights = {c: 1.0 / max(mse_fit[c], floor[c] ** 2, 1e-30) for c in chans}
    return ReplayContext(rp, sp, y, fitmask, valmask, allmask, noise, fl["heave_noise"], fl["replay_floor"], floor,
                         envelope, weights, nom, mse(y, nom, valmask, chans), fl["hs_pert"],
                         [mse(y, a, valmask, chans) for a in fl["pert_preds"]], policy, max(1, int(decimate)),
                         max(1, int(n_jobs)), chans, tuple(fl["pert_preds"]), fl["more_draws"],
                         tuple(mse(y, a, valmask, chans) for a in fl["more_preds"]))


class MoreDraws:
    """The input envelope's heave-noise draws after the first ``perturbed_draws``, made again (the same
    noise, drawn in the same order from the same seed) the first time they are asked for, then kept.

    Parameters
    ----------
    make : callable
        ``make(first)``: the envelope's draws from the ``first`` on (heave samples), the noise drawn in order.
    first : int
        The first draw kept (the number of ``hs_pert``).
    """

    def __init__(self, make, first):
        self._make, self._first = make, first
        self._draws = None
        self._lock = threading.Lock()

    def get(self) -> list:
        """The draws (heave samples)."""
        with self._lock:
            if self._draws is None:
                self._draws = self._make(self._first)
            return self._draws


def _replay_floor(rp, nom, mask, val, input_draws, n_jobs, policy, chans=CH) -> dict:
    """Residual an exact model would still show because the *input* is noisy: the nominal replay
    repeated with the heave perturbed by white noise of the heave's own noise level (second-difference
    estimate); rms difference per channel [SI] (``replay_floor``), with the sensitivity to the heave
    pre-processing (cut-off ``floor_cutoff_ratio`` x higher).

    Also the held-out *envelope* of that residual (``env_ms``, mean squares): with exact stiction one
    heave-noise draw can flip a stick event and shift a whole stretch of the replay, so the residual
    from input noise is heavy-tailed and one draw under-estimates what a run with no effect can show.
    The envelope is the largest held-out mean square over ``input_draws`` independent draws, plus the
    pre-processing term.  The first ``perturbed_draws`` draws (``hs_pert``) and their nominal replays
    (``pert_preds``) test the candidates."""
    run = rp.run
    sz = noise_floor(run["heave"], run.t if not run.uniform else None)
    ref = rp.hs.info["reference_m"]
    n_draws = max(1, int(input_draws))

    def make_draws(first=0):
        """The draws from the ``first`` on: every noise drawn in order, the heave samples of those kept."""
        rng = np.random.default_rng(NOISE_SEED)
        noises = [rng.normal(0.0, sz, run.t.size) for _ in range(n_draws)]
        return [perturbed(e) for e in noises[first:]]

    def perturbed(noise):
        pert = MeasuredRun(run.t, {**{a: run[a] for a in ANGLES if a in run.columns},
                                   "heave": run["heave"] + noise}, run.source)
        return heave_samples(pert, rp.h, rp.n_steps, reference=ref)

    def ms(a, m):
        return {c: float(np.mean((a[c][m] - nom[c][m]) ** 2)) for c in chans}

    draws = make_draws()  # replayed concurrently
    n_pert = policy.perturbed_draws
    cut = heave_samples(run, rp.h, rp.n_steps, cutoff=policy.floor_cutoff_ratio * HEAVE_CUTOFF, reference=ref)
    alt, *others, alt2 = parallel_map(lambda hs: rp.simulate([], hs=hs), draws + [cut], n_jobs)
    env = ms(alt, val)
    for o in others:
        other = ms(o, val)
        env = {c: max(env[c], other[c]) for c in chans}
    pre = ms(alt2, val)
    a, b = ms(alt, mask), ms(alt2, mask)
    return {"heave_noise": sz, "hs_pert": draws[:n_pert], "pert_preds": ([alt] + others)[:n_pert],
            "more_draws": MoreDraws(make_draws, n_pert), "more_preds": ([alt] + others)[n_pert:],
            "env_ms": {c: env[c] + pre[c] for c in chans},
            "replay_floor": {c: float(np.sqrt(a[c] + b[c])) for c in chans}}
