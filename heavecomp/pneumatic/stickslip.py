"""Stick-slip occurrence: paper B's critical curve, maps, minimum velocity (the CMC's stick map is
:mod:`heavecomp.analysis.stick_map`).

Critical curve (paper B eqs. 13-14, re-derived because the OCR lost them)
-------------------------------------------------------------------------
After breakaway the linearised velocity deviation ``y = (v - u_0)/u_0`` obeys
``y'' + 2 zeta y' + y = 0`` (time scaled by omega_n) with ``y(0) = -1`` (v = 0)
and ``y'(0) = D*`` (the static-minus-dynamic friction drop accelerates the
mass).  For zeta < 1::

    y(tau) = exp(-zeta tau) (-cos(w_d tau) + B sin(w_d tau)),  w_d = sqrt(1 - zeta^2),  B = (D* - zeta)/w_d

The first extremum is the velocity overshoot ``y_max`` at ``w_d tau_1 =
atan2(D*, -(w_d - zeta B))``; the next one is ``y_min = -y_max exp(-zeta pi / w_d)``.
The velocity returns to zero — the piston can stick again, stick-slip — when
``y_min <= -1``::

    y_max(zeta, D*) exp(-zeta pi / w_d) >= 1.

The critical curve ``D*_cr(zeta)`` is the root in D* of equality.  Limits:
``D*_cr(0) = 0`` (undamped: any friction drop leads to stick-slip) and
``D*_cr -> inf`` as zeta -> 1 (no overshoot without oscillation).  Stick-slip
lies above the curve.
"""

from __future__ import annotations

import logging
import math

import numpy as np

from heavecomp.pneumatic import linear as PL
from heavecomp.pneumatic import stepper as PS
from heavecomp.pneumatic.plant import equilibrium

log = logging.getLogger(__name__)


# ----------------------------------------------------------------------------------------------
# the critical curve
# ----------------------------------------------------------------------------------------------
def overshoot(zeta: float, D: float) -> tuple[float, float]:
    """(y_max, y_min) of the scaled linear velocity response after breakaway [-] (zeta < 1).

    Parameters
    ----------
    zeta : float
        Damping ratio zeta* of the linearised discharge side [-] (:mod:`heavecomp.pneumatic.linear`). Must be < 1.
    D : float
        Scaled friction drop D* = (F_s1 - F_lin(0)) / (M u_0 omega_n) [-].
    """
    if zeta >= 1.0:
        raise ValueError("overshoot() needs zeta < 1")
    wd = math.sqrt(1.0 - zeta * zeta)
    B = (D - zeta) / wd
    E = wd - zeta * B
    th = math.atan2(D, -E)
    tau1 = th / wd
    ymax = math.exp(-zeta * tau1) * (-math.cos(th) + B * math.sin(th))
    return ymax, -ymax * math.exp(-zeta * math.pi / wd)


def critical_D(zeta: float) -> float:
    """D*_cr(zeta): stick-slip for D* above it (inf for zeta >= 1, 0 for zeta <= 0).

    Parameters
    ----------
    zeta : float
        Damping ratio zeta* of the linearised discharge side [-] (:mod:`heavecomp.pneumatic.linear`).
    """
    from scipy.optimize import brentq

    if zeta <= 0.0:
        return 0.0
    if zeta >= 1.0:
        return math.inf

    def f(D):
        return -overshoot(zeta, D)[1] - 1.0

    hi = 1.0
    while f(hi) < 0:
        hi *= 2.0
        if hi > 1e12:
            return math.inf
    return brentq(f, 0.0, hi, xtol=1e-12, rtol=1e-12)


def critical_curve(zetas) -> np.ndarray:
    """D*_cr at each zeta (vectorised :func:`critical_D`).

    Parameters
    ----------
    zetas : float or array
        Damping ratios zeta* [-].
    """
    return np.array([critical_D(float(z)) for z in np.atleast_1d(zetas)])


def predicts_stick_slip(zeta: float, D: float) -> bool:
    """True above the critical curve.

    Parameters
    ----------
    zeta : float
        Damping ratio zeta* of the linearised discharge side [-] (:mod:`heavecomp.pneumatic.linear`).
    D : float
        Scaled friction drop D* = (F_s1 - F_lin(0)) / (M u_0 omega_n) [-].
    """
    return bool(D > critical_D(zeta))


# ----------------------------------------------------------------------------------------------
# nonlinear check of one cylinder
# ----------------------------------------------------------------------------------------------
def restart_state(p, position: float | None = None, margin: float = 1e-3) -> np.ndarray:
    """Stuck state just before a restart at ``position`` (default L/4): chamber a at
    P_s, drive force (1 - margin) F_s1 — the state the linear analysis starts from.

    Parameters
    ----------
    p : PneumaticParams
        The cylinder (:class:`heavecomp.pneumatic.plant.PneumaticParams`).
    position : float [m], optional
        Piston position of the restart; default a quarter of the stroke.
    margin : float
        Relative margin below the static limit: drive force (1 - margin) F_s1 [-].
    """
    x = 0.25 * p.stroke if position is None else float(position)
    Pb = p.supply_abs - (1.0 - margin) * p.stick_static_force / p.area
    return np.array([x, 0.0, p.supply_abs, Pb])


