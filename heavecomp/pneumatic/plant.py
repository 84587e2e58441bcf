"""Paper B's pneumatic cylinder driven by a meter-out circuit (Fujita, Tokashiki, Kagawa 1999).

Set-up (paper B, Fig. 1): horizontal rodless cylinder, bore 32 mm, stroke 600 mm.
Chamber a (charging side) is fed from the supply ``P_s`` through a valve of
effective area ``S_s``; chamber b (discharge side) exhausts to atmosphere
through the speed-control valve of effective area ``S_e``.  A load mass ``M``
rides on the piston; the seal friction is paper B's three-regime law
(:mod:`heavecomp.pneumatic.friction`).

Equations (written once, scalar ``np.*``; numba and casadi use the same source)
---------------------------------------------------------------------------------
Mass flow through an orifice of effective area S (standard compressible flow,
ISO 6358 form with critical ratio ``b = (2/(kappa+1))^(kappa/(kappa-1))``)::

    G = S P_u sqrt(2 kappa / ((kappa-1) R T)) sqrt(r^(2/kappa) - r^((kappa+1)/kappa)),  r = P_d/P_u > b
    G = S P_u sqrt(2 kappa / ((kappa-1) R T)) sqrt(b^(2/kappa) - b^((kappa+1)/kappa)),  r <= b (choked)

For ``r > 0.995`` the flow is continued linearly to zero at r = 1 (the sqrt
law has an infinite slope there, which no explicit integrator can follow; the
change is < 1 % of the flow at that ratio).

Chambers, adiabatic (paper B: "state change of air is considered adiabatic"),
air flowing at the supply/ambient temperature ``T``::

    dP_a/dt = kappa / V_a (R T G_a - P_a A v),   V_a = V_a0 + A x
    dP_b/dt = kappa / V_b (-R T G_b + P_b A v),  V_b = V_b0 + A (L - x)

Motion (horizontal, same area both sides of a rodless piston)::

    M dv/dt = A (P_a - P_b) - F_f

Assumptions (paper B's table 1 is illegible; every number here is ours)
-----------------------------------------------------------------------
bore 32 mm and stroke 600 mm (paper B); supply 0.5 MPa gauge; dead volumes of
20 mm of bore each; air kappa = 1.4, R = 287 J/(kg K), T = 293.15 K; supply
valve S_s = 5 mm^2 (the charging side stays near P_s, as paper B assumes);
load M = 8 kg; friction F_0 = 28 N, F_s1 = 20 N, F_C = 8 N, C = 64 N s/m
(paper B), u_cr = 0.06 m/s (paper B), F_k = F_C.  M, F_0, F_s1 and F_C were
chosen (on a small grid) so that the default run reproduces Exp. 2
qualitatively: breakaway from the cover, one stick near 1.3 s, restart near
1.7 s, then steady motion near u_0 = 0.03 m/s.

Exhaust area: an equilibrium velocity u_0 ~ 0.03 m/s (paper B, Exp. 2) needs,
by the mass balance ``R T G_b = P_b A u_0``, an effective area of only
~0.12 mm^2 for this bore and supply (the flow is choked); "a few mm^2" would
give u_0 of several tenths of a m/s.  The default S_e = 0.12 mm^2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from heavecomp.errors import ParameterError, did_you_mean
from heavecomp.params.core import dump_toml, from_table, q, to_table
from heavecomp.plants.symbolic import casadi
from heavecomp.pneumatic.friction import ThreeRegimeFriction, branch_magnitude

#: layout of the plant parameter vector PP
PP_NAMES = ("area", "stroke", "dead_volume_a", "dead_volume_b", "supply_abs", "atmosphere", "temperature",
            "kappa", "gas_constant", "supply_area", "exhaust_area", "mass")
(I_A, I_L, I_VA0, I_VB0, I_PS, I_PA, I_T, I_KAPPA, I_R, I_SS, I_SE, I_M) = range(len(PP_NAMES))
LAMINAR_RATIO = 0.995


# ----------------------------------------------------------------------------------------------
# scalar physics (np.* only; no branching on the state)
# ----------------------------------------------------------------------------------------------
def critical_ratio(kappa):
    """Critical pressure ratio b = (2/(kappa+1))^(kappa/(kappa-1)) [-] (0.528 for air).

    Parameters
    ----------
    kappa : float
        Ratio of specific heats [-] (1.4 for air).
    """
    return (2.0 / (kappa + 1.0)) ** (kappa / (kappa - 1.0))


def flow_function(r, kappa):
    """psi(r) = sqrt(r^(2/kappa) - r^((kappa+1)/kappa)) for the pressure ratio r clipped
    to [b, 0.995] (choked below b) [-].

    Parameters
    ----------
    r : float
        Pressure ratio P_down / P_up [-].
    kappa : float
        Ratio of specific heats [-] (1.4 for air).
    """
    rr = np.minimum(np.maximum(r, critical_ratio(kappa)), LAMINAR_RATIO)
    return np.sqrt(np.maximum(rr ** (2.0 / kappa) - rr ** ((kappa + 1.0) / kappa), 0.0))


def orifice_flow(p_up, p_down, S, T, kappa, R):
    """Signed mass flow [kg/s] through an orifice of effective area ``S`` [m^2] from
    ``p_up`` to ``p_down`` [Pa abs] (negative when the flow goes the other way).

    Parameters
    ----------
    p_up : float [Pa]
        Upstream absolute pressure.
    p_down : float [Pa]
        Downstream absolute pressure.
    S : float [m^2]
        Effective area of the orifice.
    T : float [K]
        Temperature of the air upstream.
    kappa : float
        Ratio of specific heats [-] (1.4 for air).
    R : float [J/(kg K)]
        Gas constant of air.

    Notes
    -----
    Standard compressible orifice flow (choked and unchoked), see the module
    docstring; linear in (1 - r) for r > 0.995.
    """
    hi = np.maximum(p_up, p_down)
    lo = np.minimum(p_up, p_down)
    r = lo / hi
    lin = np.minimum(1.0, (1.0 - r) / (1.0 - LAMINAR_RATIO))
    return np.sign(p_up - p_down) * S * hi * np.sqrt(2.0 * kappa / ((kappa - 1.0) * R * T)) \
        * flow_function(r, kappa) * lin


def chamber_volumes(x, PP):
    """(V_a, V_b) [m^3] at piston position ``x`` [m] (0 = start cover).

    Parameters
    ----------
    x : float [m]
        Piston position (0 = start cover).
    PP : (12,) array
        Plant parameter vector [SI], layout :data:`PP_NAMES` (:meth:`PneumaticParams.plant_vector`).
    """
    return PP[I_VA0] + PP[I_A] * x, PP[I_VB0] + PP[I_A] * (PP[I_L] - x)


def pressure_rates(x, v, Pa, Pb, PP):
    """(dP_a/dt, dP_b/dt) [Pa/s]: adiabatic chambers, meter-out circuit.

    Parameters
    ----------
    x : float [m]
        Piston position (0 = start cover).
    v : float [m/s]
        Piston velocity.
    Pa : float [Pa]
        Absolute pressure P_a of the charging chamber a.
    Pb : float [Pa]
        Absolute pressure P_b of the discharge chamber b.
    PP : (12,) array
        Plant parameter vector [SI], layout :data:`PP_NAMES` (:meth:`PneumaticParams.plant_vector`).
    """
    Va, Vb = chamber_volumes(x, PP)
    k, R, T, A = PP[I_KAPPA], PP[I_R], PP[I_T], PP[I_A]
    Ga = orifice_flow(PP[I_PS], Pa, PP[I_SS], T, k, R)
    Gb = orifice_flow(Pb, PP[I_PA], PP[I_SE], T, k, R)
    return k / Va * (R * T * Ga - Pa * A * v), k / Vb * (-R * T * Gb + Pb * A * v)


def drive_force(Pa, Pb, PP):
    """Pressure force on the piston A (P_a - P_b) [N].

    Parameters
    ----------
    Pa : float [Pa]
        Absolute pressure P_a of the charging chamber a.
    Pb : float [Pa]
        Absolute pressure P_b of the discharge chamber b.
    PP : (12,) array
        Plant parameter vector [SI], layout :data:`PP_NAMES` (:meth:`PneumaticParams.plant_vector`).
    """
    return PP[I_A] * (Pa - Pb)


def piston_accel(Pa, Pb, Ff, PP):
    """dv/dt = (A (P_a - P_b) - F_f) / M [m/s^2].

    Parameters
    ----------
    Pa : float [Pa]
        Absolute pressure P_a of the charging chamber a.
    Pb : float [Pa]
        Absolute pressure P_b of the discharge chamber b.
    Ff : float [N]
        Signed friction force (opposing the motion).
    PP : (12,) array
        Plant parameter vector [SI], layout :data:`PP_NAMES` (:meth:`PneumaticParams.plant_vector`).
    """
    return (drive_force(Pa, Pb, PP) - Ff) / PP[I_M]


def discharge_rate(v, Pb, x, PP):
    """dP_b/dt [Pa/s] of the discharge chamber alone (used for the linearisation).

    Parameters
    ----------
    v : float [m/s]
        Piston velocity.
    Pb : float [Pa]
        Absolute pressure P_b of the discharge chamber b.
    x : float [m]
        Piston position (0 = start cover).
    PP : (12,) array
        Plant parameter vector [SI], layout :data:`PP_NAMES` (:meth:`PneumaticParams.plant_vector`).
    """
    Va, Vb = chamber_volumes(x, PP)
    k, R, T, A = PP[I_KAPPA], PP[I_R], PP[I_T], PP[I_A]
    Gb = orifice_flow(Pb, PP[I_PA], PP[I_SE], T, k, R)
    return k / Vb * (-R * T * Gb + Pb * A * v)


# ----------------------------------------------------------------------------------------------
# parameters
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True, kw_only=True)
class PneumaticParams:
    """Paper B's cylinder, circuit, load and friction (TOML table ``[pneumatic]``).

    Every default is our documented assumption (paper B's table 1 is illegible);
    see the module docstring.
    """

    bore: float = q(0.032, "m", bounds=(1e-3, 1.0), open_low=True, symbol="D", doc="cylinder bore (paper B)")
    stroke: float = q(0.6, "m", bounds=(1e-3, 10.0), open_low=True, symbol="L", doc="stroke (paper B)")
    dead_length: float = q(0.02, "m", bounds=(1e-4, 1.0), open_low=True,
                           doc="dead volume of each chamber as a length of bore")
    supply_pressure: float = q(0.5e6, "Pa", bounds=(1e3, 2e6), open_low=True, symbol="P_s",
                               doc="supply pressure, gauge")
    atmosphere: float = q(101325.0, "Pa", bounds=(5e4, 1.2e5), symbol="P_a", doc="ambient pressure, absolute")
    temperature: float = q(293.15, "K", bounds=(200.0, 400.0), symbol="T", doc="air temperature")
    kappa: float = q(1.4, "-", bounds=(1.0, 1.67), open_low=True, symbol="kappa", doc="ratio of specific heats")
    gas_constant: float = q(287.0, "J/(kg K)", bounds=(100.0, 1000.0), symbol="R")
    supply_area: float = q(5e-6, "m^2", bounds=(1e-9, 1e-3), open_low=True, symbol="S_s",
                           doc="effective area of the supply (charging) path")
    exhaust_area: float = q(0.12e-6, "m^2", bounds=(1e-10, 1e-3), open_low=True, symbol="S_e",
                            doc="effective area of the speed-control valve (meter-out)")
    mass: float = q(8.0, "kg", bounds=(0.0, 1e4), open_low=True, symbol="M", doc="load mass incl. piston")
    start_static_force: float = q(28.0, "N", bounds=(0.0, 1e5), symbol="F_0", doc="max static friction at the first start")
    stick_static_force: float = q(20.0, "N", bounds=(0.0, 1e5), symbol="F_s1", doc="max static friction after a stick")
    coulomb_force: float = q(8.0, "N", bounds=(0.0, 1e5), symbol="F_C", doc="Coulomb friction (EHDL)")
    viscous_coefficient: float = q(64.0, "N s/m", bounds=(0.0, 1e6), symbol="C", doc="viscous friction (paper B: 64)")
    critical_velocity: float = q(0.06, "m/s", bounds=(1e-5, 10.0), open_low=True, symbol="u_cr",
                                 doc="end of mixed lubrication (paper B: 0.06)")
    return_peak_force: float = q(8.0, "N", bounds=(0.0, 1e5), symbol="F_k",
                                 doc="v->0 limit of the decelerating branch (default = F_C)")

    def __post_init__(self):
        self.friction  # validates the friction ordering

    # -- derived -------------------------------------------------------------------------------
    @property
    def area(self) -> float:
        """Piston area A = pi D^2 / 4 [m^2]."""
        return math.pi * self.bore ** 2 / 4.0

    @property
    def supply_abs(self) -> float:
        """Absolute supply pressure [Pa]."""
        return self.supply_pressure + self.atmosphere

    @property
    def friction(self):
        return ThreeRegimeFriction(self.start_static_force, self.stick_static_force, self.coulomb_force,
                                   self.viscous_coefficient, self.critical_velocity, self.return_peak_force)

    def plant_vector(self) -> np.ndarray:
        """PP in the layout :data:`PP_NAMES`."""
        A = self.area
        vals = dict(area=A, stroke=self.stroke, dead_volume_a=A * self.dead_length, dead_volume_b=A * self.dead_length,
                    supply_abs=self.supply_abs, atmosphere=self.atmosphere, temperature=self.temperature,
                    kappa=self.kappa, gas_constant=self.gas_constant, supply_area=self.supply_area,
                    exhaust_area=self.exhaust_area, mass=self.mass)
        return np.array([vals[n] for n in PP_NAMES], dtype=float)

    def replace(self, **changes) -> "PneumaticParams":
        """A copy with some fields changed (validated like a file)."""
        table = to_table(self)
        table.update(changes)
        return from_dict({"pneumatic": table})

    def to_dict(self) -> dict:
        return {"pneumatic": to_table(self)}


def from_dict(d) -> PneumaticParams:
    """Build from ``{"pneumatic": {...}}`` strictly (unknown keys/out-of-range values raise ParameterError).

    Parameters
    ----------
    d : mapping
        Parsed TOML: ``{"pneumatic": {key: value}}`` with values in the units of :class:`PneumaticParams`.
    """
    d = dict(d or {})
    for key in d:
        if key != "pneumatic":
            raise ParameterError(f"{key}: unknown table{did_you_mean(key, ['pneumatic'])}; known tables: pneumatic")
    if "pneumatic" not in d:
        raise ParameterError("pneumatic: missing table [pneumatic]")
    return from_table(PneumaticParams, d["pneumatic"], "pneumatic", required=set())


def load(path) -> PneumaticParams:
    """Read a ``[pneumatic]`` TOML file (keys absent take the documented defaults).

    Parameters
    ----------
    path : str or Path
        The TOML parameter file.
    """
    import tomllib
    from pathlib import Path

    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise ParameterError(f"{path}: cannot read parameter file ({exc.strerror})") from None
    try:
        d = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"{path}: not valid TOML ({str(exc).splitlines()[0]})") from None
    return from_dict(d)


def dumps(p: PneumaticParams) -> str:
    """The TOML text of ``p`` (a ``[pneumatic]`` table with a header comment), as :func:`load` reads it.

    Parameters
    ----------
    p : PneumaticParams
        The cylinder (:class:`heavecomp.pneumatic.plant.PneumaticParams`).
    """
    return dump_toml(p.to_dict(), "paper B pneumatic meter-out cylinder (heavecomp stickslip)")


def default() -> PneumaticParams:
    """The documented default cylinder (module docstring)."""
    return PneumaticParams()


def equilibrium(p: PneumaticParams, x: float | None = None):
    """Steady sliding state of the meter-out circuit with the charging side at P_s.

    Solves ``A (P_s - P_b) = F(u_0)`` (decelerating friction branch) and
    ``R T G_b(P_b) = P_b A u_0`` (mass balance of chamber b) for (u_0 [m/s], P_be [Pa abs]).
    Raises ParameterError when the supply cannot overcome Coulomb friction.

    Parameters
    ----------
    p : PneumaticParams
        The cylinder (:class:`heavecomp.pneumatic.plant.PneumaticParams`).
    x : float [m], optional
        Piston position; unused: with the charging side held at P_s the equilibrium does not
        depend on it.
    """
    from scipy.optimize import brentq

    PP = p.plant_vector()
    FPB = p.friction.FPB
    A, Ps = p.area, p.supply_abs
    k, R, T = p.kappa, p.gas_constant, p.temperature

    def residual(u):
        Pb = Ps - branch_magnitude(u, p.return_peak_force, FPB) / A
        return R * T * orifice_flow(Pb, p.atmosphere, p.exhaust_area, T, k, R) - Pb * A * u

    if residual(1e-12) <= 0:
        raise ParameterError("pneumatic: supply_pressure cannot overcome coulomb_force (no steady motion)")
    hi = 1.0
    while residual(hi) > 0:
        hi *= 2
        if hi > 1e4:
            raise ParameterError("pneumatic: no equilibrium velocity below 1e4 m/s (check exhaust_area)")
    u0 = brentq(residual, 1e-12, hi, xtol=1e-14, rtol=1e-12)
    Pb = Ps - branch_magnitude(u0, p.return_peak_force, FPB) / A
    return u0, Pb


def casadi_discharge_model(p: PneumaticParams, x: float):
    """casadi Function f([v, P_b]) -> [dv/dt, dP_b/dt] with the charging side held at P_s
    (paper B's assumption) and the decelerating friction branch, at position ``x`` [m].
    Traced from the same scalar functions the stepper compiles.

    Parameters
    ----------
    p : PneumaticParams
        The cylinder (:class:`heavecomp.pneumatic.plant.PneumaticParams`).
    x : float [m]
        Piston position (sets the discharge volume V_b).
    """
    ca = casadi()
    s = ca.SX.sym("s", 2)
    PP = p.plant_vector()
    FPB = p.friction.FPB
    v, Pb = s[0], s[1]
    Ff = branch_magnitude(v, p.return_peak_force, FPB)  # v > 0 near the equilibrium
    dv = piston_accel(PP[I_PS], Pb, Ff, PP)
    dPb = discharge_rate(v, Pb, x, PP)
    return ca.Function("pneumatic_b", [s], [ca.vertcat(dv, dPb)])
