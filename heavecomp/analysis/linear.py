"""Operating point and linearisation of the CMC -> ``control.StateSpace``.

The linear model is obtained from the same symbolic equations the rest of the
toolbox uses (:func:`heavecomp.effects.model.casadi_model`, casadi jacobians); no
equation is restated here.

The nonlinear model is driven by the heave *and its derivatives*,
``u = [z_h, dz_h, ddz_h, u_active]`` (the stroke is measured relative to the
moving platform).  Its jacobians give

    dx/dt = A x + B_0 z_h + B_1 dz_h + B_2 ddz_h + B_u u_active
    y     = C x + D_0 z_h + D_1 dz_h + D_2 ddz_h + D_u u_active

A proper LTI realisation with the heave ``z_h`` as the only disturbance input
follows from the state shift

    xi = x - N_1 dz_h - N_0 z_h,   N_1 = B_2,   N_0 = B_1 + A B_2

which removes the derivative inputs:

    dxi/dt = A xi + (B_0 + A N_0) z_h + B_u u_active
    y      = C xi + (D_0 + C N_0) z_h + D_u u_active      (needs C N_1 + D_1 = 0, D_2 = 0)

For the CMC, ``N_1 = [0, -1, 0, 0]`` and ``N_0 = [-1, f_v/M_c, 0, 0]`` with the
friction slope ``f_v = dF_f/dv``, so ``xi = [y_c, v_c - f_v z_h / M_c, y_b, v_b]``:
the absolute top-mass coordinates of ``cmc-reference.md`` (exactly, when the
friction slope is zero).  The outputs wob, stroke, pressure and tension are
proper; the friction force and the stroke velocity are not (they respond to
dz_h directly) and are therefore not outputs of the LTI model.

All signals of the returned system are deviations from the operating point
(:func:`operating_point`).
"""

from __future__ import annotations

import dataclasses
import logging
import math

import numpy as np

from heavecomp.errors import ParameterError
from heavecomp.friction.laws import FrictionLaw
from heavecomp.effects.model import casadi_model
from heavecomp.plants.symbolic import casadi
from heavecomp.effects.spec import effects_for
from heavecomp.effects.model import initial_effect_states

log = logging.getLogger(__name__)

FRICTION_MODES = ("none", "viscous", "sliding")
#: outputs of the casadi model, in order
RAW_OUTPUTS = ("wob", "stroke", "pressure", "tension", "friction")
RAW_INPUTS = ("heave", "heave_velocity", "heave_acceleration", "u_active")
RAW_STATES = ("stroke", "stroke_velocity", "lower_displacement", "lower_velocity")
#: outputs of the LTI model
OUTPUTS = ("wob", "stroke", "pressure", "tension")
INPUTS = ("heave", "u_active")


@dataclasses.dataclass(frozen=True)
class OperatingPoint:
    """Where the CMC is linearised.

    Attributes
    ----------
    x : ndarray (4,)
        State ``[s, v, y_b, v_b]`` [m, m/s, m, m/s].
    u : ndarray (4,)
        Input ``[z_h, dz_h, ddz_h, u_active]`` [m, m/s, m/s^2, N].
    y : ndarray (5,)
        Outputs ``[wob, stroke, pressure, tension, friction]`` [N, m, Pa, N, N].
    xdot : ndarray (4,)
        State derivative there; zero at an equilibrium.  While sliding at a
        constant velocity v0 the friction force F_f(v0) is not balanced
        (``xdot[1] = -F_f/M_c``): the jacobians describe the dynamics about the
        sliding motion, the constant force only shifts the mean.
    equilibrium : bool
        True when ``xdot`` is zero to rounding.
    """

    x: np.ndarray
    u: np.ndarray
    y: np.ndarray
    xdot: np.ndarray
    equilibrium: bool
    velocity: float = 0.0

    @property
    def wob(self) -> float:
        return float(self.y[0])

    @property
    def pressure(self) -> float:
        return float(self.y[2])

    @property
    def tension(self) -> float:
        return float(self.y[3])

    def as_dict(self) -> dict:
        """JSON-ready summary (SI units)."""
        d = {f"x_{n}": float(v) for n, v in zip(RAW_STATES, self.x)}
        d.update({f"u_{n}": float(v) for n, v in zip(RAW_INPUTS, self.u)})
        d.update({n: float(v) for n, v in zip(RAW_OUTPUTS, self.y)})
        d["equilibrium"] = bool(self.equilibrium)
        d["sliding_velocity"] = float(self.velocity)
        return d


