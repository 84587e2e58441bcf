"""Frequency responses of the linearised CMC: transmissibility heave -> WOB,
effective stiffness k_eff(omega), natural frequencies and damping ratios.

Results are ``control.FrequencyResponseData`` so ``control.bode_plot`` works on
them directly; :func:`freqresp_batch` evaluates many systems at many
frequencies at once with numpy (stacked ``(j omega I - A)^-1 B`` solves).
"""

from __future__ import annotations

import numpy as np

#: wave band of paper A's argument: periods 5-20 s [rad/s]
WAVE_BAND = (2 * np.pi / 20.0, 2 * np.pi / 5.0)


def freqresp_batch(A, B, C, D, omega):
    """Frequency response of many state-space systems at many frequencies.

    Parameters
    ----------
    A : ndarray (..., n, n)
    B : ndarray (..., n, m)
    C : ndarray (..., p, n)
    D : ndarray (..., p, m)
        Leading dimensions broadcast (e.g. 100 parameter variations).
    omega : array_like (nw,) [rad/s]

    Returns
    -------
    H : ndarray (..., p, m, nw), complex
        ``H = C (j omega I - A)^-1 B + D``.

    Notes
    -----
    One batched LU solve per (system, frequency) with :func:`numpy.linalg.solve`
    on stacked matrices; no Python loop.
    """
    A, B, C, D = (np.asarray(m) for m in (A, B, C, D))
    w = np.asarray(omega, dtype=float)
    n = A.shape[-1]
    M = (1j * w)[:, None, None] * np.eye(n) - A[..., None, :, :]           # (..., nw, n, n)
    X = np.linalg.solve(M, np.broadcast_to(B[..., None, :, :], M.shape[:-1] + (B.shape[-1],)))
    H = C[..., None, :, :] @ X + D[..., None, :, :]                         # (..., nw, p, m)
    return np.moveaxis(H, -3, -1)


def _siso(sys, output, input_):
    i = list(sys.output_labels).index(output)
    j = list(sys.input_labels).index(input_)
    return i, j


def frequency_grid(sys=None, n: int = 1000, lo: float = 1e-3, hi: float | None = None) -> np.ndarray:
    """Log-spaced frequencies [rad/s] from ``lo`` to 10x the fastest pole (or ``hi``).

    Parameters
    ----------
    sys : control.StateSpace, optional
        Model whose fastest pole sets the upper end (unused when ``hi`` is given).
    n : int
        Number of frequencies.
    lo : float [rad/s]
        Lowest frequency.
    hi : float [rad/s], optional
        Highest frequency; default 10 x the fastest pole (100 rad/s without ``sys``).
    """
    if hi is None:
        hi = 10.0 * max(1.0, float(np.max(np.abs(np.linalg.eigvals(sys.A))))) if sys is not None else 100.0
    return np.logspace(np.log10(lo), np.log10(hi), n)


def effective_stiffness(sys, omega):
    """Dynamic effective stiffness k_eff(omega) = -WOB(j omega) / z_h(j omega) [N/m].

    Parameters
    ----------
    sys : control.StateSpace
        From :func:`heavecomp.analysis.linear.linearise` (input ``heave``, output ``wob``).
    omega : array_like [rad/s]

    Returns
    -------
    control.FrequencyResponseData
        Complex, SISO ``heave -> k_eff``.  Its DC value is paper A eq. 14's
        k_eff = 1/(1/k_gas + 1/k_ds + 1/k_F) (the sign makes it positive: heave
        up lifts the bit).
    """
    import control as ct

    i, j = _siso(sys, "wob", "heave")
    w = np.asarray(omega, dtype=float)
    H = freqresp_batch(sys.A, sys.B, sys.C, sys.D, w)[i, j]
    return ct.frd(-H, w, inputs=["heave"], outputs=["k_eff"], name="k_eff")


def transmissibility(sys, omega, hold=()):
    """Transmissibility |WOB/heave| normalised by its static value: T(omega) = k_eff(omega) / k_eff(0) [-].

    Parameters
    ----------
    sys : control.StateSpace
        Linear CMC model with named signals (:func:`heavecomp.analysis.linear.linearise`).
        Input ``heave``, output ``wob``.
    omega : array_like [rad/s]
        Frequencies.
    hold : sequence of str
        States held at their operating values in the static value (:func:`dc_gain`).

    Returns
    -------
    control.FrequencyResponseData
        Complex, SISO; |T| > 1 amplifies the heave disturbance of the static
        estimate (paper A eq. 13), |T| < 1 filters it.
    """
    import control as ct

    i, j = _siso(sys, "wob", "heave")
    w = np.asarray(omega, dtype=float)
    H = freqresp_batch(sys.A, sys.B, sys.C, sys.D, w)[i, j]
    return ct.frd(H / dc_gain(sys, hold=hold), w, inputs=["heave"], outputs=["T_wob"], name="transmissibility")


