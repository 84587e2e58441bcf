"""The withheld-effect benchmark's truth laws: the generator's own effect classes.

They plug into the plant's hooks through the same mechanism as the library's effects
(:mod:`heavecomp.effects.base`), but they are **not** registered and share no equation with the
candidates the diagnosis fits (:mod:`heavecomp.effects`): a benchmark whose generator used the
candidates' equations would prove nothing.  ``tests/test_effects.py`` checks that each truth law
differs from its candidate.

============================  ===========================================  =============================================
effect                        truth law (here)                             candidate (fitted, heavecomp.effects)
============================  ===========================================  =============================================
friction_lag                  Stribeck curve evaluated at a first-order    asymmetric memory of the Stribeck *excess force*
                              lagged *speed* w, dw/dt = (|v| - w)/T_w
dwell_stiction                dF (1 - exp(-tau/tau_d)), tau = dwell time   power law a tau^beta
pressure_friction             k max(p - p_th, 0) (energised seal)           dC_p |p| (linear in pressure)
gas_heat_transfer             thermal state theta = T/T_0, adiabatic        effective polytropic index n_eff plus a
                              gamma, Newton heat exchange, tau_th           linear loss c_g v
flow_loss                     orifice, dp = K v|v| (turbulent)              laminar line, dp = R v
string_damping                quadratic drag c_q dv|dv| in the tension      linear dashpot c dv
============================  ===========================================  =============================================
"""

from __future__ import annotations

import inspect
from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import Effect
from heavecomp.effects.compose import composition
from heavecomp.friction.laws import FC, FS, STRIBECK, VS, stribeck_excess
from heavecomp.params.core import q
from heavecomp.plants.cmc import A, CDS, KDS, N, P0ABS, PATM, T0, V0


class TruthSpeedLag(Effect):
    """The Stribeck curve of paper A eq. 4 evaluated at a lagged speed w, dw/dt = (|v| - w)/T_w."""

    name = "friction_lag"
    hook = "seal_friction"
    states = ("w",)

    @dataclass(frozen=True)
    class Params:
        lag_time_speed: float = q(1.0, "s", bounds=(0.0, 100.0), open_low=True, symbol="T_w",
                                  doc="lag of the speed the Stribeck curve sees")

    @staticmethod
    def jump(code, a, p, J, s, d, x, FP, lag_time_speed):
        if code == STRIBECK:
            return J - stribeck_excess(np.maximum(a, 0.0), FP[FS], FP[FC], FP[VS]) + stribeck_excess(
                x[0], FP[FS], FP[FC], FP[VS])
        return J

    @staticmethod
    def rates(s, v, p, x, PP, FP, lag_time_speed):
        return ((np.abs(v) - x[0]) / lag_time_speed,)

    @staticmethod
    def initial(FP, PP, lag_time_speed):
        return (0.0,)

    @staticmethod
    def steady(v, FP, PP, lag_time_speed):
        return (abs(v),)


class TruthDwell(Effect):
    """Static friction grows with the dwell time tau and saturates: + dF (1 - exp(-tau/tau_d))."""

    name = "dwell_stiction"
    hook = "seal_friction"
    adds_stiction = True

    @dataclass(frozen=True)
    class Params:
        dF: float = q(1e4, "N", bounds=(0.0, 1e7), symbol="dF", doc="saturated static-friction gain")
        tau_d: float = q(1.0, "s", bounds=(0.0, 100.0), open_low=True, symbol="tau_d", doc="dwell time constant")

    @staticmethod
    def static(code, p, lim, tau, s, d, x, FP, dF, tau_d):
        return lim + dF * (1.0 - np.exp(-tau / tau_d))


class TruthEnergisedSeal(Effect):
    """An energised seal: extra friction k max(p - p_th, 0) above a threshold pressure."""

    name = "pressure_friction"
    hook = "seal_friction"
    adds_stiction = True

    @dataclass(frozen=True)
    class Params:
        k: float = q(0.03, "N/Pa", bounds=(0.0, 1.0), symbol="k", doc="friction per pascal above p_th")
        p_th: float = q(2e6, "Pa", bounds=(0.0, 1e8), symbol="p_th", doc="threshold pressure")

    @staticmethod
    def jump(code, a, p, J, s, d, x, FP, k, p_th):
        return J + k * np.maximum(p - p_th, 0.0)


