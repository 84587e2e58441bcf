"""The independent truth plant: the crown-block compensator of ``cmc-reference.md`` with the laws of
:mod:`heavecomp.independent.laws` at its seal, gas bank, line, string and formation, integrated
by scipy's LSODA (every law is smooth: LuGre friction needs no stick events).

State x = [s, v, y_b, v_b, z, age, w, theta, y_m, v_m]: stroke and its rate, the lower mass, the
seal's bristle deflection (LuGre) and age (dwell), the string's Bouc-Wen variable, the gas
temperature ratio T/T_0, and an optional mid-string mass (second mode). Positive is up,
displacements from the operating point.

Equations (cmc-reference.md, with the line's inertance moved to the left as an added mass):

    (M_c + I A^2) dv/dt = (p_gas + dp_line(Q)) A - F_f(v, p) - M_c g - T_top - M_c d2z_h/dt2,  Q = -A v
    p = p_gas + dp_line(Q) + I dQ/dt                     (the measured cylinder pressure)
    m_b dv_b/dt = T_bottom - m_b g + W,  W = max(0, W_0 - k_F(t) y_b - c_F v_b) while in contact
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
import math

import numpy as np

from heavecomp.independent.laws import (BoucWen, DwellStiction, Line, LuGre, ThermalGas, P_ATM,
                                        hardening, polytropic_p_abs)

G = 9.81  #: m/s^2, cmc-reference.md

#: pre-sliding length of the "exact stiction" seal [m]: 1 um. Against `heavecomp simulate` (exact stiction) under
#: the same heave file (Hs 2 m, Tp 11 s, 120 s) the WOB differs by 2.1 kN rms at 0.3 mm, 0.68 kN at 30 um,
#: 0.40 kN at 10 um and 0.12 kN at 1 um (0.3x the 400 N noise): the nominal plant is the contract's to
#: within the noise (tests/test_independent.py pins it).
NOMINAL_RELAXATION = 1e-6


class Heave:
    """Platform heave: a JONSWAP spectrum as a sum of sines with random phases, faded in over
    ``ramp`` s with r(t) = sin^2(pi/2 t/ramp) (cmc-reference.md), analytic rate and acceleration.

    JONSWAP: Hasselmann et al., Dtsch. Hydrogr. Z. A8(12), 1973; the normalisation of
    DNV-RP-C205 (2010) section 3.5.5: S(w) = A_g 5/16 Hs^2 wp^4 w^-5 exp(-5/4 (w/wp)^-4) gamma^r.

    Parameters
    ----------
    hs : float [m]
        Significant height of the platform heave.
    tp : float [s]
        Peak period.
    gamma : float [-]
        Peak enhancement.
    seed : int
        Phase seed.
    ramp : float or None [s]
        Fade-in (default 2 tp).
    n : int
        Number of sines.
    """

    def __init__(self, hs: float, tp: float, gamma: float = 3.3, seed: int = 0, ramp: float | None = None,
                 n: int = 160):
        rng = np.random.default_rng(seed)
        wp = 2.0 * math.pi / tp
        w = np.linspace(0.4 * wp, 3.5 * wp, n) + rng.uniform(-0.5, 0.5, n) * (3.1 * wp / n)
        dw = np.gradient(w)
        sig = np.where(w <= wp, 0.07, 0.09)
        ag = 1.0 - 0.287 * math.log(gamma)
        s = (ag * 5.0 / 16.0 * hs ** 2 * wp ** 4 * w ** -5.0 * np.exp(-1.25 * (w / wp) ** -4)
             * gamma ** np.exp(-0.5 * ((w - wp) / (sig * wp)) ** 2))
        self.amp = np.sqrt(2.0 * s * dw)
        self.w = w
        self.phase = rng.uniform(0.0, 2.0 * math.pi, n)
        self.ramp = 2.0 * tp if ramp is None else ramp
        self.hs, self.tp, self.gamma, self.seed = hs, tp, gamma, seed

    def tabulate(self, duration: float, rate: float = 200.0) -> "Heave":
        """Tabulate z_h and its derivatives on a ``rate`` Hz grid up to ``duration``; :meth:`at` then
        interpolates each by cubic Hermite from its value and slope (C1, so LSODA keeps its steps), 10x faster than the sum."""
        n = int(math.ceil(duration * rate)) + 2
        tt = np.arange(n) / rate
        arg = np.outer(tt, self.w) + self.phase
        sn, cs = np.sin(arg), np.cos(arg)
        am, w = self.amp, self.w
        d = [sn @ am, cs @ (am * w), -(sn @ (am * w ** 2)), -(cs @ (am * w ** 3)), sn @ (am * w ** 4)]
        r = np.zeros((4, n))
        r[0] = 1.0
        tr = self.ramp
        if tr > 0:
            on = tt < tr
            a, x = math.pi / tr, tt[on]
            r[:, on] = [np.sin(0.5 * a * x) ** 2, 0.5 * a * np.sin(a * x), 0.5 * a * a * np.cos(a * x),
                        -0.5 * a ** 3 * np.sin(a * x)]
        binom = ((1,), (1, 1), (1, 2, 1), (1, 3, 3, 1))
        zs = [sum(c * r[j] * d[k - j] for j, c in enumerate(binom[k])) for k in range(4)]
        self._tab = (rate, n, *[list(x) for x in zs])
        return self

    _tab = None

    def _r(self, t):
        tr = self.ramp
        if tr <= 0 or t >= tr:
            return 1.0, 0.0, 0.0
        a = math.pi / tr
        return math.sin(0.5 * a * t) ** 2, 0.5 * a * math.sin(a * t), 0.5 * a * a * math.cos(a * t)

    def at(self, t: float) -> tuple[float, float, float]:
        """(z_h, dz_h/dt, d2z_h/dt2) at t [m, m/s, m/s^2]."""
        if self._tab is not None:
            rate, n, z, zd, zdd, zddd = self._tab
            x = t * rate
            i = int(x)
            if 0 <= i < n - 1:  # cubic Hermite of each from its value and slope: C1 in t
                f = x - i
                h = 1.0 / rate
                f2, f3 = f * f, f * f * f
                h00, h10, h01, h11 = 2 * f3 - 3 * f2 + 1, (f3 - 2 * f2 + f) * h, -2 * f3 + 3 * f2, (f3 - f2) * h
                j = i + 1
                return (h00 * z[i] + h10 * zd[i] + h01 * z[j] + h11 * zd[j],
                        h00 * zd[i] + h10 * zdd[i] + h01 * zd[j] + h11 * zdd[j],
                        h00 * zdd[i] + h10 * zddd[i] + h01 * zdd[j] + h11 * zddd[j])
        arg = self.w * t + self.phase
        sn, cs = np.sin(arg), np.cos(arg)
        z = float(self.amp @ sn)
        zd = float((self.amp * self.w) @ cs)
        zdd = -float((self.amp * self.w * self.w) @ sn)
        r, rd, rdd = self._r(t)
        return r * z, rd * z + r * zd, rdd * z + 2.0 * rd * zd + r * zdd

    def series(self, t: np.ndarray) -> np.ndarray:
        z = np.array([self.at(float(x))[0] for x in t])
        return z


class SampledHeave(Heave):
    """Heave given as samples (a logged heave): a cubic spline through them, tabulated like
    :class:`Heave` (its third derivative is piecewise constant).

    Parameters
    ----------
    t : ndarray [s]
        Sample times.
    z : ndarray [m]
        Heave samples.
    """

    def __init__(self, t: np.ndarray, z: np.ndarray):
        from scipy.interpolate import CubicSpline

        self._spline = CubicSpline(t, z)
        self._t_end = float(t[-1])

    def tabulate(self, duration: float, rate: float = 200.0) -> "SampledHeave":
        n = int(math.ceil(duration * rate)) + 2
        tt = np.minimum(np.arange(n) / rate, self._t_end)
        self._tab = (rate, n, *[list(self._spline(tt, k)) for k in range(4)])
        return self

    def at(self, t: float) -> tuple[float, float, float]:
        if self._tab is None:
            self.tabulate(self._t_end)
        return super().at(t)


@dataclass(frozen=True)
class Plant:
    """The true plant's parameters and laws. ``from_params`` builds the nominal one (the parameter
    file's values, the seal as LuGre with a 1 um pre-sliding length); ``replace`` adds laws."""

    area: float
    moving_mass: float
    lower_mass: float
    k_ds: float
    c_ds: float
    k_f: float
    c_f: float
    wob_setpoint: float
    p0: float                 #: Pa gauge at the operating point (the charge)
    v0: float                 #: m^3 gas volume at the operating point
    polytropic_index: float
    seal: LuGre | None
    dwell: DwellStiction | None = None
    bouc_wen: BoucWen | None = None
    thermal: ThermalGas | None = None
    line: Line | None = None
    mid_fraction: float = 0.0  #: share of m_b lumped mid-string (0: one lower mass)
    #: (factor, t_start, duration) of a formation hardening
    hardening: tuple | None = None
    extra: dict = field(default_factory=dict, compare=False)

    @classmethod
    def from_params(cls, p) -> "Plant":
        """From a :class:`heavecomp.params.CMCParams` (the nominal parameter file)."""
        c, f, ds, fm = p.compensator, p.friction, p.drill_string, p.formation
        seal = None
        if f.model != "none":
            seal = LuGre(f.static_force, f.coulomb_force, f.stribeck_velocity, f.viscous_coefficient,
                         f.pressure_coefficient, NOMINAL_RELAXATION)
            seal = replace(seal, micro_damping=_critical_damping(seal, c.moving_mass, 0.7))
        return cls(area=p.area, moving_mass=c.moving_mass, lower_mass=ds.lower_mass, k_ds=ds.stiffness,
                   c_ds=ds.damping, k_f=fm.stiffness, c_f=fm.damping, wob_setpoint=p.operating_point.wob_setpoint,
                   p0=p.p0, v0=p.gas_volume, polytropic_index=c.polytropic_index, seal=seal)

    def with_(self, **kw) -> "Plant":
        return replace(self, **kw)

    @property
    def t0(self) -> float:
        """Static string tension at the top, T_0 = m_b g - W_0 [N]."""
        return self.lower_mass * G - self.wob_setpoint

    # ---- right-hand side ------------------------------------------------------------------
    def gas_pressure(self, s: float, theta: float) -> float:
        vg = self.v0 + self.area * s
        pa0 = self.p0 + P_ATM
        if self.thermal is not None:
            return self.thermal.p_abs(pa0, self.v0, vg, theta) - P_ATM
        return polytropic_p_abs(pa0, self.v0, vg, self.polytropic_index) - P_ATM

    def rhs(self, t: float, x, heave: Heave, out: dict | None = None):
        s, v, yb, vb, z, age, w, theta, ym, vm = x
        zh, zhd, zhdd = heave.at(t)
        a = self.area
        vg = self.v0 + a * s
        p_gas = self.gas_pressure(s, theta)
        q = -a * v
        dp = self.line.drop(q) if self.line is not None else 0.0
        inert = self.line.inertance if self.line is not None else 0.0
        p_res = p_gas + dp  # cylinder pressure without the inertance term (the seal sees it, close enough)

        gain = self.dwell.static_gain(age) if self.dwell is not None else 0.0
        if self.seal is not None:
            ff, zd = self.seal.force(z, v, p_res, gain)
        else:
            ff, zd = 0.0, 0.0
        aged = self.dwell.theta_dot(age, v) if self.dwell is not None else 0.0

        # string: top stretch x1 (to the mid mass, or to the lower mass)
        yc, vc = zh + s, zhd + v
        mid = self.mid_fraction > 0.0
        k_seg = 2.0 * self.k_ds if mid else self.k_ds
        c_seg = 2.0 * self.c_ds if mid else self.c_ds
        below_top = (ym, vm) if mid else (yb, vb)
        x1, x1d = yc - below_top[0], vc - below_top[1]
        if self.bouc_wen is not None:
            t_el = self.bouc_wen.force(x1, w)  # its stiffness is the segment's (the case maker sets it)
            wd = self.bouc_wen.w_dot(w, x1d)
        else:
            t_el, wd = k_seg * x1, 0.0
        t_top = self.t0 + t_el + c_seg * x1d
        m_low = self.lower_mass * (1.0 - self.mid_fraction)
        if mid:
            m_mid = self.lower_mass * self.mid_fraction
            t2_0 = m_low * G - self.wob_setpoint
            t_bot = t2_0 + k_seg * (ym - yb) + c_seg * (vm - vb)
            vmd = (t_top - t_bot - m_mid * G) / m_mid
        else:
            t_bot, vmd = t_top, 0.0

        kf = self.k_f if self.hardening is None else hardening(t, self.k_f, *self.hardening)
        pen = self.wob_setpoint - kf * yb
        wob = max(0.0, pen - self.c_f * vb) if pen > 0.0 else 0.0

        m_eff = self.moving_mass + inert * a * a
        vd = (p_res * a - ff - self.moving_mass * G - t_top - self.moving_mass * zhdd) / m_eff
        vbd = (t_bot - m_low * G + wob) / m_low
        thd = self.thermal.theta_dot(theta, vg, a * v) if self.thermal is not None else 0.0
        if out is not None:
            out.update(heave=zh, stroke=s, pressure=p_res + inert * (-a * vd), wob=wob, friction=ff,
                       stroke_velocity=v, p_gas=p_gas)
        return [v, vd, vb, vbd, zd, aged, wd, thd, vm, vmd]

    def initial_state(self) -> list:
        """At rest at the operating point: forces balanced with W = W_0 and zero friction."""
        return [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0]


