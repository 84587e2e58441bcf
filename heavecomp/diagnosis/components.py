"""The CMC's component residuals: each model equation evaluated on the measured signals alone.

Paper B measures the seal friction from pressure and displacement (``F_f = F_drive - M a``); the same
idea, applied to every equation of :mod:`heavecomp.plants.cmc` (called, never restated), gives one
residual per model component (:data:`heavecomp.effects.base.COMPONENTS`), measured minus nominal:

======================  =====  ==================================================================
equation                unit   residual
======================  =====  ==================================================================
top-mass force balance  N      seal friction the balance needs, ``net_force(p, T, ddz_h) - M_c a``,
                               minus the nominal law at the measured v and p (sliding samples, away
                               from rest and reversals by the filter's reach)
lower-mass balance      N      string tension the lower mass needs, ``m_b (a_b + g) - W``, minus
                               ``tension()`` at the measured relative displacement (bit on the rock:
                               ``y_b = delta_0 - (W + c_F v_b) / k_F``, ``v_b = -dW/dt / k_F``;
                               left out where the bit lifts off)
gas law                 Pa     measured pressure minus ``gas_pressure(s)`` at the measured stroke
======================  =====  ==================================================================

Derivatives and the values themselves come through the same zero-phase FIR low-pass
(:data:`CUTOFF`; :func:`heavecomp.signals.flat_zero_phase`), so linear terms see one
frequency response.  Each equation residual is split by a joint least-squares regression (on the
whole analysed span) into the parts other components explain:

- gas law: ``flow_line`` (v, v|v|: a pressure drop growing with flow; a: the line's inertance, the
  drop that accelerates its oil column), ``sensors`` (dp/dt: a lagging
  pressure channel); the rest (preload, stiffness, drift) is ``gas_spring``;
- lower-mass balance: ``heave_input`` (z_h, dz_h: a heave that is not the one the compensator sees),
  ``sensors`` (dW/dt: a lagging WOB channel); the rest is ``string_formation``;
- top-mass balance: ``heave_input`` (ddz_h); the rest is ``friction``.

A channel that misreads (a clipped load cell, a stroke read through a play) is one error in one
reading, so it shows in every equation that reads that channel, with coefficients the equations fix;
a seal, gas or string effect shows in its own equation only.  :func:`channel_search` fits generic
misreadings of each channel's own reading to all the equations that read it at once and keeps a term
only when two of them see it and shrink (cross-channel consistency); the gap diagnosis' open search
puts such a term first, as component ``sensors`` with the channel named.

The friction residual is blind near rest and reversals (the filtered sign(v) jump): effects acting at
breakaway (dwell stiction, frictional memory) show little there; measured on generated runs, the
largest holding force before a breakaway, read through the same filter, is dominated by the filter's
smear (-21 kN +- 10 kN with and without the effect), so it is not used.

Shares (:meth:`ComponentResiduals.shares`): each part's mean square over the noise variance of its
equation (the rms change of the residual when the channels get their own noise-floor noise),
minus the noise's own expected 1 for the rest parts and minus the nominal replay's floor, clipped at 0;
components below :data:`SHARE_MIN` get none; normalised to sum 1 (all 0 when no component rises
above its noise).
"""

from __future__ import annotations

import dataclasses
import logging
import math

import numpy as np

from heavecomp.diagnosis import equation_error as EE
from heavecomp.diagnosis.data import ANGLES, fill_gaps, lowpass_zero_phase, noise_floor
from heavecomp.diagnosis.policy import VerdictPolicy
from heavecomp.effects import sensor_term as ST
from heavecomp.effects.base import COMPONENTS
from heavecomp.effects.compose import composition_for
from heavecomp.effects.spec import plant_effects
from heavecomp.effects.features import rest_durations
from heavecomp.errors import DataError
from heavecomp.friction.laws import friction_cont, friction_jump
from heavecomp.plants.cmc import (CF, D0, KF, MB, MC, G, P0ABS, PATM, cylinder_reading, gas_pressure, net_force,
                                  plant_vectors, tension)

CUTOFF = 1.0  #: zero-phase low-pass of every channel before the equations [Hz]
STUCK_SPEED = 2e-3  #: below this filtered stroke speed the seal is at rest (friction set-valued) [m/s]
SHARE_MIN = 1.0  #: a component gap below this (noise variances above noise and floor) gets no share [-]
LIFTOFF = 0.1  #: WOB below this share of its median: the bit is off the rock (lower-mass residual left out) [-]
REACH = 0.5  #: friction samples within REACH / cutoff [s] of rest or a reversal are left out [-]
EDGE = 3.0  #: s at each end of the run left out (the filter's edges)
log = logging.getLogger(__name__)
UNITS = {"friction": "N", "gas_spring": "Pa", "flow_line": "Pa", "string_formation": "N", "sensors": "-",
         "heave_input": "N"}