class TruthThermalGas(Effect):
    """Ideal gas with a temperature state theta = T/T_0: adiabatic compression, Newton heat exchange.

    Notes
    -----
    p_abs = (p_0 + p_atm) theta V_0 / (V_0 + A s);
    dtheta/dt = -(gamma - 1) theta A v / (V_0 + A s) + (1 - theta) / tau_th.
    """

    name = "gas_heat_transfer"
    hook = "gas_spring"
    states = ("theta",)

    @dataclass(frozen=True)
    class Params:
        gamma: float = q(1.4, "-", bounds=(1.0, 1.67), symbol="gamma", doc="adiabatic index of the gas")
        tau_th: float = q(4.0, "s", bounds=(0.0, 1e3), open_low=True, symbol="tau_th", doc="heat exchange time")

    @staticmethod
    def gas(s, v, p, x, PP, gamma, tau_th):
        return PP[P0ABS] * x[0] * (PP[V0] / (PP[V0] + PP[A] * s)) - PP[PATM]

    @staticmethod
    def rates(s, v, p, x, PP, FP, gamma, tau_th):
        return (-(gamma - 1.0) * x[0] * PP[A] * v / (PP[V0] + PP[A] * s) + (1.0 - x[0]) / tau_th,)

    @staticmethod
    def initial(FP, PP, gamma, tau_th):
        return (1.0,)

    @staticmethod
    def steady(v, FP, PP, gamma, tau_th):
        return (1.0,)


class TruthOrifice(Effect):
    """Turbulent line loss: p_cyl = p_gas - K v|v|."""

    name = "flow_loss"
    hook = "line"

    @dataclass(frozen=True)
    class Params:
        K: float = q(3e5, "Pa s^2/m^2", bounds=(0.0, 1e9), symbol="K", doc="orifice coefficient")

    @staticmethod
    def line(v, p, x, PP, K):
        return p - K * v * np.abs(v)


class TruthQuadraticDrag(Effect):
    """Quadratic drag in the string: T_ds += c_q dv|dv|, dv = dz_h + v - v_b."""

    name = "string_damping"
    hook = "string"

    @dataclass(frozen=True)
    class Params:
        c_q: float = q(5e5, "N s^2/m^2", bounds=(0.0, 1e9), symbol="c_q", doc="quadratic drag coefficient")

    @staticmethod
    def string(dv, T, x, PP, c_q):
        return T + c_q * dv * np.abs(dv)


#: effect name -> truth class
TRUTH = {c.name: c for c in (TruthSpeedLag, TruthDwell, TruthEnergisedSeal, TruthThermalGas, TruthOrifice,
                              TruthQuadraticDrag)}


def truth_composition():
    """One compiled stepper for every truth law (switched on per run)."""
    return composition(tuple(TRUTH.values()))


# ---------------------------------------------------------------------------------------------
# Validation truth laws (issue 12 item 7): the schema-2 effects and effects outside every name.
# Their forms are chosen to differ from the library's candidates (heavecomp.effects); each names
# the model component it lives in (contract schema 2).  Plant laws act at the hooks through the
# compositions below (at most three extra states per composition); output laws post-process the
# clean channels (:data:`OUTPUT_TRUTH`).
#
# ==========================  =================  =====================================================
# truth label                 component          law (here)
# ==========================  =================  =====================================================
# asymmetric_friction         friction           J (1 + alpha d), d a lagged direction,
#                                                dd/dt = (v/(|v| + v_e) - d)/T_d (seal lip flips over)
# position_friction           friction           J (1 + beta max(0, 1 - ((s - s_c)/w)^2)), a parabolic
#                                                bump; s a state ds/dt = v
# gas_leak                    gas_spring         gas mass fraction mu, laminar leak dmu/dt = -mu p/(p_0 T_l),
#                                                p_gas + p_atm = (p + p_atm) mu^n
# sensor_gain                 sensors            y_m = g LP(y) (5 Hz first-order sensor bandwidth), g = -1
#                                                for a stroke transducer mounted the wrong way round
# sensor_offset               sensors            absolute pressure (+ local atmospheric), or a warm-up
#                                                zero drift b (1 - exp(-t/T_b))
# heave_reference             heave_input        lever arm x pitch: z_m = z + L sin(theta(t)) (theta a
#                                                synthetic pitch, logged as column ``pitch`` [rad]), or an
#                                                MRU with a gain error and a 2nd-order high-pass
# line_inertance (OOL)        flow_line          p_cyl = p_gas - I A (v - w)/T_i, dw/dt = (v - w)/T_i
# seal_warming (OOL)          friction           J (1 - beta theta), dtheta/dt = (|v|/v_ref - theta)/T_th
# stiffening_string (OOL)     string_formation   T += k_3 e^3, e = (T - T_0 - c dv)/k_ds the stretch
# wob_saturation (OOL)        sensors            WOB load cell clips at W_max
# stroke_backlash (OOL)       sensors            stroke read through a play of width b (backlash)
# ==========================  =================  =====================================================
# ---------------------------------------------------------------------------------------------


