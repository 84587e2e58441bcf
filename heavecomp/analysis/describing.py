"""Describing function of the main-cylinder seal friction and the amplitude-
dependent transmissibility heave -> WOB.

For a sinusoidal stroke ``s = S sin(theta)``, ``theta = omega t`` (velocity
``v = S omega cos(theta)``, pressure ``p = p(s)`` from the polytropic gas law of
:func:`heavecomp.plants.cmc.gas_pressure`), the friction force of paper A eq.
4/6/7 (:class:`heavecomp.friction.laws.FrictionLaw`, Coulomb + Stribeck +
viscous + pressure terms) is replaced by its first harmonic

    F_1(t) = k_eq S sin(theta) + c_eq S omega cos(theta)
    c_eq(S, omega) = (1 / (pi S omega)) int_0^{2 pi} F(theta) cos(theta) dtheta   [N s/m]
    k_eq(S, omega) = (1 / (pi S))       int_0^{2 pi} F(theta) sin(theta) dtheta   [N/m]

(a pure Coulomb force F_C gives c_eq = 4 F_C / (pi S omega); viscous C_v gives
C_v).  The friction acts on the top mass exactly where the active force
``u_active`` enters (``F_f = -u_active``), so at one frequency the frictionless
linear model closes with ``u = -Z s``, ``Z = k_eq + j omega c_eq``:

    s / z_h   = G_sz / (1 + Z G_su)
    WOB / z_h = G_wz - G_wu Z s / z_h

and the stroke amplitude ``S = a |s/z_h|`` is found by a root search (the
describing-function balance ``S = a |G_sz / (1 + Z(S) G_su)|``).  When no
sliding solution exists the cylinder is predicted stuck (Z -> infinity).

Limits: the describing function assumes the piston slides all the time.  With
stick phases (small heave, full static friction) the stroke is not sinusoidal
and the prediction is approximate; the comparison with the exact stick-slip
simulator (:func:`compare_with_simulation`) shows where.
"""

from __future__ import annotations

import dataclasses
import logging
import math

import numpy as np

from heavecomp.analysis.frequency import freqresp_batch
from heavecomp.analysis.linear import batch_matrices_from_params
from heavecomp.friction.laws import FrictionLaw
from heavecomp.plants.cmc import A as A_IDX, gas_pressure, plant_vector, V0 as V0_IDX
from heavecomp.simulate import simulate

log = logging.getLogger(__name__)


def equivalent_gains(law, stroke_amplitude, omega, PP, *, n: int = 2048):
    """First-harmonic gains of a friction law for s = S sin(omega t).

    Parameters
    ----------
    law : heavecomp.friction.laws.FrictionLaw
    stroke_amplitude : float or ndarray [m]
        S > 0.
    omega : float [rad/s]
    PP : ndarray
        Plant vector (:func:`heavecomp.plants.cmc.plant_vector`) for the pressure p(s).
    n : int
        Samples per period (midpoint rule; exact sliding law, never at v = 0).

    Returns
    -------
    c_eq : ndarray [N s/m]
        Equivalent viscous damping (friction in phase with the velocity).
    k_eq : ndarray [N/m]
        Equivalent stiffness (friction in phase with the stroke).
    """
    S = np.asarray(stroke_amplitude, dtype=float)
    th = (np.arange(n) + 0.5) * (2 * np.pi / n)
    s = S[..., None] * np.sin(th)
    v = S[..., None] * omega * np.cos(th)
    F = law.force(v, gas_pressure(s, PP))
    a1 = 2.0 / n * np.sum(F * np.sin(th), axis=-1)
    b1 = 2.0 / n * np.sum(F * np.cos(th), axis=-1)
    return b1 / (S * omega), a1 / S


@dataclasses.dataclass(frozen=True)
class DFResult:
    """Describing-function prediction at one heave amplitude and frequency.

    Attributes
    ----------
    heave_amplitude : float [m]
    omega : float [rad/s]
    stroke_amplitude : float [m]   (0 when predicted stuck)
    c_eq : float [N s/m]           (inf when stuck)
    k_eq : float [N/m]
    wob_amplitude : float [N]      first harmonic of the WOB
    wob_phase_deg : float [deg]    relative to the heave
    k_eff : float [N/m]            wob_amplitude / heave_amplitude (amplitude-dependent)
    stuck : bool
    """

    heave_amplitude: float
    omega: float
    stroke_amplitude: float
    c_eq: float
    k_eq: float
    wob_amplitude: float
    wob_phase_deg: float
    k_eff: float
    stuck: bool


