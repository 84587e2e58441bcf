"""Candidate friction terms for a 1-DOF axis, written once as scalar ``np.*`` functions.

Each term is a regressor: the force it adds is ``coefficient * term(...)``, so a
candidate stays linear in its coefficient and only its shape parameter (a
velocity scale, a length, a time constant) needs a search.  The functions use
only ``np.*`` calls (numpy arrays, numba and casadi alike); the two with memory
(:func:`dahl_step`, :func:`lag_step`) are exact one-step updates for a velocity
held constant over the step, iterated by :func:`run_state`.
"""

from __future__ import annotations

import numpy as np


def stribeck_excess(v, v_s):
    """Stribeck excess shape exp(-|v|/v_S) sign(v) [-]; coefficient F_S - F_C [N].

    Notes
    -----
    Paper A eq. 4 (and the Stribeck curve of paper B): F = [F_C + (F_S - F_C)
    exp(-|v|/v_S)] sign(v); the base model carries F_C sign(v), this term the rest.
    ``v`` [m/s], ``v_s`` [m/s].
    """
    return np.exp(-np.abs(v) / v_s) * np.sign(v)


def positive_velocity(v):
    """max(v, 0) [m/s]; coefficient F_v+ - F_v- [N s/m] (asymmetric viscous friction)."""
    return np.maximum(v, 0.0)


def positive_direction(v):
    """Indicator of v > 0 [-]: with an offset column, (offset, F_c) <-> (F_c+, F_c-)."""
    return 0.5 * (1.0 + np.sign(v))


def fourier_position(q, q0, length, k, phase):
    """cos(2 pi k (q - q0)/L + phase) [-]: one Fourier term of a position-dependent force.

    ``q``, ``q0``, ``length`` [m]; ``k`` harmonic number; ``phase`` 0 (cosine) or
    -pi/2 (sine).  Multiplied by sign(v) it is position-dependent friction, alone a
    position-dependent force (cogging, cable drag, misalignment).
    """
    return np.cos(2.0 * np.pi * k * (q - q0) / length + phase)


def dahl_step(z, v, h, delta):
    """One exact step of the normalised Dahl friction state z (F = F_c z) [-].

    Notes
    -----
    Dahl (1968) model in the position domain, dz/dt = (v - |v| z) / delta, so that
    z -> sign(v) after a sliding distance of a few ``delta`` [m] (pre-sliding
    length, frictional lag in distance).  For v constant over the step h [s]:
    z+ = sign(v) + (z - sign(v)) exp(-|v| h / delta).
    """
    s = np.sign(v)
    return s + (z - s) * np.exp(-np.abs(v) * h / delta)


def lag_step(y, x, h, tau):
    """One exact step of a first-order lag dy/dt = (x - y)/tau, x held over h [s]."""
    return x + (y - x) * np.exp(-h / tau)


def run_state(step, x, h, par, y0=0.0) -> np.ndarray:
    """Iterate ``y[k+1] = step(y[k], x[k], h, par)``; returns y (same length as x)."""
    y = np.empty(len(x))
    yk = float(y0)
    for i, xi in enumerate(np.asarray(x, dtype=float)):
        y[i] = yk
        yk = float(step(yk, xi, h, par))
    return y