def _critical_damping(seal: LuGre, mass: float, zeta: float) -> float:
    """sigma1 giving the bristle mode with the top mass a damping ratio zeta."""
    return 2.0 * zeta * math.sqrt(seal.sigma0 * mass)


def simulate(plant: Plant, heave: Heave, duration: float, rate: float = 50.0,
             rtol: float = 1e-8) -> dict:
    """Integrate ``plant`` under ``heave`` from rest at the operating point; outputs sampled at
    ``rate`` Hz: t, heave, stroke, pressure, wob (and friction, stroke_velocity, p_gas).

    Parameters
    ----------
    plant : Plant
        The true plant.
    heave : Heave
        Its input.
    duration : float [s]
        Length of the run.
    rate : float [Hz]
        Output sample rate.
    rtol : float [-]
        LSODA's relative tolerance.

    Returns
    -------
    dict
        Arrays by name [SI], and ``nfev``.
    """
    from scipy.integrate import solve_ivp

    t = np.arange(0.0, duration + 0.5 / rate, 1.0 / rate)
    atol = np.array([1e-7, 1e-7, 1e-8, 1e-8, 1e-9, 1e-4, 1e-8, 1e-8, 1e-8, 1e-8])
    if heave._tab is None or heave._tab[1] < duration * heave._tab[0] + 2:
        heave.tabulate(duration + 1.0)
    sol = solve_ivp(plant.rhs, (0.0, t[-1]), plant.initial_state(), method="LSODA", t_eval=t,
                    args=(heave,), rtol=rtol, atol=atol, max_step=0.05)
    if not sol.success:
        raise RuntimeError(f"independent plant: integration failed: {sol.message}")
    keys = ("heave", "stroke", "pressure", "wob", "friction", "stroke_velocity", "p_gas")
    out = {k: np.empty(t.size) for k in keys}
    d: dict = {}
    for i in range(t.size):
        plant.rhs(t[i], sol.y[:, i], heave, d)
        for k in keys:
            out[k][i] = d[k]
    out["t"] = t
    out["nfev"] = sol.nfev
    return out