class LinearModel:
    """A plant linearised about an operating point: the one linear-model abstraction.

    Every linearisation in the package (the CMC's :class:`Linearisation`, paper B's
    cylinder :class:`heavecomp.pneumatic.linear.Linearisation`) carries ``sys``, a
    ``control.StateSpace`` with named states, inputs and outputs (deviations from the
    operating point); the quantities every user derives from a linear model come from it
    here, once.
    """

    sys: object

    def poles(self) -> np.ndarray:
        """Eigenvalues of the state matrix [1/s], sorted by modulus (then imaginary part)."""
        ev = np.linalg.eigvals(np.asarray(self.sys.A, dtype=float))
        return ev[np.lexsort((ev.imag, np.abs(ev)))]

    def modes(self) -> list[tuple[float, float]]:
        """``(omega_n [rad/s], zeta [-])`` of each mode, slowest first; a complex pair counts
        once, a real pole is a mode with zeta = 1 (stable) or -1 (unstable)."""
        out = [(float(abs(p)), float(-p.real / abs(p)) if abs(p) > 0 else 1.0)
               for p in self.poles() if p.imag >= 0]
        return sorted(out)


@dataclasses.dataclass(frozen=True)
class Linearisation(LinearModel):
    """Full result of :func:`linearise_details`.

    Attributes
    ----------
    sys : control.StateSpace
        Proper LTI model, inputs ``heave`` [m], ``u_active`` [N]; outputs ``wob``
        [N], ``stroke`` [m], ``pressure`` [Pa], ``tension`` [N] (deviations).
    op : OperatingPoint
    A, B, C, D : ndarray
        Raw jacobians of the casadi model in ``x = [s, v, y_b, v_b]``,
        ``u = [z_h, dz_h, ddz_h, u_active]`` (outputs :data:`RAW_OUTPUTS`).
    N0, N1 : ndarray (4,)
        State shift ``xi = x - N1 dz_h - N0 z_h``.
    friction_slope : float
        dF_f/dv at the operating point [N s/m].
    params : CMCParams
        The parameter set actually linearised (friction replaced for ``none``/``viscous``).
    """

    sys: object
    op: OperatingPoint
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    N0: np.ndarray
    N1: np.ndarray
    friction_slope: float
    params: object

    def to_xi(self, x, zh, dzh):
        """Map raw states ``x`` (deviations) and heave to the LTI state ``xi``."""
        x = np.asarray(x, dtype=float)
        return x - np.multiply.outer(np.asarray(dzh, float), self.N1) - np.multiply.outer(np.asarray(zh, float), self.N0)


def _friction_params(params, friction: str):
    """Parameter set with the friction replaced as the linearisation mode asks."""
    if friction == "none":
        return params.replace(friction={"model": "none"})
    if friction == "viscous":
        cv = params.friction.viscous_coefficient
        if cv is None:
            raise ParameterError("friction.viscous_coefficient: needed for the viscous linearisation "
                                 f"(friction.model = \"{params.friction.model}\" has none)")
        # eq. 4 with F_S = F_C = C_p = 0 is the viscous law C_v v; v_S then multiplies nothing
        # (F_S - F_C = 0): the set's own, or 1 m/s when the set's model has none
        vs = params.friction.stribeck_velocity
        return params.replace(friction={"model": "stribeck", "static_force": 0.0, "coulomb_force": 0.0,
                                        "stribeck_velocity": 1.0 if vs is None else vs,
                                        "viscous_coefficient": cv, "pressure_coefficient": 0.0,
                                        "tangential_velocity": None})
    if friction == "sliding":
        if params.friction.model == "none":
            log.info("sliding linearisation of a frictionless set: same as friction='none'")
        return params
    raise ParameterError(f"friction = {friction!r}: must be one of {', '.join(FRICTION_MODES)}")


