"""Main-cylinder friction laws of paper A (eqs. 1-7).

The laws are written **once**, as scalar functions built from ``np.*`` calls
only.  The same source is

- compiled by numba for the exact stick-slip time stepper
  (:mod:`heavecomp.simulate._kernel`),
- traced by casadi (``np.exp`` on an ``SX`` calls ``casadi.exp``) for
  linearisation, MPC and fitting (:func:`heavecomp.plants.cmc.casadi_model`),
- vectorised over numpy arrays for plots and analysis.

Every law with stiction is split as ``F_f(v, p) = J(v, p) sign(v) + K(v, p)``:
``J`` is the part that jumps with the sign of the axial velocity (its value at
``v = 0`` is the static limit: while stuck the friction takes any value in
``[-J(0, p), +J(0, p)]``), ``K`` is continuous with ``K(0, p) = 0``.  The
smooth form for optimisation replaces ``sign(v)`` with ``tanh(v / eps)``; the
regularisation width ``eps`` [m/s] is always an explicit argument.

Friction parameter vector (``FP``, SI), shared by all laws::

    FP = [F_S, F_C, v_S, C_v, C_p, v_t]

Law codes: ``NONE = 0``, ``STRIBECK = 1`` (eq. 4), ``EQ6 = 2``, ``EQ7 = 3``.
"""

from __future__ import annotations

import numpy as np

from heavecomp.errors import did_you_mean, ParameterError

NONE, STRIBECK, EQ6, EQ7 = 0, 1, 2, 3
CODES = {"none": NONE, "stribeck": STRIBECK, "rotating_eq6": EQ6, "rotating_eq7": EQ7}
FP_NAMES = ("static_force", "coulomb_force", "stribeck_velocity", "viscous_coefficient",
            "pressure_coefficient", "tangential_velocity")


# ----------------------------------------------------------------------------
# scalar primitives (numba- and casadi-compatible: np.* only, no python branching
# on the state)
# ----------------------------------------------------------------------------
def stribeck_curve(speed, FS, FC, vS):
    """F_0 = F_C + (F_S - F_C) exp(-speed / v_S) — the Stribeck magnitude [N].

    ``speed`` is |v| for eq. 4 and the total sliding speed sqrt(v_a^2 + v_t^2)
    for eqs. 6-7 (paper A eq. 8).
    """
    return FC + (FS - FC) * np.exp(-speed / vS)


def friction_jump(code, a, p, FP):
    """J: the magnitude of the part of the friction that jumps with sign(v) [N].

    Parameters
    ----------
    code : int
        Law code (NONE, STRIBECK, EQ6, EQ7).
    a : float
        Velocity along the sliding direction, ``direction * v`` (= |v| while sliding;
        0 gives the static limit; < 0 only in the stepper's trial steps past a
        reversal, where the law is continued with its value at 0).
    p : float
        Pressure drop across the seal [Pa] (cylinder gauge pressure).
    FP : array
        Friction parameters ``[F_S, F_C, v_S, C_v, C_p, v_t]``.

    Notes
    -----
    eq. 4: J = F_C + (F_S - F_C) e^{-|v|/v_S} + C_p |p|;
    eq. 6: J = F_0(sqrt(v^2 + v_t^2)) + C_p |p|;
    eq. 7: J = C_p |p| (the Stribeck part is continuous through v = 0, see K).
    """
    if code == STRIBECK:
        # beyond v = 0 (a < 0, only in the stepper's trial steps) the magnitude is held at its
        # v = 0 value: the analytic continuation exp(-a/v_S) explodes within a few v_S
        return stribeck_curve(np.maximum(a, 0.0), FP[0], FP[1], FP[2]) + FP[4] * np.abs(p)
    if code == EQ6:
        return stribeck_curve(np.sqrt(a * a + FP[5] * FP[5]), FP[0], FP[1], FP[2]) + FP[4] * np.abs(p)
    if code == EQ7:
        return FP[4] * np.abs(p)
    return 0.0 * a


def friction_cont(code, v, p, FP):
    """K: the part of the friction that is continuous through v = 0, K(0) = 0 [N].

    Notes
    -----
    eqs. 4 and 6: K = C_v v;
    eq. 7: K = F_0(|v|) v_a / |v| + C_v v_a with |v| = sqrt(v_a^2 + v_t^2)
    (viscous-like around v_a = 0, slope F_0(v_t)/v_t + C_v).
    """
    if code == EQ7:
        speed = np.sqrt(v * v + FP[5] * FP[5])
        return stribeck_curve(speed, FP[0], FP[1], FP[2]) * v / speed + FP[3] * v
    if code == NONE:
        return 0.0 * v
    return FP[3] * v


def friction_smooth(code, v, p, FP, eps):
    """Regularised friction: J(|v|, p) tanh(v / eps) + K(v, p) [N].

    ``eps`` [m/s] is the regularisation width (must be > 0).  As eps -> 0 it
    tends to the exact law for v != 0.
    """
    return friction_jump(code, np.abs(v), p, FP) * np.tanh(v / eps) + friction_cont(code, v, p, FP)