#: plant components whose equation residual the gap diagnosis' pre-screen reads: a candidate there
#: that the residual sees (``Effect.screened``; not a string damping, which the lower-mass balance's
#: noise hides) is not replayed when its component shows no gap.  In friction only the sliding
#: friction's candidates (pressure, position, direction): the top-mass balance is blind at breakaway
#: and at reversals, where dwell stiction and frictional lag act (a lag of 6.5x its noise floor on the
#: WOB, tuning seed 20000, left the friction residual no gap at all): those two are never screened.
#: ``heave_input`` (the z_h, dz_h and d2z_h parts of the two mass balances): a heave reference the
#: compensator does not see shows there (tuning seed 20013: 16 680 noise variances, 20 % of the gap), the
#: tuning set's other runs left it at most 141 noise variances and 3 % (issue 32)
SCREENED = ("friction", "gas_spring", "flow_line", "string_formation", "heave_input")


def _dilate(t, flag, width):
    """``flag`` widened by ``width`` [s] on each side."""
    if not flag.any():
        return flag
    n = max(1, int(round(width / float(np.median(np.diff(t))))))
    return np.convolve(flag.astype(float), np.ones(2 * n + 1), mode="same") > 0


def file_hooks(params):
    """The hook functions of ``params``' own plant effects (its ``[[effects]]``) that the equations can
    evaluate on measured signals: (composition functions, EP, the effects left out), or None with none.

    Only memoryless effects (no states of their own) are evaluated: an effect with a state (a leak's
    charge, a lag, a warming) needs its history, which the measured signals do not give; it is left out
    (logged), as before.  A calibrated file's ``flow_loss``, ``line_term``, ``string_damping`` ... are
    therefore part of the equations, so its residuals show only what the file leaves.

    Parameters
    ----------
    params : heavecomp.params.CMCParams
        Parameters whose ``effects`` are read.
    """
    effects = plant_effects(params) if getattr(params, "effects", None) else []
    use = [e for e in effects if not type(e).states]
    skipped = [e.name for e in effects if type(e).states]
    if skipped:
        log.debug("component residuals: effects with a state of their own left out of the equations: %s", skipped)
    if not use:
        return None
    comp = composition_for(use)  # as the stepper and the replay compose them (hook terms first at a hook)
    return comp.functions, comp.ep(use), skipped


def equations(t, heave, stroke, pressure, wob, params, heave_reference=0.0, cutoff=CUTOFF):
    """The three equation residuals and the signals they are built from.

    The model side is the nominal CMC with the memoryless plant effects of ``params``' own
    ``[[effects]]`` at their hooks (:func:`file_hooks`): against a calibrated file, what it leaves.

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times.
    heave : numpy.ndarray [m]
        Measured heave.
    stroke : numpy.ndarray [m]
        Measured compensator stroke.
    pressure : numpy.ndarray [Pa]
        Measured gas pressure (gauge).
    wob : numpy.ndarray [N]
        Measured weight on bit.
    params : heavecomp.params.CMCParams
        The model's parameters (nominal tables and the file's own plant effects, :func:`file_hooks`).
    heave_reference : float [m]
        The heave of the operating point (``InitialState.heave_reference``).
    cutoff : float [Hz]
        Zero-phase low-pass of every channel before the equations.

    Returns
    -------
    (residuals {top_mass [N], lower_mass [N], gas [Pa]}, signals {name: array}, sliding mask)
    """
    code, FP, PP, _ = plant_vectors(params)
    zh, dzh, ddzh = lowpass_zero_phase(t, heave, cutoff)
    zh = zh - heave_reference
    s, v, a = lowpass_zero_phase(t, stroke, cutoff)
    p, dp, _ = lowpass_zero_phase(t, pressure, cutoff)
    W, dW, ddW = lowpass_zero_phase(t, wob, cutoff)
    vb, ab = -dW / PP[KF], -ddW / PP[KF]
    yb = PP[D0] - (W + PP[CF] * vb) / PP[KF]
    T_meas = PP[MB] * (ab + PP[G]) - W                      # lower-mass balance: the tension it needs
    sliding = np.abs(v) > STUCK_SPEED
    sv = np.sign(v)
    F_meas = net_force(p, T_meas, ddzh, 0.0, PP) - PP[MC] * a  # top-mass balance: the friction it needs
    hooks = file_hooks(params)
    if hooks is None:
        F_nom = friction_jump(code, np.abs(v), p, FP) * sv + friction_cont(code, v, p, FP)
    else:
        fx, EP, _ = hooks
        X = np.zeros(4)  # memoryless effects only: no state is read
        F_nom = fx["sliding_friction_fx"](code, sv, v, p, s, X, FP, EP)
    # the bit lifted off (W near 0, and the filter's reach around it): y_b is not read from W there
    lifted = _dilate(t, W < LIFTOFF * max(float(np.median(W)), 0.0), 1.0 / cutoff)
    # away from rest and reversals by the filter's reach: there the filtered sign(v) jump is smeared and
    # the nominal law at the filtered v differs from the filtered friction (artefact, not gap)
    clear = ~_dilate(t, ~sliding | (np.diff(sv, prepend=sv[0]) != 0), REACH / cutoff)
    res = {"top_mass": np.where(clear, F_meas - F_nom, np.nan),
           "lower_mass": np.where(lifted, np.nan, T_meas - (tension(s, v, yb, vb, zh, dzh, PP) if hooks is None else
                                                            fx["tension_fx"](s, v, yb, vb, zh, dzh, X, PP, EP))),
           "gas": p - (gas_pressure(s, PP) if hooks is None else
                       cylinder_reading(fx["cylinder_pressure_fx"](s, v, X, PP, EP),
                                        fx["line_mass_fx"](s, v, X, PP, EP), a, PP))}
    dwell, rest = rest_durations(t, ~sliding)
    rel = zh + s - yb  # the string's stretch from the operating point (the effects' features read it as dz)
    sig = {"t": t, "x": s, "v": v, "a": a, "p": p, "dp": dp, "wob": W, "dwob": dW, "zh": zh, "dzh": dzh,
           "ddzh": ddzh, "rel": rel, "dz": rel, "vrel": dzh + v - vb, "dwell": dwell, "rest": rest,
           "still": ~sliding,
           # the gas effects' equation-error inputs (Effect.features): the nominal gas's absolute pressure at
           # the measured stroke, its absolute pre-charge and the plant vector (geometry for a gas state's rates)
           "p_gas_abs": gas_pressure(s, PP) + PP[PATM], "p_charge_abs": float(PP[P0ABS]), "PP": PP}
    return res, sig, sliding