def _eval_model(params, x, u, eps, effects=()):
    """Values and jacobians of the casadi model (with ``effects`` at its hooks) at (x, u)."""

    ca = casadi()
    f = casadi_model(params, eps=eps, effects=effects)
    X = ca.SX.sym("X", f.size1_in(0))
    U = ca.SX.sym("U", 4)
    xdot, y = f(X, U)
    J = ca.Function("J", [X, U], [xdot, y, ca.jacobian(xdot, X), ca.jacobian(xdot, U),
                                  ca.jacobian(y, X), ca.jacobian(y, U)])
    return [np.array(v, dtype=float) for v in J(x, u)]


def _default_eps(params, velocity):
    law = FrictionLaw.from_params(params.friction)
    if not law.has_stiction:
        return None
    # tanh(v0/eps) has slope sech^2(25)/eps ~ 1e-21/eps at v0: the exact law's slope
    return abs(velocity) / 25.0


def operating_point(params, *, velocity: float | None = None, eps: float | None = None,
                    effects=()) -> OperatingPoint:
    """The CMC operating point (cmc-reference.md): s = 0, y_b = 0, at rest, WOB = W_0.

    Parameters
    ----------
    params : CMCParams
    velocity : float [m/s], optional
        Constant stroke (sliding) velocity v0.  The top mass is at rest and the
        platform moves with dz_h = -v0, so that the stroke velocity is v0.
    eps : float [m/s], optional
        Friction regularisation width (default |v0|/25 for laws with stiction).
    effects : sequence, optional
        Effects at the plant's hooks (:mod:`heavecomp.effects`); their states at rest follow x.

    Returns
    -------
    OperatingPoint
        ``y`` holds W_0, 0, p_0, T_0 = m_b g - W_0 and the friction force.
    """
    v0 = float(velocity or 0.0)
    if eps is None:
        eps = _default_eps(params, v0) if v0 != 0.0 else 1e-3

    x = np.r_[0.0, v0, 0.0, 0.0, initial_effect_states(params, effects)]
    u = np.array([0.0, -v0, 0.0, 0.0])
    xdot, y, *_ = _eval_model(params, x, u, eps, effects)
    xdot, y = xdot.ravel(), y.ravel()
    scale = params.k_eff * 1e-12 + 1e-9
    return OperatingPoint(x=x, u=u, y=y, xdot=xdot, equilibrium=bool(np.all(np.abs(xdot) < scale)), velocity=v0)