def friction_exact(code, v, p, FP):
    """Exact law for sliding, J(|v|) sign(v) + K(v) [N]; at v = 0 it returns 0
    (the friction is then set-valued, see :func:`friction_jump` for its limit)."""
    return friction_jump(code, np.abs(v), p, FP) * np.sign(v) + friction_cont(code, v, p, FP)


def hydromechanical_friction(F_p, v, eta):
    """Paper A eqs. 1-3: friction from a constant hydromechanical efficiency [N].

    With the pressure force ``F_p`` driving the motion (``F_p v > 0``, positive
    load) the load is ``eta F_p`` and the friction ``(1 - eta) F_p``; with the
    load driving (negative load) ``F_L = F_p / eta`` and the friction magnitude
    ``(1/eta - 1) |F_p|``.  The friction opposes ``v``.  It vanishes with
    ``F_p``: the model cannot express static or Coulomb friction (paper A).
    """
    F_p = np.asarray(F_p, dtype=float)
    v = np.asarray(v, dtype=float)
    positive = F_p * v > 0
    mag = np.where(positive, (1.0 - eta) * np.abs(F_p), (1.0 / eta - 1.0) * np.abs(F_p))
    return mag * np.sign(v)


# ----------------------------------------------------------------------------
# law objects (vectorised numpy API)
# ----------------------------------------------------------------------------
class FrictionLaw:
    """A main-cylinder friction law with its parameters.

    Parameters
    ----------
    model : str
        ``none``, ``stribeck`` (eq. 4), ``rotating_eq6`` or ``rotating_eq7``.
    static_force, coulomb_force : float [N]
    stribeck_velocity : float [m/s]
    viscous_coefficient : float [N s/m]
    pressure_coefficient : float [N/Pa]
    tangential_velocity : float [m/s]
        Rotating models only; with v_t = 0 eqs. 6 and 7 reduce to eq. 4.

    Examples
    --------
    >>> law = FrictionLaw.from_params(paper_a().friction)          # doctest: +SKIP
    >>> law.force([0.1, -0.1], p=2.4e6)                            # doctest: +SKIP
    """

    def __init__(self, model="stribeck", static_force=0.0, coulomb_force=0.0, stribeck_velocity=1.0,
                 viscous_coefficient=0.0, pressure_coefficient=0.0, tangential_velocity=0.0):
        if model not in CODES:
            raise ParameterError(f"friction.model = {model!r} is not one of {', '.join(CODES)}"
                                 f"{did_you_mean(model, CODES)}")
        self.model = model
        vt = tangential_velocity or 0.0
        # eqs. 6 and 7 reduce to eq. 4 at v_t = 0 (and eq. 7's v/|v| needs v_t > 0)
        self.code = STRIBECK if (CODES[model] in (EQ6, EQ7) and vt == 0.0) else CODES[model]
        self.FP = np.array([static_force or 0.0, coulomb_force or 0.0, stribeck_velocity or 1.0,
                            viscous_coefficient or 0.0, pressure_coefficient or 0.0, vt], dtype=float)

    @classmethod
    def from_params(cls, friction) -> "FrictionLaw":
        """From a :class:`heavecomp.params.cmc.Friction` table."""
        return cls(friction.model, friction.static_force, friction.coulomb_force, friction.stribeck_velocity,
                   friction.viscous_coefficient, friction.pressure_coefficient, friction.tangential_velocity)

    @property
    def has_stiction(self) -> bool:
        """True when the law has a set-valued part at v = 0 for some pressure."""
        FS, FC, vS, Cv, Cp, vt = self.FP
        if self.code == NONE:
            return False
        if self.code == EQ7:
            return Cp > 0
        return FS > 0 or Cp > 0

    def force(self, v, p=0.0):
        """Exact friction for sliding velocity ``v`` [m/s] at pressure ``p`` [Pa]; 0 at v = 0."""
        v = np.asarray(v, dtype=float)
        return friction_exact(self.code, v, np.asarray(p, dtype=float), self.FP)

    def smooth(self, v, p=0.0, *, eps: float):
        """Regularised friction with explicit width ``eps`` [m/s]."""
        if not eps > 0:
            raise ValueError("eps (regularisation width, m/s) must be > 0")
        v = np.asarray(v, dtype=float)
        return friction_smooth(self.code, v, np.asarray(p, dtype=float), self.FP, eps)

    def static_limit(self, p=0.0):
        """Largest friction magnitude that can hold the piston at v = 0 [N]."""
        p = np.asarray(p, dtype=float)
        return friction_jump(self.code, 0.0 * p, p, self.FP)

    def __repr__(self):
        return f"FrictionLaw({self.model!r}, FP={self.FP.tolist()})"