#: per equation: {component: feature names} of the joint attribution regression (the equation's own
#: component is the rest; its nominal structure (constant, drift, stiffness) is listed under it)
SPLIT = {"gas": {"gas_spring": ("const", "t", "x"), "flow_line": ("v", "v_abs_v", "a"), "sensors": ("dp",)},
         "lower_mass": {"string_formation": ("const", "rel", "vrel"), "heave_input": ("zh", "dzh"),
                        "sensors": ("dwob",)},
         "top_mass": {"friction": (), "heave_input": ("ddzh",)}}
OWN = {"gas": "gas_spring", "lower_mass": "string_formation", "top_mass": "friction"}


#: per component: the features of its nominal structure whose coefficients a *constant* parameter error
#: keeps fixed over the run (:meth:`ComponentResiduals.stationarity`)
STRUCTURE = {"friction": ("sign_v", "v"), "gas_spring": ("const", "x"), "string_formation": ("const", "rel", "vrel")}
#: unit of a structure coefficient: the residual's unit (:data:`UNITS`) followed by this
PER_FEATURE = {"sign_v": "", "const": "", "v": " s/m", "vrel": " s/m", "x": "/m", "rel": "/m"}
WINDOWS = 4  #: time windows of the stationarity test


def _column(sig, name):
    if name == "sign_v":
        return np.sign(sig["v"])
    if name == "const":
        return np.ones(sig["t"].size)
    if name == "t":
        return sig["t"] - sig["t"][0]
    if name == "v_abs_v":
        return sig["v"] * np.abs(sig["v"])
    return sig[name]