def _channels(params, omega):
    A, B, C, D = batch_matrices_from_params(params)  # frictionless, u_active = -F_f
    H = freqresp_batch(A, B, C, D, np.atleast_1d(omega))[..., 0]
    return H[1, 0], H[1, 1], H[0, 0], H[0, 1]  # G_sz, G_su, G_wz, G_wu


def describing_response(params, heave_amplitude: float, omega: float, *, n: int = 2048) -> DFResult:
    """Amplitude-dependent heave -> WOB response with the friction's describing function.

    Parameters
    ----------
    params : CMCParams
        Any friction model; ``none`` gives the linear result.
    heave_amplitude : float [m]
    omega : float [rad/s]
    n : int
        Samples per period of the describing-function integral (:func:`equivalent_gains`).

    Returns
    -------
    DFResult
    """
    a, w = float(heave_amplitude), float(omega)
    if not (a > 0 and w > 0 and math.isfinite(a) and math.isfinite(w)):
        raise ValueError("heave_amplitude and omega must be positive")
    law = FrictionLaw.from_params(params.friction)
    PP = plant_vector(params)
    Gsz, Gsu, Gwz, Gwu = _channels(params, w)

    def closed(S):
        c, k = equivalent_gains(law, S, w, PP, n=n)
        Z = k + 1j * w * c
        Ts = Gsz / (1 + Z * Gsu)
        return Ts, Z, c, k

    # balance h(S) = log(a |Ts(S)|) - log S: a stable sliding solution is where h crosses 0 downwards
    # stroke amplitudes up to where the gas volume V_0 + A s would vanish
    S_max = min(10.0 * a * max(1.0, float(np.abs(Gsz))), 0.95 * PP[V0_IDX] / PP[A_IDX])
    S_grid = np.logspace(np.log10(S_max) - 7, np.log10(S_max), 150)
    Ts, _, _, _ = closed(S_grid)
    h = np.log(a * np.abs(Ts)) - np.log(S_grid)
    down = np.nonzero((h[:-1] > 0) & (h[1:] <= 0))[0]
    if law.code == 0:
        S = a * float(np.abs(Gsz))
    elif len(down) == 0:
        S = 0.0
    else:
        from scipy.optimize import brentq

        i = down[-1]
        S = brentq(lambda x: float(np.log(a * np.abs(closed(np.array([x]))[0][0])) - np.log(x)),
                   S_grid[i], S_grid[i + 1], xtol=1e-12 * S_grid[i], rtol=1e-10)
    if S == 0.0:
        Tw = Gwz - Gwu * Gsz / Gsu  # stroke locked: the friction carries the whole difference
        c_eq, k_eq, stuck = math.inf, 0.0, True
    else:
        Ts, Z, c, k = closed(np.array([S]))
        Tw = Gwz - Gwu * Z[0] * Ts[0]
        c_eq, k_eq, stuck = float(c[0]), float(k[0]), False
    return DFResult(heave_amplitude=a, omega=w, stroke_amplitude=float(S), c_eq=c_eq, k_eq=k_eq,
                    wob_amplitude=float(a * abs(Tw)), wob_phase_deg=float(np.degrees(np.angle(Tw))),
                    k_eff=float(abs(Tw)), stuck=stuck)


def first_harmonic(t, x, omega):
    """Amplitude [x] and phase [deg] of the first harmonic of x(t) (least squares with a mean).

    Parameters
    ----------
    t : array [s]
        Sample times.
    x : array
        Signal (any unit; the amplitude is in the same unit).
    omega : float [rad/s]
        Angular frequency of the harmonic.
    """
    M = np.column_stack([np.ones_like(t), np.sin(omega * t), np.cos(omega * t)])
    c = np.linalg.lstsq(M, x, rcond=None)[0]
    return float(np.hypot(c[1], c[2])), float(np.degrees(np.arctan2(c[2], c[1])))