SEAL_SD = "d" in inspect.signature(TruthEnergisedSeal.jump).parameters  #: the hook passes (s, d)


class TruthLaggedDirection(Effect):
    """Direction-asymmetric seal friction: J (1 + alpha d) with d a lagged direction of motion."""

    name = "asymmetric_friction"
    hook = "seal_friction"
    states = ("d",)

    @dataclass(frozen=True)
    class Params:
        alpha: float = q(0.2, "-", bounds=(-0.9, 0.9), symbol="alpha", doc="friction asymmetry (extending +)")
        t_flip: float = q(0.1, "s", bounds=(0.0, 10.0), open_low=True, symbol="T_d", doc="seal lip flip time")
        v_e: float = q(2e-3, "m/s", bounds=(0.0, 1.0), open_low=True, symbol="v_e", doc="direction smoothing speed")

    if SEAL_SD:
        @staticmethod
        def jump(code, a, p, J, s, d, x, FP, alpha, t_flip, v_e):
            return J * (1.0 + alpha * x[0])
    else:
        @staticmethod
        def jump(code, a, p, J, x, FP, alpha, t_flip, v_e):
            return J * (1.0 + alpha * x[0])

    @staticmethod
    def rates(s, v, p, x, PP, FP, alpha, t_flip, v_e):
        return ((v / (np.abs(v) + v_e) - x[0]) / t_flip,)

    @staticmethod
    def initial(FP, PP, alpha, t_flip, v_e):
        return (0.0,)

    @staticmethod
    def steady(v, FP, PP, alpha, t_flip, v_e):
        return (v / (abs(v) + v_e),)


class TruthWornBand(Effect):
    """Friction raised by up to beta inside a worn band of the stroke, a parabolic bump
    J (1 + beta max(0, 1 - ((s - s_c)/w)^2)), with the stroke s tracked as a state (ds/dt = v)."""

    name = "position_friction"
    hook = "seal_friction"
    states = ("s",)

    @dataclass(frozen=True)
    class Params:
        beta: float = q(0.3, "-", bounds=(-0.9, 5.0), symbol="beta", doc="relative friction change at the centre")
        s_c: float = q(0.0, "m", bounds=(-5.0, 5.0), symbol="s_c", doc="centre of the band")
        w: float = q(0.2, "m", bounds=(0.0, 5.0), open_low=True, symbol="w", doc="half width of the band")

    if SEAL_SD:
        @staticmethod
        def jump(code, a, p, J, s, d, x, FP, beta, s_c, w):
            return J * (1.0 + beta * np.maximum(1.0 - ((x[0] - s_c) / w) ** 2, 0.0))
    else:
        @staticmethod
        def jump(code, a, p, J, x, FP, beta, s_c, w):
            return J * (1.0 + beta * np.maximum(1.0 - ((x[0] - s_c) / w) ** 2, 0.0))

    @staticmethod
    def rates(s, v, p, x, PP, FP, beta, s_c, w):
        return (v,)

    @staticmethod
    def initial(FP, PP, beta, s_c, w):
        return (0.0,)  # the run starts at rest at the operating point, s = 0

    @staticmethod
    def steady(v, FP, PP, beta, s_c, w):
        return (0.0,)


class TruthLaminarLeak(Effect):
    """Gas charge leaking through a laminar path: mass fraction mu, dmu/dt = -mu p / (p_0 T_l)."""

    name = "gas_leak"
    hook = "gas_spring"
    states = ("mu",)

    @dataclass(frozen=True)
    class Params:
        leak_rate: float = q(2.5e-5, "1/s", bounds=(0.0, 1.0), symbol="1/T_l", doc="leak rate at the charge pressure")

    @staticmethod
    def gas(s, v, p, x, PP, leak_rate):
        return (p + PP[PATM]) * x[0] ** PP[N] - PP[PATM]

    @staticmethod
    def rates(s, v, p, x, PP, FP, leak_rate):
        return (-x[0] * leak_rate * p / (PP[P0ABS] - PP[PATM]),)

    @staticmethod
    def initial(FP, PP, leak_rate):
        return (1.0,)

    @staticmethod
    def steady(v, FP, PP, leak_rate):
        return (1.0,)