@dataclasses.dataclass
class ComponentResiduals:
    """Component residuals of one run (:func:`residuals`).

    Attributes
    ----------
    t : array [s]
    equations : {top_mass, lower_mass, gas: array}  equation residuals [N, N, Pa]
    noise : {equation: float}  rms of the residual's change under the channels' own noise [N, N, Pa]
    parts : {component: {equation: array}}  each component's part of each equation residual
    residual : {component: array}  the residual a component's candidates are fitted to (its
        equation's residual minus the parts other components explain), unit :data:`UNITS`
    signals : {name: array}  the filtered signals (feature inputs, :meth:`Effect.features`)
    mask : boolean array  samples analysed (edges and the caller's mask)
    floor : {component: {equation: z}}  the same computation on the nominal model's noise-free replay
        (:func:`residuals` ``floor_channels``), subtracted in :meth:`gap`
    """

    t: np.ndarray
    equations: dict
    noise: dict
    parts: dict
    residual: dict
    signals: dict
    mask: np.ndarray
    floor: dict = dataclasses.field(default_factory=dict)
    #: {component: {equation: array}}: the floor's own parts (the nominal replay's split), sample by sample,
    #: for a caller that sums them over its own blocks (the monitor)
    floor_parts: dict = dataclasses.field(default_factory=dict)
    inputs: dict = dataclasses.field(default_factory=dict)
    #: the equations the log's channels cannot compute (:func:`unobservable`): their residuals are NaN
    missing: tuple = ()
    #: {component: equation} for a component that is a part of another's equation (:data:`SPLIT`):
    #: the equation its :attr:`residual` was taken from
    host: dict = dataclasses.field(default_factory=dict)

    @property
    def angle(self) -> bool:
        """The log carries a vessel angle (:data:`~heavecomp.diagnosis.data.ANGLES`): a heave reading's lever arm,
        L sin(theta), is in no column of the split (z_h, dz_h, d2z_h), which can then neither show nor rule
        out such a reading (the pre-screen replays it; the verdict's table check does not lower it)."""
        return any(a in self.signals for a in ANGLES)

    def observable(self) -> dict:
        """{component: whether an equation that carries a part of it is computable from the log's channels}."""
        return {c: any(e not in self.missing for e in self.parts.get(c, {})) for c in COMPONENTS}

    def z(self, mask=None) -> dict:
        """{component: {equation: mean square of its part / noise variance of the equation}} [-]."""
        m = self.mask if mask is None else (mask & self.mask)
        out = {}
        for c in COMPONENTS:
            out[c] = {}
            for eq, part in self.parts.get(c, {}).items():
                ok = m & np.isfinite(part)
                if ok.any() and self.noise[eq] > 0:
                    out[c][eq] = float(np.mean(part[ok] ** 2)) / self.noise[eq] ** 2
        return out

    def gap(self, mask=None) -> dict:
        """Per component: mean square of its parts over the noise variance of their equations, minus
        the noise's expected 1 for the equations' own rests and minus :attr:`floor` (what the same
        computation makes of the nominal model's own replay: filter and stick-event artefacts),
        clipped at 0 [-]."""
        return gap_of(self.z(mask), self.floor)

    def shares(self, mask=None) -> dict:
        """``where.components``: shares of the gap by component, summing to 1, over the components whose
        gap reaches :data:`SHARE_MIN` (all 0: no component rises above its noise; shares of gaps below it
        were noise: a dwell-stiction run read 0.43 "sensors" from gaps of 0.04-0.06)."""
        g = {c: (x if x >= SHARE_MIN else 0.0) for c, x in self.gap(mask).items()}
        tot = sum(g.values())
        return {c: (g[c] / tot if tot > 0 else 0.0) for c in COMPONENTS}

    def gap_to_noise(self, mask=None) -> dict:
        """Per component: rms of its parts over the noise, sqrt(1 + gap) for its own equation [-]."""
        return {c: math.sqrt(1.0 + g) for c, g in self.gap(mask).items()}

    def own_features(self, component) -> tuple | None:
        """The open search's features of a component that is a part of another's equation: its own parts
        in the equation its residual was taken from (:data:`SPLIT`; ``flow_line``: v, v|v| and the
        acceleration a).  None for a component that owns an equation (the full library).

        Its residual is that equation's rest plus its part, so the equation's own signals (the gas law's
        p and x) would rebuild the residual's definition (the host's structure), not the part: a
        flow-line search on a turbulent line kept const, signs, p and x and lost the v|v| term
        (docs/diagnosis.md, "the open search per component").

        Parameters
        ----------
        component : str
            A component of :data:`heavecomp.effects.base.COMPONENTS`.
        """
        e = self.host.get(component)
        return tuple(SPLIT[e][component]) if e is not None else None

    def signals_for(self, component) -> dict:
        """The ``sig`` of :meth:`Effect.features` for a component (``x``/``v`` are the string's relative
        displacement and velocity for ``string_formation``)."""
        sig = dict(self.signals)
        if component == "string_formation":
            sig["x"], sig["v"] = sig["rel"], sig["vrel"]
        return sig

    def stationarity(self, component, mask=None, windows=WINDOWS, *, drift_sigmas=VerdictPolicy.drift_sigmas,
                     drift_share=VerdictPolicy.drift_share) -> dict:
        """Does the component's residual keep its shape over the run?  Its least-squares coefficients on
        the component's nominal structure (:data:`STRUCTURE`: a wrong constant parameter of the nominal
        law) in ``windows`` equal time windows, with standard errors for the residual's correlation
        (about 2 x :data:`CUTOFF` independent samples per second).

        Returns {windows [s], drifting: the features whose coefficient moves by >=  ``drift_sigmas``
        standard errors and >= ``drift_share`` of its mean magnitude between two windows,
        coefficients: per feature {feature, unit, value (per window), stderr (per window)}}; None when
        the component has no structure listed or too few samples."""
        feats = STRUCTURE.get(component)
        r = self.residual.get(component)
        if feats is None or r is None:
            return None
        m = (self.mask if mask is None else (mask & self.mask)) & np.isfinite(r)
        if m.sum() < 50 * windows:
            return None
        t = self.t
        dt = float(np.median(np.diff(t)))
        edges = np.linspace(t[m][0], t[m][-1] + dt, windows + 1)
        X = np.column_stack([_column(self.signals, f) for f in feats])
        coefs, errs, spans = [], [], []
        for a, b in zip(edges[:-1], edges[1:]):
            w = m & (t >= a) & (t < b)
            n = int(w.sum())
            if n <= 2 * len(feats):
                return None
            A = X[w]
            coef, *_ = np.linalg.lstsq(A, r[w], rcond=None)
            e = r[w] - A @ coef
            n_eff = max(n * dt * 2.0 * CUTOFF, len(feats) + 1.0)
            cov = np.linalg.pinv(A.T @ A) * float(np.mean(e * e)) * n / n_eff
            coefs.append(coef)
            errs.append(np.sqrt(np.maximum(np.diag(cov), 0.0)))
            spans.append([float(a), float(b)])
        C, E = np.array(coefs), np.array(errs)
        drifting = []
        for j, f in enumerate(feats):
            i, k = int(np.argmax(C[:, j])), int(np.argmin(C[:, j]))
            move = C[i, j] - C[k, j]
            se = math.hypot(E[i, j], E[k, j])
            if move >= drift_sigmas * se and move >= drift_share * abs(float(np.mean(C[:, j]))):
                drifting.append(f)
        return {"windows": spans, "drifting": drifting,
                "coefficients": [{"feature": f, "unit": UNITS[component] + PER_FEATURE[f], "value": C[:, j].tolist(),
                                  "stderr": E[:, j].tolist()} for j, f in enumerate(feats)]}

    def table(self, mask=None) -> list:
        """Rows for the report: component, share, rms of its residual [unit], noise [unit], gap/noise."""
        sh, gn = self.shares(mask), self.gap_to_noise(mask)
        m = self.mask if mask is None else (mask & self.mask)
        rows = []
        for c in COMPONENTS:
            r = self.residual[c]
            ok = m & np.isfinite(r)
            eqs = list(self.parts.get(c, {}))
            rows.append({"component": c, "share": sh[c], "gap_to_noise": gn[c],
                         "observable": any(e not in self.missing for e in eqs),
                         "rms": float(np.sqrt(np.mean(r[ok] ** 2))) if ok.any() else 0.0,
                         "noise": float(math.sqrt(sum(self.noise[e] ** 2 for e in eqs) / max(len(eqs), 1))),
                         "unit": UNITS[c], "equations": eqs})
        return rows