def linearise_details(params, *, friction: str = "none", velocity: float | None = None,
                      eps: float | None = None, effects=None) -> Linearisation:
    """Linearise the CMC; returns the LTI model with the raw jacobians and the state shift.

    See :func:`linearise` for the parameters.

    Parameters
    ----------
    params : CMCParams
        The parameter set (:class:`heavecomp.params.CMCParams`).
    friction : {"none", "viscous", "sliding"}
        Friction in the linear model (:func:`linearise`).
    velocity : float [m/s], optional
        Sliding velocity v0 (``friction="sliding"`` only; non-zero).
    eps : float [m/s], optional
        Regularisation width of sign(v) (default |v0|/25).
    effects : sequence, optional
        Effects at the plant's hooks (:mod:`heavecomp.effects`: instances, registered names or
        ``(name, values)``; None: the file's plant effects).  The seal-friction effects count only in
        the sliding linearisation, like the friction law.
    """
    import control as ct

    if friction not in FRICTION_MODES:
        raise ParameterError(f"friction = {friction!r}: must be one of {', '.join(FRICTION_MODES)}")
    pl = _friction_params(params, friction)
    v0 = 0.0
    if friction == "sliding":
        if velocity is None or not math.isfinite(velocity) or velocity == 0.0:
            raise ParameterError("velocity: the sliding linearisation needs a non-zero sliding velocity v0 [m/s]")
        v0 = float(velocity)
        if eps is None:
            eps = _default_eps(pl, v0)
    elif velocity not in (None, 0.0):
        raise ParameterError(f"velocity: only used with friction='sliding' (got friction={friction!r})")
    if eps is not None and not (eps > 0 and math.isfinite(eps)):
        raise ParameterError(f"eps = {eps!r}: the friction regularisation width must be > 0 m/s")


    effects = effects_for(params, effects)  # None: the file's [[effects]] (plant)
    if friction != "sliding":  # no seal friction in a frictionless or viscous linearisation: nor its effects'
        effects = [e for e in effects if e.hook != "seal_friction"]
    elif eps is None and any(e.adds_stiction for e in effects):
        eps = abs(v0) / 25.0  # as _default_eps: a seal effect with stiction needs a smooth sign
    op = operating_point(pl, velocity=v0, eps=eps, effects=effects)
    _, _, A, B, C, D = _eval_model(pl, op.x, op.u, eps, effects)
    B0, B1, B2, Bu = B[:, 0], B[:, 1], B[:, 2], B[:, 3]
    N1 = B2.copy()
    N0 = B1 + A @ B2
    Bz = B0 + A @ N0
    idx = [RAW_OUTPUTS.index(o) for o in OUTPUTS]
    Cz = C[idx]
    Dz = D[idx, 0] + Cz @ N0
    Du = D[idx, 3]
    # the derivative inputs must have disappeared from the chosen outputs
    improper = np.abs(Cz @ N1 + D[idx, 1]) + np.abs(D[idx, 2])
    ref = np.abs(Cz).sum(axis=1) + np.abs(D[idx]).sum(axis=1) + 1e-30
    outputs = list(OUTPUTS)
    if np.any(improper > 1e-9 * ref):
        bad = [OUTPUTS[i] for i in np.nonzero(improper > 1e-9 * ref)[0]]
        if not effects:
            raise RuntimeError(f"outputs {bad} depend on heave derivatives: no proper realisation")
        # an effect can make an output follow the heave velocity directly (a laminar line: the
        # pressure moves with R v = R (V - dz_h)): heave -> that output is improper; left out
        log.warning("linearise: outputs %s follow the heave's derivatives with %s (improper); left out",
                    ", ".join(bad), ", ".join(e.name for e in effects))
        keep = [i for i, o in enumerate(OUTPUTS) if o not in bad]
        outputs = [OUTPUTS[i] for i in keep]
        Cz, Dz, Du = Cz[keep], Dz[keep], Du[keep]
    MC = pl.compensator.moving_mass
    friction_slope = float(-A[1, 1] * MC - pl.drill_string.damping)
    states = ["top_displacement", "top_velocity" if abs(N0[1]) < 1e-15 else "top_velocity_shifted",
              "lower_displacement", "lower_velocity"]
    states += [f"{c.name}.{st}" for c in dict.fromkeys(type(e) for e in effects) for st in c.states]
    sys = ct.ss(A, np.column_stack([Bz, Bu]), Cz, np.column_stack([Dz, Du]),
                states=states, inputs=list(INPUTS), outputs=outputs,
                name=f"cmc_linear_{friction}")
    return Linearisation(sys=sys, op=op, A=A, B=B, C=C, D=D, N0=N0, N1=N1,
                         friction_slope=friction_slope, params=pl)