def window(lin, periods: float = 8.0) -> float:
    """Simulated time after a restart used to decide whether the piston sticks again [s].

    Parameters
    ----------
    lin : Linearisation
        The cylinder's linearisation (:func:`heavecomp.pneumatic.linear.linearise`), for omega_n.
    periods : float
        Length of the window after the restart, in natural periods 2 pi / omega_n [-]
        (0.05 s are added).
    """
    return periods * 2 * math.pi / lin.omega_n + 0.05


def nonlinear_sticks(p, position=None, periods: float = 8.0) -> bool:
    """Does the nonlinear plant stick again after a restart (exact stick-slip simulation)?

    Parameters
    ----------
    p : PneumaticParams
        The cylinder (:class:`heavecomp.pneumatic.plant.PneumaticParams`).
    position : float [m], optional
        Piston position of the linearisation and the restart (sets V_b); default L/4.
    periods : float
        Length of the window after the restart, in natural periods 2 pi / omega_n [-].
    """

    lin = PL.linearise(p, position)
    res = PS.simulate(p, window(lin, periods), state=restart_state(p, position), moved=True, stop_at_stick=True,
                      rate=100.0)
    return bool(res["stats"]["n_stick"] >= 1)


# ----------------------------------------------------------------------------------------------
# grid over two variables
# ----------------------------------------------------------------------------------------------
def grid_map(p, var_x: str, xs, var_y: str, ys, *, convention: str = "paper", position=None,
             periods: float = 8.0, parallel: bool = True, h: float | None = None) -> dict:
    """Classify a grid of cylinders by the critical curve and by nonlinear simulation.

    Parameters
    ----------
    p : PneumaticParams
        Base cylinder.
    var_x, var_y : str
        Field names of :class:`PneumaticParams` to vary, or ``"friction_drop"``
        (F_s1 - F_C with F_C fixed) [N].
    xs, ys : arrays
        Values (SI).
    convention : {"paper", "full"}
        Linearisation convention (see :mod:`heavecomp.pneumatic.linear`).
    position : float [m], optional
        Piston position of the linearisation and the restart; default a quarter of the stroke.
    periods : float
        Simulated window after the restart, in natural periods 2 pi / omega_n [-].
    parallel : bool
        Simulate the grid in parallel (:func:`heavecomp.pneumatic.stepper.run_many`).
    h : float [s], optional
        RK4 step shared by the grid (default: the smallest :func:`heavecomp.pneumatic.stepper.default_step`).

    Returns
    -------
    dict with arrays (len(ys), len(xs)): ``zeta``, ``D``, ``u0``, ``linear`` (bool),
    ``nonlinear`` (bool), ``agree`` and the scalar ``agreement`` (fraction alike).
    """

    xs, ys = np.asarray(xs, float), np.asarray(ys, float)
    ny, nx = ys.size, xs.size
    zeta = np.empty((ny, nx))
    D = np.empty((ny, nx))
    u0 = np.empty((ny, nx))
    lin_ss = np.zeros((ny, nx), bool)
    states, t_ends, PPs, FPBs, steps = [], [], [], [], []
    for i, yv in enumerate(ys):
        for j, xv in enumerate(xs):
            q = vary(p, {var_x: xv, var_y: yv})
            lin = PL.linearise(q, position, convention)
            zeta[i, j], D[i, j], u0[i, j] = lin.zeta, lin.D, lin.u0
            lin_ss[i, j] = predicts_stick_slip(lin.zeta, lin.D)
            states.append(restart_state(q, position))
            t_ends.append(window(lin, periods))
            PPs.append(q.plant_vector())
            FPBs.append(q.friction.FPB)
            steps.append(PS.default_step(q, states[-1][0]))
    hh = h or min(steps)
    args = (np.array(states), np.array(t_ends), hh, np.array(PPs), np.array(FPBs), 1, 1)
    if parallel:
        stats = PS.run_many(*args)
    else:
        stats = np.array([PS.run(s.copy(), te, hh, P, F, 1, 1, np.empty((1, PS.NCH)), 1 << 62)[1]
                          for s, te, P, F in zip(*[args[0], args[1], args[3], args[4]])])
    nl = (stats[:, PS.STATS.index("n_stick")] >= 1).reshape(ny, nx)
    agree = nl == lin_ss
    return {"var_x": var_x, "xs": xs, "var_y": var_y, "ys": ys, "zeta": zeta, "D": D, "u0": u0,
            "linear": lin_ss, "nonlinear": nl, "agree": agree, "agreement": float(agree.mean()),
            "convention": convention, "h": hh}


