"""Linearisation of paper B's meter-out cylinder: omega_n, zeta* and D*.

Paper B's assumptions (section "Analysis of occurrence conditions"): the
charging-side pressure stays at P_s (the meter-out restriction dominates); the
discharge side is linearised about its equilibrium (u_0, P_be); temperature
effects on the mass flow are neglected.  Small deviations ``w = v - u_0``,
``p = P_b - P_be`` then obey (module :mod:`heavecomp.pneumatic.plant`)::

    M dw/dt = -A p - c w                      c = dF/dv at u_0 (decelerating branch; = C in EHDL)
    dp/dt   =  b w - a p                      b = kappa P_be A / V_b
                                              a = kappa/V_b (R T g - A u_0),  g = dG_b/dP_b

and the velocity obeys ``w'' + 2 zeta* omega_n w' + omega_n^2 w = 0`` with::

    omega_n^2 = (A b + a c) / M,   2 zeta* omega_n = a + c / M.

``convention="paper"`` neglects the volume change (``a = kappa R T g / V_b``) as
paper B does "since velocity is small"; ``"full"`` keeps the ``- A u_0`` term,
which is the exact Jacobian of the plant.  (For choked exhaust ``R T g = A u_0``
exactly, so in the full linearisation the valve adds no damping at all; with
paper-B-sized u_0/L the term is small either way.)

Breakaway from a stick with static friction F_s1 starts the linear model at
``w = -u_0`` and ``M dw/dt = F_s1 - F_lin(0)`` with ``F_lin(0) = F(u_0) - c u_0``
(= F_C in EHDL).  Scaled by ``u_0`` and ``omega_n``::

    y = w/u_0:  y'' + 2 zeta* y' + y = 0,  y(0) = -1,  y'(0) = D*,
    D* = (F_s1 - F_lin(0)) / (M u_0 omega_n)

``T_f = sqrt(M V_b / (P_be A^2))`` is the isothermal natural period / 2 pi
(paper B eq. 8); ``omega_n = sqrt(kappa) / T_f`` when ``a c`` is negligible.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from heavecomp.analysis.linear import LinearModel
from heavecomp.errors import InputError, ParameterError
from heavecomp.pneumatic.plant import (LAMINAR_RATIO, casadi_discharge_model, chamber_volumes, critical_ratio,
                                       equilibrium)
from heavecomp.plants.symbolic import casadi


#: named signals of :attr:`Linearisation.sys` (deviations from the equilibrium)
STATES = ("velocity", "pressure_b")
INPUTS = ("force",)
OUTPUTS = ("velocity", "pressure_b")


@dataclasses.dataclass(frozen=True)
class Linearisation(LinearModel):
    """Result of :func:`linearise` (SI units).

    ``sys`` is the linear model as a ``control.StateSpace``: states and outputs
    ``velocity`` w = v - u_0 [m/s] and ``pressure_b`` p = P_b - P_be [Pa], input
    ``force`` [N], an external force on the piston in the direction of motion::

        M dw/dt = -A p - c w + force,    dp/dt = b w - a p

    Its poles are the roots of ``s^2 + 2 zeta* omega_n s + omega_n^2``.
    """

    u0: float            #: equilibrium velocity [m/s]
    pb_eq: float         #: equilibrium discharge pressure [Pa abs]
    position: float      #: piston position of the linearisation [m]
    a: float             #: pressure relaxation rate [1/s]
    b: float             #: pressure per velocity gain [Pa/m]
    c: float             #: friction slope at u_0 [N s/m]
    g: float             #: dG_b/dP_b [kg/(s Pa)]
    omega_n: float       #: natural angular frequency [rad/s]
    zeta: float          #: damping factor zeta* [-]
    D: float             #: dimensionless friction drop D* [-]
    T_f: float           #: isothermal natural period / 2 pi [s]
    convention: str
    sys: object = dataclasses.field(repr=False, compare=False)  #: control.StateSpace (see above)

    @property
    def A(self) -> np.ndarray:
        """State matrix of (w, p) [1/s, m/(s^2 Pa); Pa/m, 1/s]."""
        return np.asarray(self.sys.A, dtype=float)

    def as_dict(self) -> dict:
        """The scalars (JSON-ready); the state-space model is left out."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name != "sys"}