def linearise(params, *, friction: str = "none", velocity: float | None = None, eps: float | None = None,
              effects=None):
    """Linearised CMC as a ``control.StateSpace`` with named signals.

    Parameters
    ----------
    params : CMCParams
    friction : {"none", "viscous", "sliding"}
        ``none``: frictionless; ``viscous``: only the viscous term C_v v of the
        friction law (paper A eq. 4); ``sliding``: the set's own friction law,
        linearised about a constant sliding velocity ``velocity`` (slope dF_f/dv
        at v0 and the pressure term's dF_f/ds = C_p sign(v0) dp/ds).
    velocity : float [m/s], optional
        Sliding velocity v0 (``friction="sliding"`` only; non-zero).
    eps : float [m/s], optional
        Regularisation width of sign(v) (default |v0|/25, so that tanh(v0/eps) is
        the exact sign to 1e-21 and the slope is the exact law's).
    effects : sequence, optional
        Effects at the plant's hooks (:mod:`heavecomp.effects`: instances, registered names or
        ``(name, values)``), traced by casadi from the same source the stepper compiles; their
        states follow the four plant states.  None: the plant effects of ``params``' ``[[effects]]``.

    Returns
    -------
    control.StateSpace
        States ``top_displacement`` y_c = z_h + s [m], ``top_velocity`` [m/s]
        (``top_velocity_shifted`` = v_c - f_v z_h/M_c when the friction slope
        f_v != 0), ``lower_displacement`` y_b [m], ``lower_velocity`` [m/s];
        inputs ``heave`` z_h [m], ``u_active`` [N]; outputs ``wob`` [N],
        ``stroke`` [m], ``pressure`` [Pa], ``tension`` [N] — all deviations
        from :func:`operating_point`.

    Notes
    -----
    Frictionless and undamped it is the 2-DOF system ``M ddq + K q = [k_gas, 0] z_h``
    with ``M = diag(M_c, m_b)``, ``K = [[k_gas + k_ds, -k_ds], [-k_ds, k_ds + k_F]]``;
    its DC gain heave -> WOB is ``-k_eff`` of paper A eq. 14.
    """
    return linearise_details(params, friction=friction, velocity=velocity, eps=eps, effects=effects).sys


# ----------------------------------------------------------------------------
# batched restatement for sweeps (pinned to linearise_details by tests)
# ----------------------------------------------------------------------------
def proper_realisation(A, B, C, D):
    """Remove the heave derivatives from a (batched) jacobian model.

    Parameters
    ----------
    A : ndarray (..., n, n)
    B : ndarray (..., n, 4)
        Columns ``[z_h, dz_h, ddz_h, u_active]``.
    C : ndarray (..., p, n)
    D : ndarray (..., p, 4)

    Returns
    -------
    Ap, Bp, Cp, Dp : ndarray
        Realisation with inputs ``[z_h, u_active]`` (see the module notes:
        ``N_1 = B_2``, ``N_0 = B_1 + A B_2``, ``B_z = B_0 + A N_0``, ``D_z = D_0 + C N_0``).
    """
    A, B, C, D = (np.asarray(m, dtype=float) for m in (A, B, C, D))
    N0 = B[..., 1] + (A @ B[..., 2:3])[..., 0]
    Bz = B[..., 0] + (A @ N0[..., None])[..., 0]
    Dz = D[..., 0] + (C @ N0[..., None])[..., 0]
    return A, np.stack([Bz, B[..., 3]], axis=-1), C, np.stack([Dz, D[..., 3]], axis=-1)