def vary(p, changes: dict):
    """``p`` with fields changed; ``friction_drop`` sets F_s1 = F_C + value (F_0 follows when lower).

    Parameters
    ----------
    p : PneumaticParams
        The cylinder (:class:`heavecomp.pneumatic.plant.PneumaticParams`).
    changes : dict
        Field name of :class:`PneumaticParams` (or ``friction_drop`` [N]) -> new value [SI].
    """
    ch = dict(changes)
    if "friction_drop" in ch:
        drop = ch.pop("friction_drop")
        ch["stick_static_force"] = p.coulomb_force + drop
        ch["start_static_force"] = max(p.start_static_force, p.coulomb_force + drop)
    return p.replace(**ch)


# ----------------------------------------------------------------------------------------------
# minimum equilibrium velocity
# ----------------------------------------------------------------------------------------------
def minimum_velocity(p, *, convention: str = "paper", position=None, nonlinear: bool = True,
                     area_range=(1e-9, 1e-5)) -> dict:
    """Smallest equilibrium velocity u_0 without stick-slip, varying the exhaust area S_e.

    The linear answer solves ``D*(S_e) = D*_cr(zeta*(S_e))`` (paper B Fig. 5); the
    nonlinear answer bisects S_e with the exact stick-slip simulation.
    Returns u0 [m/s] and S_e [m^2] for both.

    Parameters
    ----------
    p : PneumaticParams
        The cylinder (:class:`heavecomp.pneumatic.plant.PneumaticParams`).
    convention : {"paper", "full"}
        Linearisation convention: neglect (paper B) or keep the volume-change term (:mod:`heavecomp.pneumatic.linear`).
    position : float [m], optional
        Piston position of the linearisation and the restart (sets V_b); default L/4.
    nonlinear : bool
        Also bisect with the exact stick-slip simulation (slower).
    area_range : (float, float) [m^2]
        Bracket (low, high) of the exhaust area S_e searched.
    """
    from scipy.optimize import brentq


    def margin(logS):
        lin = PL.linearise(p.replace(exhaust_area=float(math.exp(logS))), position, convention)
        return lin.D - critical_D(lin.zeta)

    lo, hi = math.log(area_range[0]), math.log(area_range[1])
    out = {"convention": convention}
    if margin(lo) > 0 > margin(hi):
        S = math.exp(brentq(margin, lo, hi, xtol=1e-6))
        out["linear_u0"] = equilibrium(p.replace(exhaust_area=S))[0]
        out["linear_exhaust_area"] = S
    else:
        out["linear_u0"] = math.nan
        out["linear_exhaust_area"] = math.nan
    if nonlinear:
        a, b = lo, hi
        if nonlinear_sticks(p.replace(exhaust_area=math.exp(a)), position) and \
                not nonlinear_sticks(p.replace(exhaust_area=math.exp(b)), position):
            for _ in range(30):
                m = 0.5 * (a + b)
                if nonlinear_sticks(p.replace(exhaust_area=math.exp(m)), position):
                    a = m
                else:
                    b = m
            S = math.exp(b)
            out["nonlinear_u0"] = equilibrium(p.replace(exhaust_area=S))[0]
            out["nonlinear_exhaust_area"] = S
        else:
            out["nonlinear_u0"] = math.nan
            out["nonlinear_exhaust_area"] = math.nan
    return out


# ----------------------------------------------------------------------------------------------
# influence of variables (paper B Fig. 6)
# ----------------------------------------------------------------------------------------------
INFLUENCE_VARIABLES = ("friction_drop", "bore", "viscous_coefficient", "exhaust_area", "supply_pressure",
                       "mass", "stroke")


def influence(p, factors=(0.5, 0.71, 1.0, 1.41, 2.0), *, convention: str = "paper", position_fraction=0.25):
    """(zeta*, D*) as each variable of paper B Fig. 6 is scaled by lambda.

    The linearisation position scales with the stroke (``position_fraction * L``).
    Returns {variable: {"factor": [...], "zeta": [...], "D": [...], "stick_slip": [...]}}.

    Parameters
    ----------
    p : PneumaticParams
        The cylinder (:class:`heavecomp.pneumatic.plant.PneumaticParams`).
    factors : sequence of float
        Scale factors lambda applied to each variable [-].
    convention : {"paper", "full"}
        Linearisation convention: neglect (paper B) or keep the volume-change term (:mod:`heavecomp.pneumatic.linear`).
    position_fraction : float
        Linearisation position as a fraction of the stroke [-].
    """

    res = {}
    drop0 = p.stick_static_force - p.coulomb_force
    for var in INFLUENCE_VARIABLES:
        rows = {"factor": [], "zeta": [], "D": [], "stick_slip": []}
        for lam in factors:
            base = drop0 if var == "friction_drop" else getattr(p, var)
            q = vary(p, {var: base * lam})
            lin = PL.linearise(q, position_fraction * q.stroke, convention)
            rows["factor"].append(lam)
            rows["zeta"].append(lin.zeta)
            rows["D"].append(lin.D)
            rows["stick_slip"].append(bool(predicts_stick_slip(lin.zeta, lin.D)))
        res[var] = rows
    return res
