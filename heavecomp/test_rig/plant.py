"""Paper A's friction test rig with a rotating piston (Ottestad, Nilsen, Hansen 2012, section 3).

A differential cylinder (piston diameter d = 125 mm) whose piston can be turned
in a roller bearing; a pressure-compensated proportional valve group moves the
main cylinder kinematically (flow proportional to the command, no closed loop)
and two swing cylinders turn the piston.  With the load cylinders' service ports
open to tank there is no external load and the friction is read from the
chamber pressures (paper A eq. 12)::

    F_f ~ A_A p_A - A_B p_B

Model (our assumptions; paper A eqs. 10-11 and most of table 2 are illegible)
-----------------------------------------------------------------------------
* prescribed axial velocity ``v_a(t) = V sin(2 pi t / T_cycle)`` (V = 0.05 m/s,
  T_cycle = 20 s) — the pressure-compensated valve with stiff oil: the piston
  follows the command exactly (oil compressibility is neglected);
* rotation ``omega`` (0.77 rad/s, so ``v_t = omega d / 2 = 0.048 m/s``) is
  switched on while ``|v_a| < rotation_band`` (around zero axial velocity) or
  all the time (``rotation_band = inf``);
* friction: paper A eq. 4 with one parameter set per quadrant of
  (sign v, sign a) (table 2; only F_S = 580 N is legible, the rest is ours:
  accelerating quadrants have a Stribeck peak, decelerating ones are
  viscous-like); with rotation, eq. 7 with the same quadrant set and ``v_t``;
* chambers: the outflow side drains to tank through the valve's metering
  orifice, ``dp = rho/2 (Q / (C_d A_o))^2`` with ``Q`` = area x speed; the inflow
  side pressure follows from the force balance
  ``A_A p_A - A_B p_B = F_f + m a`` (quasi-static pressures).

Eq. 12 therefore reads ``F_f + m a``: its error is the piston inertia,
``|m a| <= m V 2 pi / T_cycle`` (= 0.47 N for m = 30 kg), plus sensor noise.

The friction functions are the foundation's (:mod:`heavecomp.friction.laws`),
evaluated on numpy arrays — no restatement.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from heavecomp.friction import laws

#: quadrant order: (sign v, sign a) = (+,+) accelerating forward, (+,-) decelerating forward,
#: (-,-) accelerating backward, (-,+) decelerating backward
QUADRANTS = ("v+a+", "v+a-", "v-a-", "v-a+")


@dataclasses.dataclass(frozen=True)
class QuadrantFriction:
    """Eq. 4 parameters for one quadrant [N, N, m/s, N s/m]."""

    static_force: float
    coulomb_force: float
    stribeck_velocity: float
    viscous_coefficient: float

    def FP(self, v_t: float = 0.0) -> np.ndarray:
        """Foundation friction vector [F_S, F_C, v_S, C_v, C_p = 0, v_t]."""
        return np.array([self.static_force, self.coulomb_force, self.stribeck_velocity,
                         self.viscous_coefficient, 0.0, v_t])


#: table 2 as we assume it (only F_S = 580 N is legible in the paper)
TABLE2 = {
    "v+a+": QuadrantFriction(580.0, 320.0, 0.004, 2500.0),
    "v+a-": QuadrantFriction(260.0, 260.0, 0.004, 4500.0),
    "v-a-": QuadrantFriction(540.0, 300.0, 0.005, 2300.0),
    "v-a+": QuadrantFriction(240.0, 240.0, 0.005, 4200.0),
}


@dataclasses.dataclass(frozen=True)
class RigParams:
    """Paper A's rig (SI).  Defaults: our reading of table 1 plus assumptions (module docstring)."""

    piston_diameter: float = 0.125   # m (paper A)
    rod_diameter: float = 0.09       # m (assumed)
    moving_mass: float = 30.0        # kg, piston + rod (assumed)
    velocity_amplitude: float = 0.05  # m/s (table 1, ~)
    cycle_period: float = 20.0       # s (table 1)
    omega: float = 0.77              # rad/s (table 1)
    rotation_band: float = 0.02      # m/s: rotation on while |v_a| below this
    oil_density: float = 870.0       # kg/m^3
    orifice_area: float = 2e-5       # m^2, C_d A_o of the metering edge to tank (assumed)
    quadrants: tuple = tuple(TABLE2[q] for q in QUADRANTS)

    @property
    def area_a(self) -> float:
        return math.pi * self.piston_diameter ** 2 / 4

    @property
    def area_b(self) -> float:
        return math.pi * (self.piston_diameter ** 2 - self.rod_diameter ** 2) / 4

    @property
    def tangential_velocity(self) -> float:
        """v_t = omega d / 2 [m/s] (paper A eq. 5)."""
        return self.omega * self.piston_diameter / 2


def kinematics(p: RigParams, t):
    """Prescribed axial velocity and acceleration [m/s, m/s^2] (our form of eqs. 10-11).

    Parameters
    ----------
    p : RigParams
        The rig (amplitude V [m/s] and cycle period [s]).
    t : float or array [s]
        Time.
    """
    w = 2 * math.pi / p.cycle_period
    t = np.asarray(t, float)
    return p.velocity_amplitude * np.sin(w * t), p.velocity_amplitude * w * np.cos(w * t)


