"""Paper B's three-regime seal friction (Fujita, Tokashiki, Kagawa 1999, Fig. 3).

Three lubrication modes, as measured on a 32 mm rodless pneumatic cylinder:

* **boundary lubrication** (v = 0): maximum static friction; it differs between
  the first start from the cylinder cover (``F_0``) and later sticks (``F_s1``);
* **mixed lubrication** (0 < |v| < u_cr): friction falls with velocity (negative
  slope) until the critical velocity ``u_cr`` (paper: 0.06 m/s);
* **elasto-hydrodynamic lubrication** (|v| >= u_cr): Coulomb plus viscous,
  ``F_C + C |v|`` (paper: C = 64 N s/m).

The static->dynamic transition differs from the dynamic->static one (paper B:
"friction force change from static to dynamic is different from the change from
dynamic to static").  We express this with two branches of the same shape that
differ only in their v -> 0 limit (the *peak*):

* accelerating branch, entered at breakaway: peak = the static force just
  overcome (``F_0`` or ``F_s1``), so the friction falls continuously from the
  breakaway force;
* decelerating branch, entered at the velocity maximum: peak = ``F_k``
  (default ``F_C``: the EHDL line continued down to v = 0, the
  "viscous-like when decelerating" behaviour paper A also reports).

Mixed-lubrication shape (our assumption, the paper gives only the curve):
``(peak - F_C) * max(0, 1 - |v|/u_cr)**2`` — zero slope at ``u_cr`` so the
branches join the EHDL line smoothly.

All functions are scalar ``np.*`` code (numba and casadi compile/trace the same
source, see ``docs/DEVELOPING.md``).  Friction parameter vector::

    FPB = [F_0, F_s1, F_C, C, u_cr, F_k]
"""

from __future__ import annotations

import dataclasses

import numpy as np

from heavecomp.errors import ParameterError

FPB_NAMES = ("start_static_force", "stick_static_force", "coulomb_force", "viscous_coefficient",
             "critical_velocity", "return_peak_force")
I_F0, I_FS1, I_FC, I_C, I_UCR, I_FK = range(6)


def mixed_shape(speed, ucr):
    """Mixed-lubrication weight ``max(0, 1 - speed/u_cr)^2`` in [0, 1] (dimensionless).

    Parameters
    ----------
    speed : float [m/s]
        Sliding speed |v| >= 0.
    ucr : float [m/s]
        Critical velocity u_cr, the end of mixed lubrication (> 0).
    """
    s = np.maximum(0.0, 1.0 - speed / ucr)
    return s * s


def branch_magnitude(speed, peak, FPB):
    """Friction magnitude [N] while sliding at ``speed`` = |v| >= 0 [m/s] on a branch
    whose limit at v -> 0 is ``peak`` [N].

    Parameters
    ----------
    speed : float [m/s]
        Sliding speed |v| >= 0.
    peak : float [N]
        The branch's limit at v -> 0: the static force just overcome (accelerating branch,
        F_0 or F_s1) or F_k (decelerating branch).
    FPB : (6,) array
        Friction parameters ``[F_0, F_s1, F_C, C, u_cr, F_k]`` [N, N, N, N s/m, m/s, N].

    Notes
    -----
    Paper B, Fig. 3 (three lubrication modes):
    ``F = F_C + (peak - F_C) max(0, 1 - |v|/u_cr)^2 + C |v|``.
    """
    return FPB[I_FC] + (peak - FPB[I_FC]) * mixed_shape(speed, FPB[I_UCR]) + FPB[I_C] * speed


def sliding_friction(v, peak, FPB):
    """Signed sliding friction [N] opposing ``v`` [m/s] (exact form; 0 at v = 0).

    Parameters
    ----------
    v : float [m/s]
        Piston velocity (the friction opposes it).
    peak : float [N]
        The branch's limit at v -> 0: the static force just overcome (accelerating branch,
        F_0 or F_s1) or F_k (decelerating branch).
    FPB : (6,) array
        Friction parameters ``[F_0, F_s1, F_C, C, u_cr, F_k]`` [N, N, N, N s/m, m/s, N].
    """
    return np.sign(v) * branch_magnitude(np.abs(v), peak, FPB)


def smooth_friction(v, peak, FPB, eps):
    """Regularised friction ``tanh(v/eps) * magnitude(|v|)`` [N], width ``eps`` [m/s].

    Parameters
    ----------
    v : float [m/s]
        Piston velocity.
    peak : float [N]
        The branch's limit at v -> 0: the static force just overcome (accelerating branch,
        F_0 or F_s1) or F_k (decelerating branch).
    FPB : (6,) array
        Friction parameters ``[F_0, F_s1, F_C, C, u_cr, F_k]`` [N, N, N, N s/m, m/s, N].
    eps : float [m/s]
        Regularisation width of ``tanh(v / eps)`` (> 0).
    """
    return np.tanh(v / eps) * branch_magnitude(np.abs(v), peak, FPB)


@dataclasses.dataclass(frozen=True)
class ThreeRegimeFriction:
    """Paper B's friction with its parameters (SI units).

    Parameters
    ----------
    start_static_force : float [N]
        ``F_0``, maximum static friction at the first start (piston at the cover).
    stick_static_force : float [N]
        ``F_s1``, maximum static friction after a stick during the stroke.
    coulomb_force : float [N]
        ``F_C`` (EHDL Coulomb level).
    viscous_coefficient : float [N s/m]
        ``C`` (paper B: 64 N s/m).
    critical_velocity : float [m/s]
        ``u_cr``, end of mixed lubrication (paper B: 0.06 m/s).
    return_peak_force : float [N]
        ``F_k``, v -> 0 limit of the decelerating (dynamic->static) branch.
    """

    start_static_force: float
    stick_static_force: float
    coulomb_force: float
    viscous_coefficient: float
    critical_velocity: float
    return_peak_force: float

    def __post_init__(self):
        for name in FPB_NAMES:
            val = getattr(self, name)
            if not np.isfinite(val) or val < 0:
                raise ParameterError(f"friction.{name} = {val} must be a finite number >= 0")
        if self.critical_velocity <= 0:
            raise ParameterError("friction.critical_velocity must be > 0 m/s")
        for name in ("start_static_force", "stick_static_force", "return_peak_force"):
            if getattr(self, name) < self.coulomb_force:
                raise ParameterError(f"friction.{name} = {getattr(self, name)} N is below "
                                     f"friction.coulomb_force = {self.coulomb_force} N")

    @property
    def FPB(self) -> np.ndarray:
        """Parameter vector ``[F_0, F_s1, F_C, C, u_cr, F_k]``."""
        return np.array([getattr(self, n) for n in FPB_NAMES], dtype=float)

    def accelerating(self, v, static=None):
        """Friction [N] on the static->dynamic branch after breakaway from ``static`` (default F_s1)."""
        peak = self.stick_static_force if static is None else static
        return sliding_friction(np.asarray(v, float), peak, self.FPB)

    def decelerating(self, v):
        """Friction [N] on the dynamic->static branch (peak F_k)."""
        return sliding_friction(np.asarray(v, float), self.return_peak_force, self.FPB)
