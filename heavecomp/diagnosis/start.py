"""Start anywhere: the replay's initial state estimated from the first seconds of a measured run.

A rig log starts wherever the rig was, not at rest at the operating point.  Measured are the
stroke s, the pressure p and the WOB W; the rest follows from the operating point
(``docs/contracts/parameter-file.md``):

- stroke and stroke velocity (s_0, v_0): a least-squares polynomial over the first
  ``window`` seconds of the stroke, evaluated at t = 0 (a straight line when the
  compensator is stuck there: the measured speed below ``stuck_speed`` and the stroke
  flat to within its noise);
- the heave reference z_ref (the heave the operating point belongs to): a log cut from a
  longer record starts at an arbitrary heave, and the string only feels
  z_h + s - y_b.  The lower mass is quasi-static below its eigenfrequency (> 1 Hz, the
  waves < 0.7 Hz), so at every sample of the window the string tension balances the WOB,
  k_ds (z - z_ref + s - y_b) = W_0 - W with y_b = delta_0 - W / k_F; z_ref is the mean of
  that balance over the window (the stroke taken from its fit, the heave from the replay's
  filtered heave, so the replay's own start is consistent);
- the lower mass (y_b, v_b): from the measured WOB at t = 0 and its slope (a straight line
  over ``LOWER_WINDOW``), W = k_F (delta_0 - y_b) - c_F v_b;
- the memory states of the effects start from their steady values at v_0
  (:func:`heavecomp.diagnosis.stepper.run_segments`).

At rest at the operating point every estimate is zero within its noise and z_ref is the
first (filtered) heave sample: the replay of a log that does start at rest is the replay
from rest.

A log without a stroke or a WOB channel (contract schema 3): what that channel would tell is
taken from the operating point and listed in ``assumed`` -- no stroke: s_0 = v_0 = 0, stuck (the
static operating point), and s = 0 in the z_ref balance (over the window's waves the stroke
averages near its static value); no WOB: W = W_0 (y_b = delta_0, v_b = 0) in the balance and at
t = 0.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from heavecomp.diagnosis.data import noise_floor, ZREF_WINDOW

WINDOW = 2.0  #: s of the measurement the initial state is estimated from
STUCK_SPEED = 2e-3  #: m/s; below this measured stroke speed the compensator starts stuck
LOWER_WINDOW = 0.15  #: s of WOB the lower-mass state is read from
REST_SIGMAS = 4.0  #: an estimate within this many standard errors of the operating point counts as "at rest"


@dataclasses.dataclass
class InitialState:
    """The replay's initial state (SI, from the operating point) and how it was found."""

    stroke: float
    stroke_velocity: float
    lower_displacement: float
    lower_velocity: float
    stuck: bool
    heave_reference: float
    wob: float  #: measured WOB at t = 0 (straight line over the window) [N]
    at_rest: bool
    window: float
    sigma: dict
    #: what was taken from the operating point because its channel is missing (``stroke``, ``wob``)
    assumed: tuple = ()

    def start(self):
        """The ``starts`` entry of :func:`heavecomp.diagnosis.stepper.run_segments`."""
        return (self.stroke, self.stroke_velocity, self.lower_displacement, self.lower_velocity, self.stuck)

    def to_json(self) -> dict:
        return {"stroke": self.stroke, "stroke_velocity": self.stroke_velocity,
                "lower_displacement": self.lower_displacement, "lower_velocity": self.lower_velocity,
                "stuck": bool(self.stuck), "heave_reference": self.heave_reference, "wob": self.wob,
                "at_rest": bool(self.at_rest), "window_s": self.window,
                "standard_error": {k: float(v) for k, v in self.sigma.items()},
                **({"assumed_from_operating_point": list(self.assumed)} if self.assumed else {})}


def _poly_at_zero(t, y, deg):
    """Value and slope at t = 0 of a least-squares polynomial of degree ``deg``, and the residual
    standard deviation."""
    ok = np.isfinite(y)
    c = np.polynomial.polynomial.polyfit(t[ok], y[ok], deg)
    res = y[ok] - np.polynomial.polynomial.polyval(t[ok], c)
    sd = float(np.sqrt(np.sum(res * res) / max(ok.sum() - deg - 1, 1)))
    return float(c[0]), float(c[1]) if deg >= 1 else 0.0, sd, c


def _stroke_at_start(tw, s, sigma, stuck_speed):
    """Stroke and stroke velocity at t = 0 from the first samples ``s`` at times ``tw`` [s from the start].

    The window is the longest of ``tw[-1]``, /2, /4, /8, /16 on which one regime describes the stroke: stuck
    (a straight line with a slope under ``stuck_speed`` within 1.5x the noise ``sigma``; s_0 its mean)
    or sliding (a parabola within 1.2x the noise; s_0 and v_0 its value and slope at 0).  A stick or
    breakaway event inside the window shortens it.  Returns (s0, v0, stuck, standard error of s0,
    window used [s]).
    """
    sigma = max(sigma, 1e-12)
    full = float(tw[-1]) if tw.size else 0.0
    for k in range(5):
        win = full / 2 ** k
        m = tw <= win + 1e-12
        if m.sum() < 8 and k:
            break
        n = max(int(np.isfinite(s[m]).sum()), 1)
        _, v_lin, sd_lin, _ = _poly_at_zero(tw[m], s[m], 1)
        if abs(v_lin) < stuck_speed and sd_lin < 1.5 * sigma:
            return float(np.nanmean(s[m])), 0.0, True, sigma / math.sqrt(n), win
        s0, v0, sd_q, _ = _poly_at_zero(tw[m], s[m], 2)
        best = (s0, v0, False, 3.0 * sigma / math.sqrt(n), win)
        if sd_q < 1.2 * sigma:
            return best
    return best