def quadrant_index(v, a) -> np.ndarray:
    """0..3 in the order of :data:`QUADRANTS` (v = 0 counts with the sign of a).

    Parameters
    ----------
    v : float or array [m/s]
        Axial velocity.
    a : float or array [m/s^2]
        Axial acceleration.
    """
    v, a = np.asarray(v, float), np.asarray(a, float)
    sv = np.where(v != 0, np.sign(v), np.sign(a))
    fwd = sv > 0
    same = np.sign(a) == sv
    return np.where(fwd, np.where(same, 0, 1), np.where(same, 2, 3))


def rig_friction(p: RigParams, v, a, v_t):
    """Friction [N] at axial velocity v, acceleration a and tangential velocity v_t.

    eq. 4 with the quadrant's parameters when v_t = 0, eq. 7 (same parameters) when v_t > 0
    (:func:`heavecomp.friction.laws.friction_exact`).

    Parameters
    ----------
    p : RigParams
        The rig (its per-quadrant eq. 4 parameters).
    v : float or array [m/s]
        Axial velocity.
    a : float or array [m/s^2]
        Axial acceleration (selects the quadrant).
    v_t : float or array [m/s]
        Tangential velocity of the rotating piston, omega d / 2 (paper A eq. 5); 0 without rotation.
    """
    v, a, v_t = np.broadcast_arrays(np.asarray(v, float), np.asarray(a, float), np.asarray(v_t, float))
    q = quadrant_index(v, a)
    F = np.zeros(v.shape)
    for k, par in enumerate(p.quadrants):
        for rot in (False, True):
            m = (q == k) & ((v_t > 0) == rot)
            if not m.any():
                continue
            vt = v_t[m] if rot else 0.0
            if rot:
                FP = np.stack([par.FP(x) for x in vt])
                F[m] = [laws.friction_exact(laws.EQ7, vi, 0.0, fp) for vi, fp in zip(v[m], FP)]
            else:
                F[m] = laws.friction_exact(laws.STRIBECK, v[m], 0.0, par.FP())
    return F


def run(p: RigParams, *, rotation: bool, cycles: float = 1.0, fs: float = 100.0, pressure_noise: float = 0.0,
        seed: int = 0) -> dict:
    """One or more rig cycles: friction, chamber pressures and eq. 12's reading.

    Parameters
    ----------
    p : RigParams  the rig
    rotation : bool  turn the piston (within ``rotation_band``)
    cycles : float  number of velocity cycles
    fs : float [Hz]  sampling rate
    pressure_noise : float [Pa]  standard deviation added to each pressure sensor
    seed : int  seed of the pressure noise

    Returns
    -------
    dict of arrays: t, v, a, v_t, quadrant, friction (model), p_A, p_B [Pa gauge],
    friction_eq12 [N] and the scalar ``inertia_bound`` [N].
    """
    t = np.arange(0.0, cycles * p.cycle_period, 1.0 / fs)
    v, a = kinematics(p, t)
    vt = np.where(np.abs(v) < p.rotation_band, p.tangential_velocity, 0.0) if rotation else np.zeros_like(v)
    F = rig_friction(p, v, a, vt)
    AA, AB = p.area_a, p.area_b
    # outflow chamber drains to tank through the metering orifice (turbulent)
    q_out = np.where(v > 0, AB * v, -AA * v)
    dp = p.oil_density / 2 * (q_out / p.orifice_area) ** 2
    need = F + p.moving_mass * a  # = A_A p_A - A_B p_B
    pB = np.where(v > 0, dp, (AA * dp - need) / AB)
    pA = np.where(v > 0, (need + AB * dp) / AA, dp)
    if pressure_noise > 0:
        rng = np.random.default_rng(seed)
        pA = pA + rng.normal(0, pressure_noise, pA.size)
        pB = pB + rng.normal(0, pressure_noise, pB.size)
    return {"t": t, "v": v, "a": a, "v_t": vt, "quadrant": quadrant_index(v, a), "friction": F,
            "p_A": pA, "p_B": pB, "friction_eq12": AA * pA - AB * pB,
            "inertia_bound": p.moving_mass * p.velocity_amplitude * 2 * math.pi / p.cycle_period}


def fit_quadrants(v, F, quadrant, *, v_min: float = 1e-4) -> list[QuadrantFriction]:
    """Least-squares eq. 4 fit (C_p = 0) per quadrant to a measured friction-velocity loop.

    Bounded: F_C >= 0, F_S - F_C >= 0, C_v >= 0, 0.1 mm/s <= v_S <= 50 mm/s.

    Parameters
    ----------
    v : array [m/s]
        Axial velocity.
    F : array [N]
        Measured friction (e.g. paper A eq. 12's reading).
    quadrant : array of int
        Quadrant index of each sample (:func:`quadrant_index`).
    v_min : float [m/s]
        Samples slower than this are left out.
    """
    from scipy.optimize import least_squares

    out = []
    for k in range(4):
        m = (quadrant == k) & (np.abs(v) > v_min)
        s, f = np.abs(v[m]), np.abs(F[m])

        def res(th):
            FC, dF, lvS, Cv = th
            return FC + dF * np.exp(-s / np.exp(lvS)) + Cv * s - f

        x0 = [np.median(f), max(f.max() - np.median(f), 1.0), math.log(0.005), 1000.0]
        lb = [0.0, 0.0, math.log(1e-4), 0.0]
        ub = [np.inf, np.inf, math.log(0.05), np.inf]
        r = least_squares(res, x0, bounds=(lb, ub), x_scale=[100, 100, 1, 1000])
        FC, dF, lvS, Cv = r.x
        FS = FC + dF
        out.append(QuadrantFriction(float(FS), float(FC), float(math.exp(lvS)), float(Cv)))
    return out
