"""Truth laws from the literature, one class or function each, with its reference.

Written clean-room from ``cmc-reference.md``/``physics.md`` and the cited papers: nothing here is
taken from the diagnosis' candidate effects. Scalar laws take and return Python floats (the plant's
right-hand side calls them per step); signal laws (the sensors) take and return numpy arrays.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np

P_ATM = 101325.0  #: Pa, cmc-reference.md


# ---------------------------------------------------------------------------------------------
# friction
# ---------------------------------------------------------------------------------------------

def stribeck_level(v: float, p: float, f_s: float, f_c: float, v_s: float, c_p: float) -> float:
    """Paper A eq. 4's velocity-weakening level g(v, p) = F_C + (F_S - F_C) exp(-|v|/v_S) + C_p |p| [N].

    Ottestad, Nilsen & Hansen, ICCAS 2012, eq. 4 (the sign and the viscous part left out): the
    steady sliding friction is g(v, p) sign(v) + C_v v.

    Parameters
    ----------
    v : float [m/s]
        Sliding velocity.
    p : float [Pa]
        Pressure across the seal.
    f_s, f_c : float [N]
        Static and Coulomb levels.
    v_s : float [m/s]
        Stribeck velocity.
    c_p : float [N/Pa]
        Pressure coefficient.

    Returns
    -------
    float [N]
        g(v, p) > 0.
    """
    return f_c + (f_s - f_c) * math.exp(-abs(v) / v_s) + c_p * abs(p)


@dataclass(frozen=True)
class LuGre:
    """LuGre friction: a bristle state z with dz/dt = v - sigma0 |v| z / g(v, p),
    F = sigma0 z + sigma1(v) dz/dt + C_v v.

    Canudas de Wit, Olsson, Aström & Lischinsky, "A new model for control of systems with
    friction", IEEE TAC 40(3), 1995; the velocity-dependent micro-damping
    sigma1(v) = sigma1_0 exp(-(v/v_d)^2) that keeps the model passive at speed is from Olsson,
    Aström, Canudas de Wit, Gäfvert & Lischinsky, "Friction models and friction compensation",
    Eur. J. Control 4, 1998, section 4.

    g(v, p) is paper A eq. 4's Stribeck level (:func:`stribeck_level`), so the steady state
    (dz/dt = 0) is exactly eq. 4: F_ss = g(v, p) sign(v) + C_v v. The relaxation (pre-sliding)
    length is ``relaxation_length`` = F_S / sigma0 [m]: the displacement it takes to reach the
    static level from rest. With a length of a fraction of a millimetre it is the nominal eq. 4
    with stiction to well within the noise; with 3-6 cm it is friction with memory over sliding
    distance.
    """

    static_force: float
    coulomb_force: float
    stribeck_velocity: float
    viscous_coefficient: float
    pressure_coefficient: float
    relaxation_length: float
    #: sigma1_0 [N s/m]; the micro-damping's fade speed v_d is the Stribeck velocity
    micro_damping: float = 0.0

    @property
    def sigma0(self) -> float:
        return self.static_force / self.relaxation_length

    def level(self, v: float, p: float, static_gain: float = 0.0) -> float:
        """g(v, p) [N]; ``static_gain`` [N] is added to the static peak (dwell-time stiction)."""
        return stribeck_level(v, p, self.static_force + static_gain, self.coulomb_force,
                              self.stribeck_velocity, self.pressure_coefficient)

    def zdot(self, z: float, v: float, p: float, static_gain: float = 0.0) -> float:
        """dz/dt [m/s]."""
        return v - self.sigma0 * abs(v) * z / self.level(v, p, static_gain)

    def force(self, z: float, v: float, p: float, static_gain: float = 0.0) -> tuple[float, float]:
        """(F [N], dz/dt [m/s]) at bristle state z, velocity v, seal pressure p."""
        zd = self.zdot(z, v, p, static_gain)
        s1 = self.micro_damping * math.exp(-(v / self.stribeck_velocity) ** 2)
        return self.sigma0 * z + s1 * zd + self.viscous_coefficient * v, zd


@dataclass(frozen=True)
class DwellStiction:
    """Static friction that grows with the time at rest, with a rate-and-state 'age' theta.

    The age follows Dieterich's ageing law, dtheta/dt = 1 - |v| theta / D_c (Dieterich, "Modeling
    of rock friction 1", JGR 84, 1979; Ruina, JGR 88, 1983): at rest it counts time, sliding over
    D_c wipes it. The static peak gained after an age theta is Kato's law (Kato, Sato & Matsuyama,
    "Mechanism of the static friction...", ASLE Trans. 1972; the power law in time of Rabinowicz's
    dwell experiments, J. Appl. Phys. 1951):

        Delta F_S(theta) = gain * (1 - exp(-(theta / time_constant)^exponent)).
    """

    gain: float            #: N, static friction gained after a long dwell
    time_constant: float   #: s
    exponent: float = 1.0  #: -, Kato's m (0.5-1)
    slip_distance: float = 1e-3  #: m, D_c

    def theta_dot(self, theta: float, v: float) -> float:
        return 1.0 - abs(v) * theta / self.slip_distance

    def static_gain(self, theta: float) -> float:
        return self.gain * (1.0 - math.exp(-(max(theta, 0.0) / self.time_constant) ** self.exponent))


# ---------------------------------------------------------------------------------------------
# drill string
# ---------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class BoucWen:
    """Bouc-Wen hysteresis on the string's stretch x (Wen, "Method for random vibration of
    hysteretic systems", ASCE J. Eng. Mech. 102, 1976; Bouc 1967):

        T_h = k [alpha x + (1 - alpha) w],   dw/dt = xdot - beta |xdot| |w|^(n-1) w - gamma xdot |w|^n

    with A = 1, so at small amplitude w = x and the string has its nominal stiffness k; the
    hysteretic part saturates at the yield force F_y = (1 - alpha) k w_u, w_u = (beta + gamma)^(-1/n).
    beta = gamma (the usual symmetric choice) and beta + gamma > 0 make it dissipative
    (Ikhouane, Mañosa & Rodellar, J. Sound Vib. 2007).
    """

    stiffness: float      #: N/m, k (the nominal string stiffness)
    alpha: float          #: -, post-yield stiffness ratio
    yield_force: float    #: N, F_y
    exponent: float = 1.0  #: n

    @property
    def w_ultimate(self) -> float:
        return self.yield_force / ((1.0 - self.alpha) * self.stiffness)

    @property
    def beta(self) -> float:
        return 0.5 * self.w_ultimate ** (-self.exponent)

    gamma = beta

    def w_dot(self, w: float, xdot: float) -> float:
        n = self.exponent
        aw = abs(w)
        return xdot - self.beta * abs(xdot) * aw ** (n - 1.0) * w - self.gamma * xdot * aw ** n

    def force(self, x: float, w: float) -> float:
        """Elastic + hysteretic tension change [N] (T_0 left out)."""
        return self.stiffness * (self.alpha * x + (1.0 - self.alpha) * w)


# ---------------------------------------------------------------------------------------------
# gas spring
# ---------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class ThermalGas:
    """Ideal gas with heat exchange through the vessel wall, a thermal time constant tau.

    Otis & Pourmovahed, "An algorithm for computing nonflow gas processes in gas springs and
    hydropneumatic accumulators", ASME J. Dyn. Syst. Meas. Control 107, 1985 (the thermal time
    constant model; Pourmovahed & Otis, ibid. 112, 1990): with the wall at the charge temperature
    T_0 and theta = T/T_0,

        dtheta/dt = -(gamma - 1) theta (dV/dt) / V + (1 - theta) / tau,    p_abs = p_abs0 (V0/V) theta.

    tau -> 0 is isothermal (p V = const), tau -> infinity adiabatic (p V^gamma = const).
    """

    gamma: float   #: -, ratio of specific heats (N2: 1.4)
    tau: float     #: s

    def theta_dot(self, theta: float, v_gas: float, v_gas_dot: float) -> float:
        heat = (1.0 - theta) / self.tau if self.tau > 0.0 else 0.0
        return -(self.gamma - 1.0) * theta * v_gas_dot / v_gas + heat

    @staticmethod
    def p_abs(p_abs0: float, v0: float, v_gas: float, theta: float) -> float:
        return p_abs0 * v0 / v_gas * theta


def polytropic_p_abs(p_abs0: float, v0: float, v_gas: float, n: float) -> float:
    """cmc-reference.md: p + p_atm = (p_0 + p_atm) (V_0 / V)^n [Pa, absolute].

    Parameters
    ----------
    p_abs0 : float [Pa]
        Absolute pressure at V_0.
    v0 : float [m^3]
        Gas volume at the operating point.
    v_gas : float [m^3]
        Gas volume now.
    n : float [-]
        Polytropic index.

    Returns
    -------
    float [Pa]
        Absolute gas pressure.
    """
    return p_abs0 * (v0 / v_gas) ** n


# ---------------------------------------------------------------------------------------------
# line between cylinder and gas bank
# ---------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Line:
    """A lumped hydraulic line: inertance + laminar and turbulent resistance,
    p_cyl - p_gas = R_l Q + R_t Q |Q| + I dQ/dt.

    The lumped (first-mode) form of a distributed line: inertance I = rho L / A_p, turbulent loss
    from Darcy-Weisbach with a valve/fitting coefficient K, R_t = (f L / d + K) rho / (2 A_p^2)
    (Blackburn, Reethof & Shearer, "Fluid Power Control", MIT Press 1960, ch. 4; Merritt,
    "Hydraulic Control Systems", Wiley 1967, section 2.9); the laminar part from Hagen-Poiseuille,
    R_l = 128 mu L / (pi d^4). The friction factor uses Blasius, f = 0.316 Re^-0.25, taken at the
    reference flow (the law is then a fixed quadratic).
    """

    diameter: float        #: m, d
    length: float          #: m, L
    valve_k: float         #: -, K of valves and fittings
    density: float = 870.0     #: kg/m^3 (mineral oil)
    viscosity: float = 0.03    #: Pa s (mineral oil ~ 35 cSt)
    reference_flow: float = 0.1  #: m^3/s, where Blasius' f is taken

    @property
    def area(self) -> float:
        return math.pi * self.diameter ** 2 / 4.0

    @property
    def inertance(self) -> float:
        return self.density * self.length / self.area

    @property
    def r_laminar(self) -> float:
        return 128.0 * self.viscosity * self.length / (math.pi * self.diameter ** 4)

    @property
    def r_turbulent(self) -> float:
        u = self.reference_flow / self.area
        re = self.density * u * self.diameter / self.viscosity
        f = 0.316 * re ** -0.25
        return (f * self.length / self.diameter + self.valve_k) * self.density / (2.0 * self.area ** 2)

    def drop(self, q: float) -> float:
        """Resistive drop [Pa] at flow q [m^3/s] (the inertance term is the plant's)."""
        return self.r_laminar * q + self.r_turbulent * q * abs(q)


# ---------------------------------------------------------------------------------------------
# formation
# ---------------------------------------------------------------------------------------------

def hardening(t: float, k0: float, factor: float, t_start: float, duration: float) -> float:
    """Formation stiffness that moves from k0 to factor*k0 between t_start and t_start + duration,
    a smooth (cosine) step: the bit drills into a harder layer (Detournay & Defourny, "A phenomenological
    model for the drilling action of drag bits", Int. J. Rock Mech. 29, 1992: the contact response
    scales with the rock's strength).

    Parameters
    ----------
    t : float [s]
        Time.
    k0 : float [N/m]
        Stiffness before.
    factor : float [-]
        Stiffness after / before.
    t_start : float [s]
        Start of the change.
    duration : float [s]
        How long the change takes.

    Returns
    -------
    float [N/m]
        k_F(t).
    """
    if t <= t_start:
        return k0
    if t >= t_start + duration:
        return k0 * factor
    r = 0.5 - 0.5 * math.cos(math.pi * (t - t_start) / duration)
    return k0 * (1.0 + (factor - 1.0) * r)


# ---------------------------------------------------------------------------------------------
# sensors (arrays)
# ---------------------------------------------------------------------------------------------

def mru_highpass(t: np.ndarray, z: np.ndarray, corner_period: float, damping: float = 1 / math.sqrt(2)) -> np.ndarray:
    """A motion reference unit's heave: the double-integrated acceleration through a second-order
    high-pass, H(s) = s^2 / (s^2 + 2 zeta w_c s + w_c^2), w_c = 2 pi / corner_period.

    Kongsberg Seatex MRU and similar units output heave through such a filter (the heave filter's
    'period' setting, typically 50-200 s); Godhaven, "Adaptive tuning of heave filter in motion
    sensor", OCEANS 1998. Gain at the corner: 1 / (2 zeta) (0.707 for the Butterworth zeta).

    Parameters
    ----------
    t : ndarray [s]
        Sample times.
    z : ndarray [m]
        True heave.
    corner_period : float [s]
        2 pi / w_c.
    damping : float [-]
        zeta (default Butterworth).

    Returns
    -------
    ndarray [m]
        The heave the MRU reports.
    """
    from scipy import signal

    wc = 2.0 * math.pi / corner_period
    sys = signal.lti([1.0, 0.0, 0.0], [1.0, 2.0 * damping * wc, wc * wc])
    _, y, _ = signal.lsim(sys, z, t)
    return y


def quantise(y: np.ndarray, step: float) -> np.ndarray:
    """Mid-tread quantiser: round to the nearest multiple of ``step`` (error within +-step/2;
    Widrow & Kollár, "Quantization Noise", CUP 2008, ch. 4).

    Parameters
    ----------
    y : ndarray
        Signal.
    step : float
        Quantum, in y's unit.

    Returns
    -------
    ndarray
        Quantised signal.
    """
    return step * np.round(y / step)


def adc16(y: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """A 16-bit logger over [lo, hi]: 65535 steps, values outside clip.

    Parameters
    ----------
    y : ndarray
        Signal.
    lo, hi : float
        The logger's range, in y's unit.

    Returns
    -------
    ndarray
        The logged values.
    """
    step = (hi - lo) / 65535.0
    return lo + quantise(np.clip(y, lo, hi) - lo, step)


def mains_hum(t: np.ndarray, amplitude: float, frequency: float, phase: float) -> np.ndarray:
    """Mains pickup sampled at the logger's times: a sine at ``frequency`` (50 or 60 Hz, off by the
    grid's drift) evaluated at t, so that a logger without anti-alias filter aliases it to
    |f - k f_s| (IEC 61000-4-30 grid tolerance: +-1 %).

    Parameters
    ----------
    t : ndarray [s]
        Sample times.
    amplitude : float
        Hum amplitude, in the channel's unit.
    frequency : float [Hz]
        Mains frequency.
    phase : float [rad]
        Phase at t = 0.

    Returns
    -------
    ndarray
        The hum at t.
    """
    return amplitude * np.sin(2.0 * math.pi * frequency * t + phase)


def delayed(t: np.ndarray, y: np.ndarray, delay: float) -> np.ndarray:
    """The channel read ``delay`` s late: y(t - delay), cubic interpolation, the first values held.

    Parameters
    ----------
    t : ndarray [s]
        Sample times.
    y : ndarray
        Channel.
    delay : float [s]
        Lag (> 0: late).

    Returns
    -------
    ndarray
        y(t - delay).
    """
    from scipy.interpolate import CubicSpline

    return CubicSpline(t, y)(np.maximum(t - delay, t[0]))


def gain_offset(y: np.ndarray, gain: float = 1.0, offset: float = 0.0) -> np.ndarray:
    """A miscalibrated sensor: reading = gain * y + offset (a gauge read as absolute: offset p_atm).

    Parameters
    ----------
    y : ndarray
        True value.
    gain : float [-]
        Factor.
    offset : float
        Offset, in y's unit.

    Returns
    -------
    ndarray
        The reading.
    """
    return gain * y + offset