class TruthLineInertance(Effect):
    """Out of every name: the oil column's inertance, p_cyl = p_gas - I A dv/dt, with dv/dt taken
    from a fast first-order follower w of the piston speed (dw/dt = (v - w)/T_i)."""

    name = "line_inertance"
    hook = "line"
    states = ("w",)

    @dataclass(frozen=True)
    class Params:
        inertance: float = q(2e5, "Pa s^2/m^3", bounds=(0.0, 1e9), symbol="I", doc="line inertance (per flow)")
        t_i: float = q(0.05, "s", bounds=(0.0, 1.0), open_low=True, symbol="T_i", doc="follower time constant")

    @staticmethod
    def line(v, p, x, PP, inertance, t_i):
        return p - inertance * PP[A] * (v - x[0]) / t_i

    @staticmethod
    def rates(s, v, p, x, PP, FP, inertance, t_i):
        return ((v - x[0]) / t_i,)

    @staticmethod
    def initial(FP, PP, inertance, t_i):
        return (0.0,)

    @staticmethod
    def steady(v, FP, PP, inertance, t_i):
        return (v,)


class TruthSealWarming(Effect):
    """Out of every name: the seal warms with cycling and its friction drops, J (1 - beta theta),
    dtheta/dt = (|v|/v_ref - theta)/T_th."""

    name = "seal_warming"
    hook = "seal_friction"
    states = ("theta",)

    @dataclass(frozen=True)
    class Params:
        beta: float = q(0.2, "-", bounds=(0.0, 0.9), symbol="beta", doc="friction drop at the reference speed")
        v_ref: float = q(0.3, "m/s", bounds=(0.0, 10.0), open_low=True, symbol="v_ref", doc="reference mean speed")
        t_th: float = q(120.0, "s", bounds=(0.0, 1e5), open_low=True, symbol="T_th", doc="seal thermal time")

    if SEAL_SD:
        @staticmethod
        def jump(code, a, p, J, s, d, x, FP, beta, v_ref, t_th):
            return J * (1.0 - beta * np.minimum(x[0], 1.0))
    else:
        @staticmethod
        def jump(code, a, p, J, x, FP, beta, v_ref, t_th):
            return J * (1.0 - beta * np.minimum(x[0], 1.0))

    @staticmethod
    def rates(s, v, p, x, PP, FP, beta, v_ref, t_th):
        return ((np.abs(v) / v_ref - x[0]) / t_th,)

    @staticmethod
    def initial(FP, PP, beta, v_ref, t_th):
        return (0.0,)

    @staticmethod
    def steady(v, FP, PP, beta, v_ref, t_th):
        return (0.0,)


class TruthStiffeningString(Effect):
    """Out of every name: a string that stiffens with stretch, T += k_3 e^3 with the stretch
    e = (T - T_0 - c_ds dv)/k_ds recovered from the nominal tension."""

    name = "stiffening_string"
    hook = "string"

    @dataclass(frozen=True)
    class Params:
        k3: float = q(1e8, "N/m^3", bounds=(0.0, 1e14), symbol="k_3", doc="cubic stiffness")

    @staticmethod
    def string(dv, T, x, PP, k3):
        e = (T - PP[T0] - PP[CDS] * dv) / PP[KDS]
        return T + k3 * e * e * e


#: the validation's plant truth laws, in two compositions of at most three extra states each
NAMED_PLANT_TRUTH = {c.name: c for c in (TruthLaggedDirection, TruthWornBand, TruthLaminarLeak)}
OOL_PLANT_TRUTH = {c.name: c for c in (TruthLineInertance, TruthSealWarming, TruthStiffeningString)}


def validation_composition(name):
    """The compiled truth stepper that holds the plant truth law ``name`` (None: the classic one)."""
    if name in NAMED_PLANT_TRUTH:
        return composition(tuple(NAMED_PLANT_TRUTH.values()))
    if name in OOL_PLANT_TRUTH:
        return composition(tuple(OOL_PLANT_TRUTH.values()))
    return truth_composition()


