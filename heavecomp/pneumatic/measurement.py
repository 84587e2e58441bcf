"""Friction measured from pressure and displacement (paper B's method), validated on synthetic data.

A run of the pneumatic plant with known three-regime friction is "measured" like
paper B's rig (encoder quantised to 12.5 um, pressure sensor noise), and the
friction is recovered with :func:`heavecomp.signals.friction_from_motion` — only
the equation of motion ``M a = A (P_a - P_b) - F_f`` is shared with the generator,
not the friction law.  On measured data (the TU Delft O-ring files) the method is
one of the analysis variants of the seal study
(:data:`heavecomp.identification.seal.METHOD_VARIANTS`).
"""

from __future__ import annotations

import logging

import numpy as np

from heavecomp.pneumatic import plant as pn
from heavecomp.pneumatic import stepper as PS
from heavecomp.signals import friction_from_motion

log = logging.getLogger(__name__)

ENCODER_RESOLUTION = 12.5e-6  # m, paper B's optical encoder


def synthetic_validation(p=None, *, duration: float = 3.0, fs: float = 1000.0, cutoff: float = 25.0,
                         pressure_noise: float = 200.0, seed: int = 0) -> dict:
    """Recover the known friction of a simulated Exp.-2 run.

    Parameters
    ----------
    p : PneumaticParams, optional (default cylinder)
    duration : float [s]
    fs : float [Hz]  sampling rate of the synthetic measurement
    cutoff : float [Hz]  FIR cutoff
    pressure_noise : float [Pa]  standard deviation of each pressure sensor
    seed : int  seed of the pressure noise

    Returns
    -------
    dict: ``t``, true and measured ``friction`` [N], ``velocity`` [m/s], and
    ``rms_error_N``/``friction_span_N``/``velocity_rms_error`` over the sliding
    samples (excluding 30 ms around each stick/branch event, where the true
    friction jumps and no band-limited method can follow).
    """
    p = p or pn.default()
    r = PS.simulate(p, duration, rate=fs)
    rng = np.random.default_rng(seed)
    x = np.round(r["position"] / ENCODER_RESOLUTION) * ENCODER_RESOLUTION
    Pa = r["pressure_a"] + rng.normal(0.0, pressure_noise, x.size)
    Pb = r["pressure_b"] + rng.normal(0.0, pressure_noise, x.size)
    m = friction_from_motion(r["t"], x, p.area * (Pa - Pb), p.mass, cutoff)
    events = np.flatnonzero(np.diff(r["stuck"]) != 0) + 1
    events = np.concatenate([events, np.flatnonzero(np.diff(r["accelerating"]) != 0) + 1])
    ok = (r["stuck"] < 0.5) & (r["t"] > 0.05) & (r["t"] < duration - 0.05)
    guard = int(0.03 * fs)
    for e in events:
        ok[max(0, e - guard):e + guard] = False
    err = m["friction"] - r["friction"]
    return {"t": r["t"], "friction_true": r["friction"], "friction_measured": m["friction"],
            "velocity_true": r["velocity"], "velocity_measured": m["velocity"], "sliding": ok,
            "rms_error_N": float(np.sqrt(np.mean(err[ok] ** 2))),
            "max_error_N": float(np.max(np.abs(err[ok]))),
            "friction_span_N": float(np.ptp(r["friction"][ok])),
            "velocity_rms_error": float(np.sqrt(np.mean((m["velocity"] - r["velocity"])[ok] ** 2))),
            "cutoff_Hz": cutoff, "fs_Hz": fs, "pressure_noise_Pa": pressure_noise}