def discharge_conductance(p, Pb: float) -> float:
    """g = dG_b/dP_b [kg/(s Pa)] of the exhaust orifice at P_b (closed form).

    Choked (P_a/P_b <= b): ``g = G/P_b``; unchoked:
    ``g = S K [psi(r) - r psi'(r)]`` with ``r = P_a/P_b``, ``K = sqrt(2 kappa/((kappa-1) R T))``.

    Parameters
    ----------
    p : PneumaticParams
        The cylinder (:class:`heavecomp.pneumatic.plant.PneumaticParams`).
    Pb : float [Pa]
        Absolute pressure of the discharge chamber (upstream of the exhaust).
    """
    k, R, T = p.kappa, p.gas_constant, p.temperature
    K = math.sqrt(2 * k / ((k - 1) * R * T))
    r = p.atmosphere / Pb
    bcr = critical_ratio(k)
    if r > LAMINAR_RATIO:
        raise ParameterError("pneumatic.supply_pressure: the equilibrium exhaust pressure ratio is above 0.995 "
                             "(supply too low to linearise the exhaust flow)")
    if r <= bcr:
        psi = math.sqrt(bcr ** (2 / k) - bcr ** ((k + 1) / k))
        return p.exhaust_area * K * psi
    psi = math.sqrt(r ** (2 / k) - r ** ((k + 1) / k))
    dpsi = ((2 / k) * r ** (2 / k - 1) - ((k + 1) / k) * r ** (1 / k)) / (2 * psi)
    return p.exhaust_area * K * (psi - r * dpsi)


def linearise(p, position: float | None = None, convention: str = "paper") -> Linearisation:
    """omega_n, zeta*, D* of the cylinder ``p`` (closed form, module docstring).

    Parameters
    ----------
    p : PneumaticParams
    position : float [m], optional
        Piston position (sets V_b); default a quarter of the stroke.
    convention : {"paper", "full"}
        Neglect (paper B) or keep the volume-change term in ``a``.

    Returns
    -------
    Linearisation
        The scalars of the module docstring and ``sys``, the model as a named
        ``control.StateSpace``.
    """
    import control as ct

    if convention not in ("paper", "full"):
        raise InputError(f"convention must be 'paper' or 'full', got {convention!r}")
    x = 0.25 * p.stroke if position is None else float(position)
    u0, Pb = equilibrium(p)
    A, M, k, R, T = p.area, p.mass, p.kappa, p.gas_constant, p.temperature
    _, Vb = chamber_volumes(x, p.plant_vector())
    ucr = p.critical_velocity
    c = p.viscous_coefficient - 2 * (p.return_peak_force - p.coulomb_force) * max(0.0, 1 - u0 / ucr) / ucr
    g = discharge_conductance(p, Pb)
    b = k * Pb * A / Vb
    a = k * R * T * g / Vb - (k * A * u0 / Vb if convention == "full" else 0.0)
    wn2 = (A * b + a * c) / M
    wn = math.sqrt(wn2)
    zeta = (a + c / M) / (2 * wn)
    F_eq = A * (p.supply_abs - Pb)
    D = (p.stick_static_force - (F_eq - c * u0)) / (M * u0 * wn)
    T_f = math.sqrt(M * Vb / (Pb * A * A))
    sys = ct.ss(np.array([[-c / M, -A / M], [b, -a]]), np.array([[1.0 / M], [0.0]]), np.eye(2), np.zeros((2, 1)),
                states=list(STATES), inputs=list(INPUTS), outputs=list(OUTPUTS), name=f"pneumatic_linear_{convention}")
    return Linearisation(*(float(v) for v in (u0, Pb, x, a, b, c, g, wn, zeta, D, T_f)), convention, sys)


def casadi_jacobian(p, position: float | None = None) -> np.ndarray:
    """Jacobian d[dv/dt, dP_b/dt]/d[v, P_b] at the equilibrium, by casadi from the
    plant's own scalar functions (no restated physics); equals
    ``linearise(p, position, "full").A``.

    Parameters
    ----------
    p : PneumaticParams
        The cylinder (:class:`heavecomp.pneumatic.plant.PneumaticParams`).
    position : float [m], optional
        Piston position (sets V_b); default a quarter of the stroke.
    """
    ca = casadi()
    x = 0.25 * p.stroke if position is None else float(position)
    f = casadi_discharge_model(p, x)
    s = ca.SX.sym("s", 2)
    J = ca.Function("J", [s], [ca.jacobian(f(s), s)])
    u0, Pb = equilibrium(p)
    return np.array(J([u0, Pb]))
