"""The CMC main cylinder's stick map over heave amplitude and period (exact stick-slip
simulation), and the quasi-static amplitude below which it never breaks loose.

Paper B's stick-slip question asked of the CMC; the pneumatic cylinder's own
analysis is :mod:`heavecomp.pneumatic.stickslip`.
"""

from __future__ import annotations

import math

import numpy as np

from heavecomp.friction.laws import FrictionLaw
from heavecomp.simulate import simulate


def cmc_stick_map(params, amplitudes, periods, models=("stribeck", "rotating_eq6", "rotating_eq7"), *,
                  n_periods: float = 4.0, rate: float = 10.0, tangential_velocity: float = 0.05) -> dict:
    """Stick fraction, stick count and mean stick duration of the CMC main cylinder over
    heave amplitude x period, for each friction model (foundation simulator, exact stick).

    Statistics are taken after the heave fade-in (``ramp`` = one period) over ``n_periods``.
    ``tangential_velocity`` [m/s] is used for the rotating models when ``params``
    has none (paper A: v_t = omega d / 2 ~ 0.05 m/s).
    Returns {model: {"stick_fraction", "n_stick_per_period", "mean_stick_s", "stroke_p2p"}}
    with arrays (len(periods), len(amplitudes)), plus the axes.

    Parameters
    ----------
    params : CMCParams
        The parameter set (:class:`heavecomp.params.CMCParams`). Its heave and friction model
        are replaced for each cell.
    amplitudes : sequence of float [m]
        Heave amplitudes of the sine.
    periods : sequence of float [s]
        Heave periods.
    models : sequence of str
        Friction models (``stribeck`` eq. 4, ``rotating_eq6``, ``rotating_eq7`` of paper A).
    n_periods : float
        Periods simulated after the one-period fade-in [-].
    rate : float [Hz]
        Output rate of the simulation.
    tangential_velocity : float [m/s]
        v_t of the rotating models when ``params`` has none.
    """
    A, T = np.asarray(amplitudes, float), np.asarray(periods, float)
    out = {"amplitudes": A, "periods": T}
    for m in models:
        sf = np.empty((T.size, A.size))
        ns = np.empty_like(sf)
        dur = np.empty_like(sf)
        smax = np.empty_like(sf)
        for i, per in enumerate(T):
            for j, amp in enumerate(A):
                fr = {"model": m}
                if m.startswith("rotating") and params.friction.tangential_velocity is None:
                    fr["tangential_velocity"] = tangential_velocity
                q = params.replace(friction=fr,
                                   heave={"kind": "sine", "amplitude": float(amp), "period": float(per),
                                          "ramp": float(per)})
                res = simulate(q, (n_periods + 1) * per, rate=rate)
                met = res.metrics()
                w = res.window()
                stuck = res["stuck"][w] > 0.5
                # stick episodes inside the window (rising edges)
                starts = np.count_nonzero(np.diff(stuck.astype(int)) == 1) + int(stuck[0])
                sf[i, j] = met["stick_fraction"]
                ns[i, j] = starts / n_periods
                dur[i, j] = (met["stick_fraction"] * n_periods * per / starts) if starts else \
                    (n_periods * per if met["stick_fraction"] > 0.99 else 0.0)
                smax[i, j] = np.ptp(res["stroke"][w])
        out[m] = {"stick_fraction": sf, "n_stick_per_period": ns, "mean_stick_s": dur, "stroke_p2p": smax}
    return out


def cmc_breakout_amplitude(params, period: float, model: str = "stribeck") -> float:
    """Heave amplitude [m] below which the main cylinder never breaks loose (zero stroke).

    Quasi-static estimate: stuck, the rod holds the heave through the drill-string
    and formation springs in series, so the holding force changes by ``k_s z_h`` with
    ``1/k_s = 1/k_DS + 1/k_F`` (plus the inertia of the top mass, ``M_c omega^2 z_h``);
    breakout when that exceeds the static limit at the operating pressure.

    Parameters
    ----------
    params : CMCParams
        The parameter set (:class:`heavecomp.params.CMCParams`).
    period : float [s]
        Heave period (sets the top mass's inertia term M_c omega^2).
    model : str
        Friction model whose static limit at the operating pressure p_0 is used (default ``stribeck``, eq. 4).
    """
    law = FrictionLaw.from_params(params.replace(friction={"model": model}).friction)
    Fs = float(law.static_limit(params.p0))
    ds, fo, c = params.drill_string, params.formation, params.compensator
    ks = 1.0 / (1.0 / ds.stiffness + 1.0 / fo.stiffness)
    w = 2 * math.pi / period
    return Fs / abs(ks - c.moving_mass * w * w) if Fs > 0 else 0.0