def drift_states(sys, xdot=None) -> list[str]:
    """States the linear model cannot hold still: an effect's charge that drifts or integrates.

    Parameters
    ----------
    sys : control.StateSpace
        Linear CMC model with named states (:func:`heavecomp.analysis.linear.linearise`).
    xdot : array_like, optional
        State derivative at the operating point (:attr:`heavecomp.analysis.linear.OperatingPoint.xdot`).

    Returns
    -------
    list of str
        Labels of the states whose row of ``[A B]`` is zero (to first order nothing moves them: a
        pure integrator, a pole at 0 the heave never excites, e.g. ``gas_leak``'s charge change at
        a fixed rate) or, beyond the four mechanical states, whose derivative at the operating
        point is not zero (the operating point is no steady state for them: a leaking charge).
    """
    A, B = np.asarray(sys.A, dtype=float), np.asarray(sys.B, dtype=float)
    scale = np.abs(np.hstack([A, B])).max(axis=1)
    out = [k for k in range(A.shape[0]) if scale[k] == 0.0 or scale[k] <= 1e-14 * scale.max()]
    if xdot is not None:
        xdot = np.asarray(xdot, dtype=float).ravel()
        out += [k for k in range(4, min(len(xdot), A.shape[0])) if abs(xdot[k]) > 1e-14 and k not in out]
    labels = list(sys.state_labels)
    return [labels[k] for k in sorted(out)]


def frozen(sys, states=()):
    """The model with ``states`` held at their operating values (their rows and columns removed).

    Parameters
    ----------
    sys : control.StateSpace
        Linear model with named states.
    states : sequence of str
        State labels to hold (:func:`drift_states`).

    Returns
    -------
    control.StateSpace
        ``sys`` itself when ``states`` is empty.  Holding a drifting charge at its present value is
        the model of the heave time scale: the gain and the modes are those at today's charge.
    """
    if not states:
        return sys
    import control as ct

    labels = list(sys.state_labels)
    keep = [k for k, n in enumerate(labels) if n not in set(states)]
    A, B, C = (np.asarray(m, dtype=float) for m in (sys.A, sys.B, sys.C))
    return ct.ss(A[np.ix_(keep, keep)], B[keep], C[:, keep], sys.D, states=[labels[k] for k in keep],
                 inputs=list(sys.input_labels), outputs=list(sys.output_labels), name=f"{sys.name}_frozen")


def dc_gain(sys, output="wob", input_="heave", hold=()) -> float:
    """Static gain of one channel (solve of -A x = B; no inverse of D-only systems).

    Parameters
    ----------
    sys : control.StateSpace
        Linear CMC model with named signals (:func:`heavecomp.analysis.linear.linearise`).
    output : str
        Output label (default ``wob`` [N]).
    input_ : str
        Input label (default ``heave`` [m]).
    hold : sequence of str
        States held at their operating values (:func:`drift_states`, :func:`frozen`): an effect's
        charge that integrates or drifts has no static value of its own (A is singular, or the
        operating point is no steady state for it); the gain is then the one at the present charge.
    """
    sys = frozen(sys, hold)
    i, j = _siso(sys, output, input_)
    return float((sys.D[i, j] - sys.C[i] @ np.linalg.solve(sys.A, sys.B[:, j])).real)


def undamped_natural_frequencies(sys) -> np.ndarray:
    """Undamped natural frequencies [rad/s, ascending] of a mechanical realisation.

    Requires the states ``[q_1, dq_1, q_2, dq_2]`` layout of
    :func:`~heavecomp.analysis.linear.linearise` (rows 0 and 2 of A are
    velocity selectors); then ``-A[[1,3]][:, [0,2]] = M^-1 K`` and
    omega_i^2 are its eigenvalues (damping and friction slopes dropped).

    Parameters
    ----------
    sys : control.StateSpace or (4, 4) array
        The model or its A matrix, states ``[q_1, dq_1, q_2, dq_2]`` (:func:`~heavecomp.analysis.linear.linearise`).
    """
    A = np.asarray(sys.A if hasattr(sys, "A") else sys, dtype=float)
    if A.shape != (4, 4):
        raise ValueError("undamped_natural_frequencies: A has effect states beyond [q, dq]")
    pos, vel = [0, 2], [1, 3]
    sel = np.zeros((2, 4))
    sel[0, 1] = sel[1, 3] = 1.0
    if not np.allclose(A[pos], sel):
        raise ValueError("undamped_natural_frequencies: A is not in [q, dq] mechanical form")
    K = -A[np.ix_(vel, pos)]
    lam = np.sort(np.linalg.eigvals(K).real)
    return np.sqrt(np.maximum(lam, 0.0))


