"""Main-cylinder friction laws of paper A (eqs. 1-7).

The laws are written **once**, as scalar functions built from ``np.*`` calls
only.  The same source is

- compiled by numba for the exact stick-slip time stepper
  (:mod:`heavecomp.simulate._kernel`),
- traced by casadi (``np.exp`` on an ``SX`` calls ``casadi.exp``) for
  linearisation, MPC and fitting (:func:`heavecomp.effects.model.casadi_model`),
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

import math

import numpy as np

from heavecomp.errors import ParameterError, did_you_mean

NONE, STRIBECK, EQ6, EQ7 = 0, 1, 2, 3
#: the friction models, written once: parameter-file name -> law code
CODES = {"none": NONE, "stribeck": STRIBECK, "rotating_eq6": EQ6, "rotating_eq7": EQ7}
#: FP layout: parameter-file names in vector order; the index constants below are generated from it
FP_NAMES = ("static_force", "coulomb_force", "stribeck_velocity", "viscous_coefficient",
            "pressure_coefficient", "tangential_velocity")
FS, FC, VS, CV, CP, VT = range(len(FP_NAMES))
#: the parameters that scale the friction force (a "friction x k" study scales exactly these)
FORCE_KEYS = ("static_force", "coulomb_force", "viscous_coefficient", "pressure_coefficient")


# ----------------------------------------------------------------------------
# scalar primitives (numba- and casadi-compatible: np.* only, no python branching
# on the state)
# ----------------------------------------------------------------------------
def stribeck_curve(speed, FS, FC, vS):
    """F_0 = F_C + (F_S - F_C) exp(-speed / v_S) — the Stribeck magnitude [N].

    ``speed`` is |v| for eq. 4 and the total sliding speed sqrt(v_a^2 + v_t^2)
    for eqs. 6-7 (paper A eq. 8).

    Parameters
    ----------
    speed : float or array [m/s]
        Sliding speed (>= 0).
    FS : float [N]
        Static (breakaway) force F_S.
    FC : float [N]
        Coulomb force F_C.
    vS : float [m/s]
        Stribeck velocity v_S (> 0).
    """
    return FC + stribeck_excess(speed, FS, FC, vS)


def stribeck_excess(speed, FS, FC, vS):
    """(F_S - F_C) exp(-speed / v_S) — the Stribeck curve's excess over Coulomb friction [N].

    Parameters
    ----------
    speed : float or array [m/s]
        Sliding speed (>= 0).
    FS : float [N]
        Static (breakaway) force F_S.
    FC : float [N]
        Coulomb force F_C.
    vS : float [m/s]
        Stribeck velocity v_S (> 0).
    """
    return (FS - FC) * np.exp(-speed / vS)


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
        return stribeck_curve(np.maximum(a, 0.0), FP[FS], FP[FC], FP[VS]) + FP[CP] * np.abs(p)
    if code == EQ6:
        return stribeck_curve(np.sqrt(a * a + FP[VT] * FP[VT]), FP[FS], FP[FC], FP[VS]) + FP[CP] * np.abs(p)
    if code == EQ7:
        return FP[CP] * np.abs(p)
    return 0.0 * a


def friction_cont(code, v, p, FP):
    """K: the part of the friction that is continuous through v = 0, K(0) = 0 [N].

    Parameters
    ----------
    code : int
        Law code (``NONE``, ``STRIBECK`` eq. 4, ``EQ6``, ``EQ7``; paper A).
    v : float or array [m/s]
        Axial piston velocity.
    p : float or array [Pa]
        Pressure drop across the seal (unused by K; kept for the common law signature).
    FP : (6,) array
        Friction parameters ``[F_S, F_C, v_S, C_v, C_p, v_t]`` [N, N, m/s, N s/m, N/Pa, m/s].

    Notes
    -----
    eqs. 4 and 6: K = C_v v;
    eq. 7: K = F_0(|v|) v_a / |v| + C_v v_a with |v| = sqrt(v_a^2 + v_t^2)
    (viscous-like around v_a = 0, slope F_0(v_t)/v_t + C_v).
    """
    if code == EQ7:
        speed = np.sqrt(v * v + FP[VT] * FP[VT])
        return stribeck_curve(speed, FP[FS], FP[FC], FP[VS]) * v / speed + FP[CV] * v
    if code == NONE:
        return 0.0 * v
    return FP[CV] * v


def friction_smooth(code, v, p, FP, eps):
    """Regularised friction: J(|v|, p) tanh(v / eps) + K(v, p) [N].

    ``eps`` [m/s] is the regularisation width (must be > 0).  As eps -> 0 it
    tends to the exact law for v != 0.

    Parameters
    ----------
    code : int
        Law code (``NONE``, ``STRIBECK`` eq. 4, ``EQ6``, ``EQ7``; paper A).
    v : float or array [m/s]
        Axial piston velocity.
    p : float or array [Pa]
        Pressure drop across the seal (cylinder gauge pressure).
    FP : (6,) array
        Friction parameters ``[F_S, F_C, v_S, C_v, C_p, v_t]`` [N, N, m/s, N s/m, N/Pa, m/s].
    eps : float [m/s]
        Regularisation width of ``tanh(v / eps)`` (> 0).
    """
    return friction_jump(code, np.abs(v), p, FP) * np.tanh(v / eps) + friction_cont(code, v, p, FP)


def friction_exact(code, v, p, FP):
    """Exact law for sliding, J(|v|) sign(v) + K(v) [N]; at v = 0 it returns 0
    (the friction is then set-valued, see :func:`friction_jump` for its limit).

    Parameters
    ----------
    code : int
        Law code (``NONE``, ``STRIBECK`` eq. 4, ``EQ6``, ``EQ7``; paper A).
    v : float or array [m/s]
        Axial piston velocity.
    p : float or array [Pa]
        Pressure drop across the seal (cylinder gauge pressure).
    FP : (6,) array
        Friction parameters ``[F_S, F_C, v_S, C_v, C_p, v_t]`` [N, N, m/s, N s/m, N/Pa, m/s].
    """
    return friction_jump(code, np.abs(v), p, FP) * np.sign(v) + friction_cont(code, v, p, FP)


def steepest_slope(code, FP) -> float:
    """Steepest slope |dF_f/dv| of the law near v = 0 [N s/m] (sets the stepper's default step).

    Parameters
    ----------
    code : int
        Law code (``NONE``, ``STRIBECK`` eq. 4, ``EQ6``, ``EQ7``; paper A).
    FP : (6,) array
        Friction parameters ``[F_S, F_C, v_S, C_v, C_p, v_t]`` [N, N, m/s, N s/m, N/Pa, m/s].

    Notes
    -----
    eqs. 4 and 6: max(C_v, (F_S - F_C)/v_S) (the Stribeck drop at 0+; for eq. 6 an upper bound);
    eq. 7: F_0(v_t)/v_t + C_v (the viscous-like slope of K at v_a = 0); ``none``: 0.
    ``tests/test_conformance.py`` pins it to the laws' numerical derivatives.
    """
    if code == NONE:
        return 0.0
    if code == EQ7:
        return max(FP[CV], (FP[FC] + (FP[FS] - FP[FC]) * math.exp(-FP[VT] / FP[VS])) / FP[VT] + FP[CV])
    return max(FP[CV], (FP[FS] - FP[FC]) / FP[VS])


def hydromechanical_friction(F_p, v, eta):
    """Paper A eqs. 1-3: friction from a constant hydromechanical efficiency [N].

    With the pressure force ``F_p`` driving the motion (``F_p v > 0``, positive
    load) the load is ``eta F_p`` and the friction ``(1 - eta) F_p``; with the
    load driving (negative load) ``F_L = F_p / eta`` and the friction magnitude
    ``(1/eta - 1) |F_p|``.  The friction opposes ``v``.  It vanishes with
    ``F_p``: the model cannot express static or Coulomb friction (paper A).

    Parameters
    ----------
    F_p : float or array [N]
        Pressure force on the piston.
    v : float or array [m/s]
        Piston velocity (the friction opposes it).
    eta : float
        Hydromechanical efficiency, 0 < eta <= 1 [-].
    """
    F_p = np.asarray(F_p, dtype=float)
    v = np.asarray(v, dtype=float)
    positive = F_p * v > 0
    mag = np.where(positive, (1.0 - eta) * np.abs(F_p), (1.0 / eta - 1.0) * np.abs(F_p))
    return mag * np.sign(v)


# ----------------------------------------------------------------------------
# parameters -> (code, FP), written once
# ----------------------------------------------------------------------------
#: the FP entries each friction model uses (the others must be absent, i.e. None, or are ignored)
MODEL_KEYS = {"none": (), "stribeck": FP_NAMES[:VT], "rotating_eq6": FP_NAMES, "rotating_eq7": FP_NAMES}


def law_vector(model, values):
    """``(code, FP)`` of a friction model from its named parameters [SI].

    Every key the model uses (:data:`MODEL_KEYS`) must be a number: a missing one raises
    :class:`heavecomp.errors.ParameterError` naming it (no silent default).  Keys the model does
    not use enter FP as 0 (their terms vanish; ``none`` computes no friction at all).  Rotating
    models with ``v_t = 0`` reduce to eq. 4 and get its code (eq. 7's v/|v| needs v_t > 0).

    Parameters
    ----------
    model : str
        Friction model: ``none``, ``stribeck`` (eq. 4), ``rotating_eq6`` or ``rotating_eq7``.
    values : mapping
        Parameter-file name -> value [SI] (:data:`FP_NAMES`; absent or ``None`` for unused keys).
    """

    used = MODEL_KEYS[model]
    FP = np.zeros(len(FP_NAMES))
    for i, key in enumerate(FP_NAMES):
        val = values.get(key)
        if val is None:
            if key in used:
                raise ParameterError(f"friction.{key}: missing required key for model = \"{model}\"")
            continue
        FP[i] = float(val)
    code = CODES[model]
    if code in (EQ6, EQ7) and FP[VT] == 0.0:
        code = STRIBECK
    return code, FP


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
        self.code, self.FP = law_vector(model, dict(zip(FP_NAMES, (
            static_force, coulomb_force, stribeck_velocity, viscous_coefficient, pressure_coefficient,
            tangential_velocity))))

    @classmethod
    def from_params(cls, friction) -> "FrictionLaw":
        """From a :class:`heavecomp.params.cmc.Friction` table."""
        law = object.__new__(cls)
        law.model = friction.model
        law.code, law.FP = law_vector(friction.model, {k: getattr(friction, k) for k in FP_NAMES})
        return law

    @property
    def has_stiction(self) -> bool:
        """True when the law has a set-valued part at v = 0 for some pressure."""
        if self.code == NONE:
            return False
        if self.code == EQ7:
            return self.FP[CP] > 0
        return self.FP[FS] > 0 or self.FP[CP] > 0

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