def residuals(run, params, *, heave_reference=None, noise=None, mask=None, cutoff=CUTOFF, seed=7,
              floor_channels=None) -> ComponentResiduals:
    """Component residuals of a :class:`~heavecomp.diagnosis.data.MeasuredRun` against the model of
    ``params``: the nominal equations with the file's own memoryless plant effects at their hooks
    (:func:`file_hooks`; a calibrated file's residuals show only what it leaves).

    Parameters
    ----------
    run : heavecomp.diagnosis.data.MeasuredRun
        The measured run (heave, stroke, pressure and wob columns).
    params : heavecomp.params.CMCParams
        The model's parameters (nominal tables and the file's plant effects).
    heave_reference : float [m], optional
        Heave of the operating point (default: the first filtered heave sample).
    noise : {channel: sigma}, optional
        Measurement noise per channel [SI] (default :func:`heavecomp.diagnosis.data.noise_floor`).
    mask : boolean array, optional
        Samples to analyse (e.g. after the settling window); the filter edges are always left out.
    floor_channels : {stroke, pressure, wob: array}, optional
        The nominal model's replay at the run's times (driven by the measured heave): its component
        z-values are the floor subtracted from the run's (:attr:`ComponentResiduals.floor`).
    cutoff : float [Hz]
        Zero-phase low-pass of every channel before the equations.
    seed : int
        Seed of the measurement-noise draws that measure each equation's noise.
    """

    t = run.t
    lost = tuple(k for k in ("stroke", "pressure", "wob") if k not in run.columns)
    if lost and floor_channels is None:
        raise DataError(f"{run.source}: column '{lost[0]}' missing: the component residuals without it need the "
                        "nominal replay in its place (the gap diagnosis gives it; floor_channels)")
    # a missing channel: the nominal replay stands in so the arrays exist; every equation that reads it is
    # not computable (:func:`unobservable`) and left out (NaN)
    ch = {k: fill_gaps(t, run[k] if k in run.columns else np.asarray(floor_channels[k], float))
          for k in ("heave", "stroke", "pressure", "wob")}
    missing = unobservable(lost)
    if heave_reference is None:
        heave_reference = float(lowpass_zero_phase(t, ch["heave"], cutoff)[0][0])
    m = (t >= t[0] + EDGE) & (t <= t[-1] - EDGE)
    if mask is not None:
        m &= mask
    noise = dict(noise) if noise else {k: noise_floor(run[k], None if run.uniform else t) for k in ch if k not in lost}
    noise = {k: noise.get(k, 0.0) for k in ch}
    out = _split(t, ch, params, heave_reference, cutoff, noise, m, seed, missing=missing)
    out.missing = missing
    for a in ANGLES:  # a logged vessel angle [rad], filtered as the heave (heave_reference's lever arm)
        if a in run.columns:
            out.signals[a] = lowpass_zero_phase(t, fill_gaps(t, run[a]), cutoff)[0]
    out.inputs = {"channels": ch, "params": params, "heave_reference": heave_reference, "cutoff": cutoff,
                  "channel_noise": noise, "present": tuple(k for k in READS if k not in lost)}
    if floor_channels is not None:
        ref = dict(ch, **{k: fill_gaps(t, np.asarray(floor_channels[k], float)) for k in ("stroke", "pressure", "wob")})
        nf = _split(t, ref, params, heave_reference, cutoff, None, m, seed, noise_of=out.noise, missing=missing)
        out.floor = nf.z()
        out.floor_parts = nf.parts
    return out


def gap_of(z, floor=None) -> dict:
    """Per component: the gap of :meth:`ComponentResiduals.gap` from the z-values ``z`` ({component:
    {equation: mean square of its part / noise variance}}) and the nominal replay's ``floor`` (the same,
    of the replay): the sum over its equations of z minus the noise's expected 1 for an equation's own
    rest minus the floor, each clipped at 0 [-].  The one computation of a gap: the diagnosis over its
    run, the monitor over each segment's blocks.

    Parameters
    ----------
    z : {component: {equation: float}}
        The run's z-values.
    floor : {component: {equation: float}}, optional
        The nominal replay's z-values (none: no floor subtracted).
    """
    floor = floor or {}
    return {c: sum(max(v - (1.0 if OWN[eq] == c else 0.0) - floor.get(c, {}).get(eq, 0.0), 0.0)
                   for eq, v in zs.items()) for c, zs in z.items()}