def batch_matrices(*, gas_stiffness, moving_mass, lower_mass, string_stiffness, formation_stiffness,
                   area, string_damping=0.0, formation_damping=0.0, friction_slope=0.0,
                   friction_stiffness=0.0):
    """LTI matrices of the linearised CMC for many parameter sets at once.

    A vectorised restatement of the jacobians of :func:`heavecomp.effects.model.casadi_model`
    at the operating point (pinned to :func:`linearise_details` by
    ``tests/test_analysis_frequency.py``), for sweeps where a casadi call per
    variation would dominate.  All arguments broadcast against each other.

    Parameters
    ----------
    gas_stiffness : array_like [N/m]
        k_gas = n (p_0 + p_atm) A^2 / V_0.
    moving_mass, lower_mass : array_like [kg]
        M_c, m_b.
    string_stiffness, string_damping : array_like [N/m], [N s/m]
        k_ds, c_ds.
    formation_stiffness, formation_damping : array_like [N/m], [N s/m]
        k_F, c_F (contact closed).
    area : array_like [m^2]
        Plunger area A (pressure output p = -k_gas s / A).
    friction_slope : array_like [N s/m]
        dF_f/dv (C_v for the viscous model, an equivalent damping for a describing function).
    friction_stiffness : array_like [N/m]
        dF_f/ds (pressure term of eq. 4 while sliding).

    Returns
    -------
    A (..., 4, 4), B (..., 4, 2), C (..., 4, 4), D (..., 4, 2) : ndarray
        States as :func:`linearise`, inputs ``[heave, u_active]``, outputs
        ``[wob, stroke, pressure, tension]``.
    """
    kg, Mc, mb, kd, kF, Ar, cd, cF, fv, fs = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (
        gas_stiffness, moving_mass, lower_mass, string_stiffness, formation_stiffness, area, string_damping,
        formation_damping, friction_slope, friction_stiffness)))
    sh = kg.shape
    z = np.zeros(sh)
    one = np.ones(sh)
    # raw jacobians in x = [s, v, y_b, v_b], u = [z_h, dz_h, ddz_h, u_active]
    A = np.stack([
        np.stack([z, one, z, z], -1),
        np.stack([-(kg + kd + fs) / Mc, -(cd + fv) / Mc, kd / Mc, cd / Mc], -1),
        np.stack([z, z, z, one], -1),
        np.stack([kd / mb, cd / mb, -(kd + kF) / mb, -(cd + cF) / mb], -1),
    ], -2)
    B = np.stack([
        np.stack([z, z, z, z], -1),
        np.stack([-kd / Mc, -cd / Mc, -one, 1.0 / Mc], -1),
        np.stack([z, z, z, z], -1),
        np.stack([kd / mb, cd / mb, z, z], -1),
    ], -2)
    C = np.stack([
        np.stack([z, z, -kF, -cF], -1),
        np.stack([one, z, z, z], -1),
        np.stack([-kg / Ar, z, z, z], -1),
        np.stack([kd, cd, -kd, -cd], -1),
    ], -2)
    D = np.stack([
        np.stack([z, z, z, z], -1),
        np.stack([z, z, z, z], -1),
        np.stack([z, z, z, z], -1),
        np.stack([kd, cd, z, z], -1),
    ], -2)
    return proper_realisation(A, B, C, D)


def batch_matrices_from_params(params, *, friction_slope=0.0, friction_stiffness=0.0):
    """:func:`batch_matrices` for one :class:`CMCParams` (frictionless unless a slope is given).

    Parameters
    ----------
    params : CMCParams
        The parameter set (:class:`heavecomp.params.CMCParams`).
    friction_slope : float [N s/m]
        Friction slope dF_f/dv on the stroke (0: frictionless).
    friction_stiffness : float [N/m]
        Friction stiffness dF_f/ds on the stroke (e.g. the pressure term C_p sign(v0) dp/ds; 0: none).
    """
    c, ds, fo = params.compensator, params.drill_string, params.formation
    return batch_matrices(gas_stiffness=c.gas_stiffness, moving_mass=c.moving_mass, lower_mass=ds.lower_mass,
                          string_stiffness=ds.stiffness, string_damping=ds.damping,
                          formation_stiffness=fo.stiffness, formation_damping=fo.damping, area=params.area,
                          friction_slope=friction_slope, friction_stiffness=friction_stiffness)