def _wob_slope(tw, W, at):
    """dW/dt [N/s] at time ``at`` from a straight line over the LOWER_WINDOW (at least 8 samples) nearest it."""
    d = np.abs(tw - at)
    m = d <= max(LOWER_WINDOW, np.sort(d)[min(7, d.size - 1)])
    return _poly_at_zero(tw[m] - at, W[m], 1)[1]


def string_balance_heave(z, s, W, params):
    """The heave reference the quasi-static string balance implies at each sample [m]:
    k_ds (z - z_ref + s - y_b) = W_0 - W with y_b = delta_0 - W / k_F, solved for z_ref (the lower mass is
    quasi-static below its eigenfrequency; its inertia averages out over a window of waves).  Read by the
    start estimate over its window and by the monitor over a segment's block means.

    Parameters
    ----------
    z, s, W : float or array
        Heave [m], stroke [m] and WOB [N] (a missing stroke: 0; a missing WOB: W_0).
    params : CMCParams
        The parameters (string and formation stiffness, the WOB set-point W_0).
    """
    kds, kF = params.drill_string.stiffness, params.formation.stiffness
    W0 = params.operating_point.wob_setpoint
    yb = W0 / kF - W / kF
    return z + s - yb - (W0 - W) / kds


def estimate(run, params, heave_filtered, *, window=WINDOW, stuck_speed=STUCK_SPEED, noise=None) -> InitialState:
    """Estimate the initial state of a measured run (see the module docstring).

    Parameters
    ----------
    run : MeasuredRun
    params : CMCParams
        The nominal parameters (operating point, string and formation stiffness).
    heave_filtered : callable t -> z [m]
        The replay's pre-filtered heave at the run's times (before the reference is removed).
    window : float [s]
    stuck_speed : float [m/s]
    noise : dict, optional
        Output-noise standard deviation per channel (for the standard errors); estimated if missing.
    """

    t = run.t
    w = t <= t[0] + window
    if w.sum() < 8:
        w = np.zeros(t.size, bool)
        w[: min(8, t.size)] = True
    tw = t[w] - t[0]
    ds, fo, op = params.drill_string, params.formation, params.operating_point
    kds, kF, W0 = ds.stiffness, fo.stiffness, op.wob_setpoint
    assumed = tuple(c for c in ("stroke", "wob") if c not in run.columns)
    # a missing channel reads as its operating-point value (module docstring), with no noise
    col = {c: (run[c] if c in run.columns else np.full(t.size, 0.0 if c == "stroke" else W0)) for c in ("stroke", "wob")}
    s = col["stroke"][w]
    W = col["wob"][w]
    noise = dict(noise or {})
    for c in ("stroke", "wob"):
        if c not in noise:
            noise[c] = noise_floor(col[c], None if run.uniform else run.t) if c in run.columns else 0.0
    if "stroke" in run.columns:
        s0, v0, stuck, se_s, used = _stroke_at_start(tw, s, noise["stroke"], stuck_speed)
    else:
        s0, v0, stuck, se_s, used = 0.0, 0.0, True, 0.0, float(tw[-1])
    delta0 = W0 / kF
    # heave reference: a constant, so read from the string balance away from the filter's edge
    # (the first ZREF_WINDOW[0] s of the filtered heave carry its edge error) over ZREF_WINDOW
    rel = t - t[0]
    wz = (rel >= ZREF_WINDOW[0]) & (rel <= ZREF_WINDOW[1])
    if wz.sum() < 8:
        wz = w
    tz = rel[wz]
    Wz, sz = col["wob"][wz], col["stroke"][wz]
    z = heave_filtered(t[wz])
    ok = np.isfinite(Wz) & np.isfinite(sz)
    # the lower mass' inertia over the window, mean(m_b a_b) = m_b (v_b(end) - v_b(start)) / T, with
    # v_b = -dW/dt / k_F from straight lines at both ends (it oscillates at its own mode after stick events)
    inertia = (ds.lower_mass * (_wob_slope(tz, Wz, tz[-1]) - _wob_slope(tz, Wz, tz[0])) / (-kF)
               / max(tz[-1] - tz[0], 1e-9))
    zref = float(np.mean(string_balance_heave(z, sz, Wz, params)[ok]) - inertia / kds)
    se_z = math.hypot(noise["wob"] * (1.0 / kds + 1.0 / kF), noise["stroke"]) / math.sqrt(max(int(ok.sum()), 1))
    # lower mass from the measured WOB at t = 0 (a straight line over LOWER_WINDOW: shorter than half a
    # period of the lower-mass mode, which stick events excite), W = k_F (delta_0 - y_b) - c_F v_b
    m = tw <= max(LOWER_WINDOW, tw[min(7, tw.size - 1)])
    W_0t, dW, _, _ = _poly_at_zero(tw[m], W[m], 1)
    vb0 = -dW / kF
    yb0 = delta0 - (W_0t + fo.damping * vb0) / kF
    # measured WOB at t = 0 (straight line over the window) decides "at rest" with the stroke
    W_meas = _poly_at_zero(tw, W, 1)[0]
    se_W = 2.0 * noise["wob"] / math.sqrt(max(int(np.isfinite(W).sum()), 1))
    at_rest = (stuck and abs(s0) <= REST_SIGMAS * max(se_s, 1e-6) + 1e-3
               and abs(W_meas - W0) <= REST_SIGMAS * se_W + 0.01 * W0)
    return InitialState(stroke=s0, stroke_velocity=v0, lower_displacement=float(yb0), lower_velocity=float(vb0),
                        stuck=bool(stuck), heave_reference=zref, wob=W_meas, at_rest=bool(at_rest),
                        window=float(used), sigma={"stroke": se_s, "heave_reference": se_z, "wob": se_W},
                        assumed=assumed)