def simulated_response(params, heave_amplitude: float, period: float, *, settle_periods: int = 3,
                       measure_periods: int = 4, rate: float = 20.0) -> dict:
    """Steady first-harmonic WOB of the exact stick-slip simulator for a sine heave.

    The heave fades in over two periods (cmc-reference.md), then ``settle_periods``
    periods are dropped and the WOB's first harmonic is fitted over the next
    ``measure_periods`` periods.

    Parameters
    ----------
    params : CMCParams
        The parameter set (:class:`heavecomp.params.CMCParams`). Its heave is replaced by the sine.
    heave_amplitude : float [m]
        Amplitude of the sine heave.
    period : float [s]
        Period of the sine heave.
    settle_periods : int
        Periods dropped after the fade-in.
    measure_periods : int
        Periods the first harmonic is fitted over.
    rate : float [Hz]
        Output rate of the simulation.

    Returns
    -------
    dict
        ``wob_amplitude`` [N], ``wob_phase_deg`` [deg] (relative to the heave),
        ``stroke_amplitude`` [m], ``stick_fraction`` [-], ``wob_p2p`` [N].
    """
    ramp = 2.0 * period
    p = params.replace(heave={"kind": "sine", "amplitude": heave_amplitude, "period": period, "ramp": ramp})
    start = ramp + settle_periods * period
    res = simulate(p, start + measure_periods * period, rate=rate, stats_start=start)
    m = res.window(start)
    w = 2 * np.pi / period
    t = res["t"][m]
    amp, ph = first_harmonic(t, res["wob"][m], w)
    _, ph_h = first_harmonic(t, res["heave"][m], w)
    s_amp, _ = first_harmonic(t, res["stroke"][m], w)
    return {"wob_amplitude": amp, "wob_phase_deg": (ph - ph_h + 180.0) % 360.0 - 180.0,
            "stroke_amplitude": s_amp, "stick_fraction": float(np.mean(res["stuck"][m])),
            "wob_p2p": float(np.ptp(res["wob"][m]))}


def compare_with_simulation(params, amplitudes, periods, **sim_kw) -> list[dict]:
    """Describing-function WOB amplitude vs the simulator's, for a grid of sine heaves.

    Parameters
    ----------
    params : CMCParams
        The parameter set (:class:`heavecomp.params.CMCParams`).
    amplitudes : sequence of float [m]
        Heave amplitudes.
    periods : sequence of float [s]
        Heave periods.
    **sim_kw : keyword arguments
        Passed to :func:`simulated_response` (``settle_periods``, ``measure_periods``, ``rate``).

    Returns
    -------
    list of dict
        One row per (amplitude [m], period [s]) with ``wob_df``, ``wob_sim`` [N],
        ``rel_error`` = (wob_df - wob_sim) / wob_sim, ``wob_linear`` (frictionless
        linear model) [N], ``stroke_df``, ``stroke_sim`` [m], ``stick_fraction``
        and ``df_stuck``.
    """
    A, B, C, D = batch_matrices_from_params(params)
    rows = []
    for T in periods:
        w = 2 * np.pi / T
        lin = abs(freqresp_batch(A, B, C, D, [w])[0, 0, 0])
        for a in amplitudes:
            df = describing_response(params, a, w)
            sim = simulated_response(params, a, T, **sim_kw)
            rows.append({"friction": params.friction.model, "amplitude": float(a), "period": float(T),
                         "wob_df": df.wob_amplitude, "wob_sim": sim["wob_amplitude"],
                         "rel_error": (df.wob_amplitude - sim["wob_amplitude"]) / sim["wob_amplitude"],
                         "wob_linear": a * lin, "phase_df_deg": df.wob_phase_deg,
                         "phase_sim_deg": sim["wob_phase_deg"], "stroke_df": df.stroke_amplitude,
                         "stroke_sim": sim["stroke_amplitude"], "c_eq": df.c_eq,
                         "stick_fraction": sim["stick_fraction"], "df_stuck": df.stuck})
    return rows


def describing_transmissibility(params, heave_amplitude: float, omega, *, n: int = 1024):
    """Amplitude-dependent effective stiffness k_eff(omega; a) = -WOB_1/heave [N/m] as an FRD.

    Parameters
    ----------
    params : CMCParams
    heave_amplitude : float [m]
        Heave amplitude a of the sine the describing function is balanced for.
    omega : array_like [rad/s]
    n : int
        Samples per period of the describing-function integral (:func:`equivalent_gains`).

    Returns
    -------
    control.FrequencyResponseData
        SISO ``heave -> k_eff``; at each frequency the first-harmonic WOB per
        metre of heave with the friction replaced by its describing function
        (:func:`describing_response`).  For ``friction.model = "none"`` it is
        :func:`heavecomp.analysis.frequency.effective_stiffness`.
    """
    import control as ct

    w = np.asarray(omega, dtype=float)
    r = [describing_response(params, heave_amplitude, wi, n=n) for wi in w]
    H = np.array([x.k_eff * np.exp(1j * np.radians(x.wob_phase_deg)) for x in r])
    return ct.frd(-H, w, inputs=["heave"], outputs=["k_eff"], name=f"k_eff_df_a{heave_amplitude * 1e3:.0f}mm")