def unobservable(lost) -> tuple:
    """The equations that read a channel of ``lost`` (:data:`READS`): not computable without it.

    Parameters
    ----------
    lost : iterable of str
        The output channels (stroke, pressure, wob) the log does not have.
    """
    lost = set(lost)
    return tuple(e for e in SPLIT if any(e in READS[c] for c in lost))


def _split(t, ch, params, heave_reference, cutoff, noise, m, seed, noise_of=None, missing=()):
    """Equation residuals of channels ``ch`` (those in ``missing`` NaN: not computable), their noise (or
    ``noise_of``) and the attribution."""
    eq, sig, _ = equations(t, ch["heave"], ch["stroke"], ch["pressure"], ch["wob"], params, heave_reference, cutoff)
    for e in missing:
        eq[e] = np.full(t.size, np.nan)
    if noise_of is not None:
        return _attribute(t, eq, sig, noise_of, m)
    # noise of each equation residual: the change when every channel gets its own noise again
    rng = np.random.default_rng(seed)
    eq2, _, _ = equations(t, *(ch[k] + rng.normal(0.0, noise[k], t.size) for k in ("heave", "stroke", "pressure", "wob")),
                          params, heave_reference, cutoff)
    sig_noise = {}
    for k in eq:
        d = eq2[k] - eq[k]
        ok = m & np.isfinite(d)
        sig_noise[k] = float(np.sqrt(np.mean(d[ok] ** 2))) if ok.any() else 0.0
    return _attribute(t, eq, sig, sig_noise, m)


def _attribute(t, eq, sig, sig_noise, m):
    """Split each equation residual into the components' parts (:data:`SPLIT`, joint least squares on ``m``)."""
    parts = {c: {} for c in COMPONENTS}
    resid = {}
    for e, split in SPLIT.items():
        r = eq[e]
        names = [(c, f) for c, fs in split.items() for f in fs]
        ok = m & np.isfinite(r)
        X = np.column_stack([_column(sig, f) for _, f in names]) if names else np.zeros((t.size, 0))
        contrib = {c: np.zeros(t.size) for c in split}
        if names and ok.sum() > len(names):
            sc = X[ok].std(axis=0)
            sc[sc == 0] = 1.0
            coef, *_ = np.linalg.lstsq(X[ok] / sc, r[ok], rcond=None)
            for j, ((c, _), k) in enumerate(zip(names, coef / sc)):
                contrib[c] = contrib[c] + k * X[:, j]
        own = OWN[e]
        rest = r - sum(contrib[c] for c in split if c != own)
        parts[own][e] = rest
        for c in split:
            if c != own:
                parts[c][e] = np.where(np.isfinite(r), contrib[c], np.nan)
        resid[own] = rest
    # a component that only explains parts of other equations: its residual is the equation's (the one
    # where it is largest) with the other components' parts removed (what its candidates see)
    def size(c, k):  # mean square over the noise of component c's part in equation k (-1: not computable)
        v = parts[c][k][m]
        v = v[np.isfinite(v)]
        return float(np.mean(v * v)) / max(sig_noise[k], 1e-300) ** 2 if v.size else -1.0

    host = {}
    for c in COMPONENTS:
        if c not in resid:
            e = max(parts[c], key=lambda k: size(c, k))
            resid[c] = parts[OWN[e]][e] + parts[c][e]
            host[c] = e
    return ComponentResiduals(t, eq, sig_noise, parts, resid, sig, m, host=host)


# ---------------------------------------------------------------------------- sensors: one channel misreads
#: the equations that read each measured channel: a channel that misreads shows in every one of them
READS = {"stroke": ("gas", "lower_mass", "top_mass"), "pressure": ("gas", "top_mass"),
         "wob": ("lower_mass", "top_mass")}
PLAY_WIDTHS = (0.05, 0.1, 0.2)  #: widths of the play (backlash) features, x the reading's standard deviation [-]
EDGE_SIGMAS = 3.0  #: a reading within this many noise sigmas of its extreme percentile is "at its limit" [-]
#: an equation "sees" a channel term whose held-out part reaches this many noise variances [-]
SEEN = 1.0
CONSISTENT_SHRINK = 0.05  #: every equation that sees the channel term must shrink at least this much [-]