def plant_truth(name):
    """The plant truth class of ``name`` (any composition), or None for an output law."""
    return {**TRUTH, **NAMED_PLANT_TRUTH, **OOL_PLANT_TRUTH}.get(name)


# --- output truth laws: post-processing of the clean channels -----------------------------------
def first_order_lag(t, y, tau):
    """Causal first-order lag of ``y`` sampled at ``t`` (uniform), starting settled at y[0]."""
    from scipy.signal import lfilter

    a = np.exp(-(t[1] - t[0]) / tau)
    return lfilter([1 - a], [1, -a], y - y[0]) + y[0]


def sensor_gain(t, cols, channel, gain, bandwidth=5.0):
    """y_m = g LP(y): the channel's calibration factor g behind its own first-order bandwidth [Hz]."""
    out = dict(cols)
    out[channel] = gain * first_order_lag(t, cols[channel], 1.0 / (2 * np.pi * bandwidth))
    return out


def sensor_offset(t, cols, channel, offset, drift_time=0.0):
    """y_m = y + b (constant, drift_time = 0) or y + b (1 - exp(-t/T_b)) (warm-up zero drift)."""
    out = dict(cols)
    shape = 1.0 if drift_time <= 0 else 1.0 - np.exp(-(t - t[0]) / drift_time)
    out[channel] = cols[channel] + offset * shape
    return out


def synthetic_pitch(t, amplitude, period, seed):
    """A vessel pitch angle [rad]: narrow-band random (a sum of 12 components spread +-15 % around
    ``period`` [s], random phases), rms ``amplitude`` [rad]."""
    rng = np.random.default_rng(seed)
    f = rng.uniform(0.85, 1.15, 12) / period
    ph = rng.uniform(0, 2 * np.pi, 12)
    th = np.sum(np.cos(2 * np.pi * f[:, None] * t[None, :] + ph[:, None]), axis=0)
    return amplitude * th / np.sqrt(6.0)


def heave_lever_arm(t, cols, lever_arm, pitch):
    """Heave measured at a lever arm L from the compensator: z_m = z + L sin(theta)."""
    out = dict(cols)
    out["heave"] = cols["heave"] + lever_arm * np.sin(pitch)
    out["pitch"] = pitch
    return out


def heave_mru(t, cols, gain, corner=0.01):
    """Heave from a motion reference unit with a gain error and a 2nd-order Butterworth high-pass at
    ``corner`` [Hz] (its drift-free double integration)."""
    from scipy.signal import butter, lfilter

    b, a = butter(2, corner, btype="highpass", fs=1.0 / (t[1] - t[0]))
    out = dict(cols)
    out["heave"] = gain * lfilter(b, a, cols["heave"])
    return out


def wob_saturation(t, cols, w_max):
    """The WOB load cell clips at ``w_max`` [N]."""
    out = dict(cols)
    out["wob"] = np.minimum(cols["wob"], w_max)
    return out


def backlash(y, width):
    """``y`` read through a play of total width ``width`` (the reading moves only once the play is
    taken up), starting centred."""
    out = np.empty_like(y)
    r = y[0]
    half = 0.5 * width
    for i, v in enumerate(y):
        if v > r + half:
            r = v - half
        elif v < r - half:
            r = v + half
        out[i] = r
    return out


def stroke_backlash(t, cols, width):
    """The stroke transducer reads through a play of ``width`` [m]."""
    out = dict(cols)
    out["stroke"] = backlash(cols["stroke"], width)
    return out


#: output truth label -> component (contract schema 2) for every validation truth law
COMPONENT = {"friction_lag": "friction", "dwell_stiction": "friction", "pressure_friction": "friction",
             "asymmetric_friction": "friction", "position_friction": "friction", "seal_warming": "friction",
             "gas_heat_transfer": "gas_spring", "gas_leak": "gas_spring", "flow_loss": "flow_line",
             "line_inertance": "flow_line", "string_damping": "string_formation",
             "stiffening_string": "string_formation", "sensor_delay": "sensors", "sensor_gain": "sensors",
             "sensor_offset": "sensors", "wob_saturation": "sensors", "stroke_backlash": "sensors",
             "heave_reference": "heave_input", "parameter_mismatch": None, "none": None}
#: truth labels outside every contract name
OUT_OF_LIBRARY = ("line_inertance", "seal_warming", "stiffening_string", "wob_saturation", "stroke_backlash")
