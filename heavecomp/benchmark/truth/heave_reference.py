"""heave_reference, as generated: the heave signal is not the heave the compensator sees.

Variant ``lever_arm`` (default): measured at a lever arm L, z_m = z + L sin(theta(t)), theta a
synthetic pitch logged as column ``pitch`` [rad]; variant ``mru``: a motion reference unit with a
gain error and a 2nd-order high-pass; variant ``mru_drift``: an MRU's 2nd-order high-pass with its corner
near 100 s and a slow drift of centimetres (the maintainers' held-back set, issue 30).  The candidate (fitted, :mod:`heavecomp.effects`) is a
scaled, shifted heave less a lever arm times a pitch.
"""

from __future__ import annotations

import numpy as np

from heavecomp.benchmark.truth.base import Draw, TruthLaw


def synthetic_pitch(t, amplitude, period, seed):
    """A vessel pitch angle [rad]: narrow-band random (a sum of 12 components spread +-15 % around
    ``period`` [s], random phases), rms ``amplitude`` [rad].

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times.
    amplitude : float [rad]
        Rms of the pitch angle.
    period : float [s]
        Centre period of the 12 components.
    seed : int
        Seed of the components' frequencies and phases.

    Returns
    -------
    numpy.ndarray [rad]
        Pitch angle at ``t``.
    """
    rng = np.random.default_rng(seed)
    f = rng.uniform(0.85, 1.15, 12) / period
    ph = rng.uniform(0, 2 * np.pi, 12)
    th = np.sum(np.cos(2 * np.pi * f[:, None] * t[None, :] + ph[:, None]), axis=0)
    return amplitude * th / np.sqrt(6.0)


def heave_lever_arm(t, cols, lever_arm, pitch):
    """Heave measured at a lever arm L [m] from the compensator: z_m = z + L sin(theta).

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times (uniform).
    cols : dict
        Clean logged channel -> array [SI].
    lever_arm : float [m]
        Horizontal distance L from the heave sensor to the compensator.
    pitch : numpy.ndarray [rad]
        Vessel pitch angle theta at ``t``.

    Returns
    -------
    dict
        ``cols`` with ``heave`` measured at the lever arm and a ``pitch`` column [rad] added (a new dict).
    """
    out = dict(cols)
    out["heave"] = cols["heave"] + lever_arm * np.sin(pitch)
    out["pitch"] = pitch
    return out


def heave_mru(t, cols, gain, corner=0.01):
    """Heave from a motion reference unit with a gain error and a 2nd-order Butterworth high-pass at
    ``corner`` [Hz] (its drift-free double integration).

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times (uniform).
    cols : dict
        Clean logged channel -> array [SI].
    gain : float [-]
        Factor of the MRU's heave (1: no gain error).
    corner : float [Hz]
        Corner frequency of the high-pass.

    Returns
    -------
    dict
        ``cols`` with ``heave`` replaced by the MRU's reading [m] (a new dict).
    """
    from scipy.signal import butter, lfilter

    out = dict(cols)
    if corner <= 0.0:  # no high-pass (a drift alone)
        out["heave"] = gain * np.asarray(cols["heave"], dtype=float)
        return out
    b, a = butter(2, corner, btype="highpass", fs=1.0 / (t[1] - t[0]))
    out["heave"] = gain * lfilter(b, a, cols["heave"])
    return out


def heave_drift(t, amplitude, period, phase):
    """A slow drift of an MRU's heave [m]: amplitude sin(2 pi t / period + phase).

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times.
    amplitude : float [m]
        Amplitude of the drift.
    period : float [s]
        Its period (minutes: far below the wave band).
    phase : float [rad]
        Its phase at t = 0.
    """
    return amplitude * np.sin(2.0 * np.pi * np.asarray(t, dtype=float) / period + phase)


def misreference(t, cols, **parameters):
    """The logged heave of a drawn lever arm (``lever_arm``, ``pitch_rms`` [rad], ``pitch_period`` [s],
    ``pitch_seed``) or of a drawn MRU (``gain_error`` [-], ``corner`` [Hz]).

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times (uniform).
    cols : dict
        Clean logged channel -> array [SI].
    **parameters : dict
        The drawn parameters: ``lever_arm`` [m], ``pitch_rms`` [rad], ``pitch_period`` [s],
        ``pitch_seed`` (int); or ``gain_error`` [-], ``corner`` [Hz].

    Returns
    -------
    dict
        ``cols`` with the misreferenced ``heave`` [m] (and ``pitch`` [rad] for a lever arm).
    """
    p = parameters
    if "lever_arm" in p:
        return heave_lever_arm(t, cols, p["lever_arm"],
                               synthetic_pitch(t, p["pitch_rms"], p["pitch_period"], p["pitch_seed"]))
    out = heave_mru(t, cols, 1.0 + p["gain_error"], p["corner"])
    if "drift" in p:
        out["heave"] = out["heave"] + heave_drift(t, p["drift"], p["drift_period"], p["drift_phase"])
    return out


def draw(rng, setting):
    """``mru``: a gain 8-14 % low and a 0.005-0.015 Hz high-pass, size the gain error, at most 50 %;
    ``mru_drift``: a 0.008-0.012 Hz high-pass and a drift of 1.5-2.5 cm over 10-30 min, size the corner, at
    most 0.05 Hz (zero: the drift alone);
    else L 5-15 m, pitch rms 0.005-0.01 rad at 8-12 s, size L, at most 120 m.

    Parameters
    ----------
    rng : numpy.random.Generator
        The case's random stream.
    setting : heavecomp.benchmark.truth.Setting
        What the draw may depend on; this law reads ``variant`` (``mru``, else a lever arm).

    Returns
    -------
    heavecomp.benchmark.truth.Draw
        The law's parameters [SI], the parameter that sets its size and that size's cap.
    """
    if setting.variant == "mru":
        return Draw({"gain_error": -rng.uniform(0.08, 0.14), "corner": rng.uniform(0.005, 0.015)}, "gain_error", 0.5)
    if setting.variant == "mru_drift":  # no gain error: the high-pass near 100 s and a 2 cm drift over minutes
        # the size knob is the corner: the high-pass's phase lead in the wave band (~ sqrt(2) f_c / f rad)
        # moves the stroke far more than a 2 cm drift does (18 x the floor against nothing measurable)
        return Draw({"gain_error": 0.0, "corner": rng.uniform(0.008, 0.012), "drift": rng.uniform(0.015, 0.025),
                     "drift_period": rng.uniform(600.0, 1800.0), "drift_phase": rng.uniform(0.0, 2 * np.pi)},
                    "corner", 0.05)
    return Draw({"lever_arm": rng.uniform(5.0, 15.0), "pitch_rms": rng.uniform(0.005, 0.01),
                 "pitch_period": rng.uniform(8.0, 12.0), "pitch_seed": int(rng.integers(2**31))}, "lever_arm", 120.0)


LAW = TruthLaw("heave_reference", "heave_input", draw, output=misreference, on_heave=True,
               variants=("lever_arm", "mru", "mru_drift"))