def channel_features(y, sigma, motion=None) -> dict:
    """Generic misreadings of one channel, functions of its own reading ``y`` only (noise ``sigma``):
    ``abs``/``sq`` (a reading that bends away from linear, ``|y - median|``, ``(y - median)^2``),
    ``top``/``bottom`` (a reading held at its limit: within :data:`EDGE_SIGMAS` noise of its 99th / 1st
    percentile; with ``motion`` [m], the string top's position ``z_h + s``, also ``*_motion``: that
    indicator times the motion, the part of the load the reading no longer follows), ``play*`` (a
    reading through a play of :data:`PLAY_WIDTHS` x std, minus the reading).

    Returns {name: (array, readable expression)} in the channel's unit.

    Parameters
    ----------
    y : numpy.ndarray [unit of the channel]
        The channel's (gap-filled) reading.
    sigma : float [unit of the channel]
        The channel's measurement noise.
    motion : numpy.ndarray [m], optional
        The string top's position ``z_h + s`` (adds the ``*_motion`` features); None: none.
    """
    feats, _ = channel_terms(y, sigma, motion)
    return feats


def channel_terms(y, sigma, motion=None) -> tuple:
    """:func:`channel_features` and their constants: ({name: (array, expression)}, levels), the levels
    the features were made with (``center``, ``top_level``, ``bottom_level``, ``motion_top``,
    ``motion_bottom`` [m, of the ``motion`` given], ``play_width`` by feature name): what
    :class:`heavecomp.effects.sensor_term.SensorTerm` needs to carry a term as a reading correction.

    Parameters
    ----------
    y : numpy.ndarray [unit of the channel]
        The channel's (gap-filled) reading.
    sigma : float [unit of the channel]
        The channel's measurement noise.
    motion : numpy.ndarray [m], optional
        The string top's position ``z_h + s`` (adds the ``*_motion`` features); None: none.
    """
    y = np.asarray(y, float)
    hi, lo = np.quantile(y, [0.99, 0.01])
    lv = {"center": float(np.median(y)), "top_level": float(hi - EDGE_SIGMAS * sigma),
          "bottom_level": float(lo + EDGE_SIGMAS * sigma)}
    out = {"abs": (ST.feature("abs", y, lv), "|y - median y|"), "sq": (ST.feature("sq", y, lv), "(y - median y)^2"),
           "top": (ST.feature("top", y, lv), f"(y >= {lv['top_level']:.4g})"),
           "bottom": (ST.feature("bottom", y, lv), f"(y <= {lv['bottom_level']:.4g})")}
    if motion is not None:
        # held at its limit, the unread part follows what drives the channel: the string top's motion
        for k in ("top", "bottom"):
            at = out[k][0] > 0
            if at.any():
                lv[f"motion_{k}"] = float(np.mean(motion[at]))
                out[f"{k}_motion"] = (ST.feature(f"{k}_motion", y, lv, motion), f"{out[k][1]}*(z_h + s - mean there)")
    sd = float(np.std(y))
    for k in PLAY_WIDTHS:
        lv[f"play{k:g}"] = k * sd
        out[f"play{k:g}"] = (ST.feature("play", y, {"play_width": k * sd}), f"(play(y, {k * sd:.3g}) - y)")
    return out, lv


def _residualise(sig, eqs, n, fit, cols):
    """Each block (equation) of the stacked ``cols`` minus its least-squares fit, on the fit part, by
    that equation's attribution columns (:data:`SPLIT`) and a constant: the base refitted alongside
    every channel term once for all (Frisch-Waugh-Lovell; the blocks' bases are disjoint)."""
    out = {k: np.array(c, float) for k, c in cols.items()}
    ok = fit.copy()
    for c in out.values():
        ok &= np.isfinite(c)
    for j, e in enumerate(eqs):
        names = sorted({"const"} | {f for fs in SPLIT[e].values() for f in fs})
        B = np.column_stack([_column(sig, f) for f in names])
        sl = slice(j * n, (j + 1) * n)
        okj = ok[sl]
        if okj.sum() <= B.shape[1]:
            continue
        Y = np.column_stack([out[k][sl][okj] for k in out])
        sc = EE._scales(B[okj])
        coef, *_ = np.linalg.lstsq(B[okj] / sc, Y, rcond=None)
        fitted = (B / sc) @ coef
        for i, k in enumerate(out):
            out[k][sl] = out[k][sl] - fitted[:, i]
    return out


def _consistency(r, cols, fm, vm, eqs, n) -> dict:
    """Joint fit of a channel term on the stacked (residualised) equations; per equation its held-out
    part [noise variances] and shrink."""
    joint = EE.fit_columns(r, cols, fm, vm)
    term = sum(joint["coefficients"][k] * cols[k] for k in cols)
    per = {}
    for j, e in enumerate(eqs):
        sl = slice(j * n, (j + 1) * n)
        ok = vm[sl] & np.isfinite(r[sl]) & np.isfinite(term[sl])
        if ok.any():
            before = math.sqrt(np.mean(r[sl][ok] ** 2))
            after = math.sqrt(np.mean((r[sl] - term[sl])[ok] ** 2))
            per[e] = {"seen": float(np.mean(term[sl][ok] ** 2)), "shrink": 1.0 - after / before if before > 0 else 0.0}
    agree = [e for e in per if per[e]["seen"] >= SEEN and per[e]["shrink"] >= CONSISTENT_SHRINK]
    return {"coefficients": joint["coefficients"], "shrink": joint["shrink"], "equations": per,
            "consistent": len(agree) >= 2}