def modes(sys) -> dict:
    """Natural frequencies and damping ratios from the poles.

    Parameters
    ----------
    sys : control.StateSpace
        Linear CMC model with named signals (:func:`heavecomp.analysis.linear.linearise`).

    Returns
    -------
    dict
        ``natural_frequencies`` [rad/s, ascending]: undamped values
        (:func:`undamped_natural_frequencies`); ``damped_natural_frequencies``
        |lambda| of each pole pair [rad/s]; ``damping_ratios`` -Re(lambda)/|lambda|
        (for an overdamped pair of real poles: -(l1 + l2) / (2 sqrt(l1 l2)));
        ``poles`` (list of [re, im]).  Pairs are ordered by |lambda|, matched to
        the undamped frequencies in the same order.
    """
    lam = np.linalg.eigvals(np.asarray(sys.A, dtype=float))
    cplx = lam[lam.imag > 1e-12 * (np.abs(lam) + 1e-300)]
    real = np.sort(lam[np.abs(lam.imag) <= 1e-12 * (np.abs(lam) + 1e-300)].real)
    pairs = [(abs(l), -l.real / abs(l)) for l in cplx]
    for a, b in zip(real[::2], real[1::2]):
        wn = np.sqrt(a * b) if a * b > 0 else max(abs(a), abs(b))
        pairs.append((wn, -(a + b) / (2 * wn)))
    pairs.sort()
    out = {
        "damped_natural_frequencies": [float(p[0]) for p in pairs],
        "damping_ratios": [float(p[1]) for p in pairs],
        "poles": [[float(l.real), float(l.imag)] for l in sorted(lam, key=lambda l: (abs(l), l.imag))],
    }
    try:
        out["natural_frequencies"] = [float(w) for w in undamped_natural_frequencies(sys)]
    except ValueError:
        out["natural_frequencies"] = out["damped_natural_frequencies"]
    return out


def response_table(sys, omega, hold=()) -> dict[str, np.ndarray]:
    """Columns of ``frequency_response.csv``: heave -> every output, magnitude and phase.

    Parameters
    ----------
    sys : control.StateSpace
        Linear CMC model with named signals (:func:`heavecomp.analysis.linear.linearise`).
        Input ``heave``, output ``wob`` among others.
    omega : array_like [rad/s]
        Frequencies.
    hold : sequence of str
        States held at their operating values in the static value (:func:`dc_gain`).

    Returns
    -------
    dict
        ``omega`` [rad/s], ``frequency`` [Hz], ``period`` [s], ``k_eff_mag`` [N/m],
        ``k_eff_phase_deg`` [deg], ``transmissibility`` [-] (|k_eff(w)|/k_eff(0)),
        ``wob_per_heave_mag`` [N/m], ``wob_per_heave_phase_deg`` [deg],
        ``stroke_per_heave_mag`` [m/m], ``pressure_per_heave_mag`` [Pa/m],
        ``tension_per_heave_mag`` [N/m] and their phases [deg].
    """
    w = np.asarray(omega, dtype=float)
    j = list(sys.input_labels).index("heave")
    H = freqresp_batch(sys.A, sys.B, sys.C, sys.D, w)[:, j, :]
    i = list(sys.output_labels).index("wob")
    k0 = -dc_gain(sys, hold=hold)
    cols = {"omega": w, "frequency": w / (2 * np.pi), "period": 2 * np.pi / w,
            "k_eff_mag": np.abs(H[i]), "k_eff_phase_deg": np.degrees(np.angle(-H[i])),
            "transmissibility": np.abs(H[i]) / abs(k0)}
    for k, name in enumerate(sys.output_labels):
        cols[f"{name}_per_heave_mag"] = np.abs(H[k])
        cols[f"{name}_per_heave_phase_deg"] = np.degrees(np.angle(H[k]))
    return cols