def _levels_of(levels, feats, heave_reference) -> dict:
    """The feature constants the features ``feats`` use (``levels`` of :func:`channel_terms`), as
    :class:`heavecomp.effects.sensor_term.SensorTerm` reads them: a motion level on the log's own heave
    (the equations' heave is measured from ``heave_reference`` [m]), a play's width as ``play_width``."""
    out = {}
    for f in feats:
        kind = ST.base_name(f)
        if kind == "play":
            out["play_width"] = levels[f]
            continue
        out.setdefault("center", levels["center"])
        if kind.startswith("top"):
            out["top_level"] = levels["top_level"]
        if kind.startswith("bottom"):
            out["bottom_level"] = levels["bottom_level"]
        if kind.endswith("_motion"):
            key = "motion_" + kind.split("_")[0]
            out[key] = levels[key] + float(heave_reference)
    return out


def channel_search(cr, fit, validate) -> dict | None:
    """Cross-channel consistency: the best misreading of ONE channel (:func:`channel_features` of its
    own reading) that explains the residual of every equation that reads it (:data:`READS`).

    A channel feature ``f`` enters equation ``e`` as the change of its residual when the channel reads
    ``y + f`` (the equations evaluated again, nothing restated); the residuals of the equations reading
    the channel, each over its noise, are stacked and searched jointly
    (:func:`heavecomp.diagnosis.equation_error.open_search`, the equations' own attribution columns as
    base).  The term is *consistent* when at least two equations see it (its held-out part reaches
    :data:`SEEN` noise variances) and shrink by :data:`CONSISTENT_SHRINK` held out with the same
    coefficients: a string, seal or gas effect lives in one equation only (the others read the
    channel right), so a channel term fitted to it is seen in one equation, or predicts a part in
    another that is not there.  (An equation may see the term and not shrink: the top-mass balance
    reads the stroke through its second derivative, where a generic play's shape is only roughly
    right; measured on a backlash run, held-out shrinks 0.26 gas, 0.24 lower mass, -0.11 top mass.)

    Returns the best consistent term (by stacked held-out shrink): {``component``: "sensors",
    ``channel``, ``term``, ``features``, ``coefficients`` [-, per noise], ``shrink`` (stacked,
    held out), ``equations`` {e: {``seen`` [noise variances], ``shrink``}}}, or None.

    Parameters
    ----------
    cr : ComponentResiduals
        Component residuals of the run (:func:`residuals`; its ``inputs`` re-evaluate the equations).
    fit, validate : numpy.ndarray of bool
        Samples to fit on / to score on (held out).
    """
    inp = cr.inputs
    if not inp:
        return None
    t, ch = cr.t, inp["channels"]
    args = (inp["params"], inp["heave_reference"], inp["cutoff"])
    base_eq = cr.equations
    best = None
    missing = set(cr.missing)
    for c, eqs in READS.items():
        eqs = tuple(e for e in eqs if e not in missing)
        if c not in inp.get("present", READS) or len(eqs) < 2:  # a channel the log lacks, or seen once: no test
            continue
        sigma = float(inp["channel_noise"].get(c, 0.0)) or float(np.std(ch[c])) * 1e-3
        feats, levels = channel_terms(ch[c], sigma, cr.signals["zh"] + cr.signals["x"])
        lib = {}
        for name, (f, expr) in feats.items():
            scale = float(np.std(f))
            if not scale > 0:
                continue
            step = sigma / scale  # a perturbation of the reading's own noise size: linear
            pert = dict(ch, **{c: ch[c] + step * f})
            eq1, _, _ = equations(t, pert["heave"], pert["stroke"], pert["pressure"], pert["wob"], *args)
            lib[f"{c}:{name}"] = (np.concatenate([(eq1[e] - base_eq[e]) / step / cr.noise[e] for e in eqs]),
                                  f"{c}-misreading {expr}")
        if not lib:
            continue
        n = t.size
        fm = np.tile(fit & cr.mask, len(eqs))
        vm = np.tile(validate & cr.mask, len(eqs))
        stacked = _residualise(cr.signals, eqs, n, fm, dict(
            {"": np.concatenate([base_eq[e] / cr.noise[e] for e in eqs])}, **{k: a for k, (a, _) in lib.items()}))
        r = stacked.pop("")
        found = EE.open_search(r, None, fm, vm, component="sensors", max_terms=2,
                               features={k: (stacked[k], lib[k][1]) for k in lib})
        trials = [[k] for k in lib] + ([found["features"]] if found and len(found["features"]) > 1 else [])
        for feats in trials:
            d = _consistency(r, {k: stacked[k] for k in feats}, fm, vm, eqs, n)
            log.debug("channel %s: %s shrink %.2f per equation %s consistent %s", c, feats, d["shrink"],
                      d["equations"], d["consistent"])
            if d["consistent"] and d["shrink"] >= EE.MIN_SHRINK and (best is None or d["shrink"] > best["shrink"]):
                term = " + ".join(f"{d['coefficients'][k]:.3g}*{lib[k][1]}" for k in feats)
                best = dict(d, component="sensors", channel=c, features=feats, term=term,
                            levels=_levels_of(levels, [k.split(":", 1)[1] for k in feats], inp["heave_reference"]))
    return best
