"""Estimation from what a rig measures: heave preview and state/friction observer.

Heave predictor
---------------
A direct multi-step linear predictor fitted online by least squares: the heave
k intervals ahead (k = 0..H, H >= 2 s) is regressed on the last ``order``
measured samples (every ``step``-th, default 80 samples 0.1 s apart = 8 s of
history) and a constant.  The sums X'X and X'Y are updated recursively at every
sample with exponential forgetting (time constant ``window``, default 240 s),
so the cost per sample is O(order^2 + order H) and the (order+1)^2 system is
re-solved every ``refit`` seconds (ridge-regularised).  A direct predictor has
no iterated recursion, hence no stability question, and its k-step error is
the least-squares optimum for that k (an AR model iterated forward is not).
dz_h/dt and d^2z_h/dt^2 on the control grid are the derivatives of a
least-squares polynomial (degree 6) through the last 2 s of measured samples and
the predicted trajectory, so that "now" is inside the fit and the sensor noise
is smoothed before it is differentiated; z_h itself is that polynomial at "now"
(the k = 0 regression is the noisy sample itself) blending linearly into the
direct prediction over ``z_blend`` intervals (0.5 s).  Until the fit has
``handover`` seconds of data (~40 s after the start) the former predictor,
:class:`ARBlockPredictor`, which converges within seconds, gives the preview.
With 5 mm sensor noise on a JONSWAP
sea (H_s 2 m, T_p 12 s) the 1 s ahead error is ~8 cm, close to what an offline
least-squares predictor fitted on an hour of the same noisy sea achieves
(~7 cm); without noise the band-limited heave would be predictable to < 1 mm.

Observer
--------
A steady-state Kalman filter on the controller's discrete linear model
(:mod:`heavecomp.controllers.model`) augmented with a constant force
disturbance d on the top mass (random walk)::

    x+ = Ad x + Bu u + Bw w + Bf (f_ff + d),   d+ = d
    y  = C x + y0            (stroke, pressure, WOB measured)

``f_ff`` is the friction model's force the controller already accounts for
(zero when it has none); ``d`` is then the friction the model misses (stiction,
wrong parameters) plus every other model error.
"""

from __future__ import annotations

import numpy as np


class HeavePredictor:
    """Online direct multi-step linear heave predictor (see module docstring).

    Parameters
    ----------
    dt : float [s]
        Sample interval of the measured heave (the control interval).
    order : int
        Number of past samples regressed on (lags ``0, step, 2 step, ...``).
    window : float [s]
        Time constant of the exponential forgetting of the least-squares sums.
    step : int
        Lag spacing in samples (default 2: the last 80 x 2 x 50 ms = 8 s at 20 Hz).
    horizon : int
        Number of intervals ahead predicted directly (beyond: extrapolated with the
        last predicted velocity); the derivative polynomial is fitted over it.
    ridge : float
        Ridge regularisation, relative to the mean diagonal of the Gram matrix.
    refit : float [s]
        Interval between re-solves of the least-squares problem.
    min_data : float [s]
        Regression rows (in seconds, forgetting-weighted) before the first solve.
    poly_degree : int
        Degree of the least-squares polynomial the velocity and acceleration come from.
    ridge_start : float
        Extra ridge, ``ridge_start * order / rows``, large while few rows are in.
    handover : float [s]
        Regression rows needed before this predictor replaces :class:`ARBlockPredictor`.
    z_blend : float
        Intervals over which z blends from the polynomial (now) into the direct prediction.
    past : int
        Measured samples (before and including now) in the derivative polynomial.
    """

    def __init__(self, dt: float, order: int = 80, window: float = 240.0, step: int = 2, horizon: int = 40,
                 ridge: float = 1e-6, refit: float = 2.0, min_data: float = 5.0, poly_degree: int = 6,
                 ridge_start: float = 1e-3, handover: float = 30.0, z_blend: float = 10.0, past: int = 40):
        self.dt, self.order, self.window, self.step = float(dt), int(order), float(window), int(step)
        self.horizon, self.ridge, self.refit, self.min_data = int(horizon), float(ridge), float(refit), float(min_data)
        self.poly_degree, self.past, self.ridge_start = int(poly_degree), int(past), float(ridge_start)
        self.handover, self.z_blend = float(handover), float(z_blend)
        self.reset()

    def reset(self):
        p, H = self.order, self.horizon
        self._L = (p - 1) * self.step + 1 + H          # samples kept: lags of the oldest regressor + its targets
        self._z = np.zeros(self._L)
        self._n = 0
        self._G = np.zeros((p + 1, p + 1))             # sum of x x' (x: lags and a constant)
        self._B = np.zeros((p + 1, H + 1))             # sum of x y' (y: the heave 0..H intervals later)
        self._w = 0.0                                  # sum of the forgetting weights
        self._lam = float(np.exp(-self.dt / self.window))
        self._idx = np.arange(p) * self.step
        self._since = 0
        self.coef_ = None                              # (p + 1, H + 1): z(t + k dt) = x(t) @ coef_[:, k]
        self.z_last = 0.0
        self._startup = ARBlockPredictor(self.dt)     # used until the direct fit has `handover` s of data

    def _ready(self) -> bool:
        return self.coef_ is not None and self._w * self.dt >= self.handover

    def update(self, t: float, z: float) -> None:
        """Add one measured heave sample z [m] at time t [s] (samples every ``dt``)."""
        self.z_last = float(z)
        if self._startup is not None:
            if self._ready():
                self._startup = None
            else:
                self._startup.update(t, z)
        self._z[:-1] = self._z[1:]
        self._z[-1] = z
        self._n += 1
        if self._n < self._L:
            return
        j = self._L - 1 - self.horizon                 # the regressor H intervals ago ...
        x = np.empty(self.order + 1)
        x[:-1] = self._z[j - self._idx]
        x[-1] = 1.0
        y = self._z[j:]                                # ... and what followed it
        self._G *= self._lam
        self._G += np.outer(x, x)
        self._B *= self._lam
        self._B += np.outer(x, y)
        self._w = self._lam * self._w + 1.0
        self._since += 1
        if self._w * self.dt >= min(self.min_data, 0.5 * self.window) and (
                self.coef_ is None or self._since * self.dt >= self.refit):
            G = self._G.copy()
            d = np.arange(self.order)
            # ridge: relative to the mean diagonal, larger while few rows are in (start-up)
            ridge = self.ridge + self.ridge_start * self.order / self._w
            G[d, d] += ridge * np.trace(self._G[:-1, :-1]) / self.order + 1e-12
            self.coef_ = np.linalg.solve(G, self._B)
            self._since = 0

    def trajectory(self, t: float, n: int) -> np.ndarray:
        """Predicted (z, dz, ddz) at t + k dt, k = 0..n, as an (n+1, 3) array [m, m/s, m/s^2]."""
        out = np.zeros((n + 1, 3))
        if not self._ready():
            return self._startup.trajectory(t, n)
        x = np.empty(self.order + 1)
        x[:-1] = self._z[self._L - 1 - self._idx]
        x[-1] = 1.0
        zf = x @ self.coef_                           # direct predictions 0..horizon intervals ahead
        # velocity and acceleration: derivatives of a least-squares polynomial through the
        # last ``past`` measured samples and the predicted trajectory (differencing the
        # prediction directly would amplify the sensor noise it passes through; the past
        # samples keep t = now away from the end of the fit)
        P = self.past
        zz = np.r_[self._z[self._L - P:self._L - 1], zf] if P > 1 else zf
        T = self.dt * self.horizon
        tau = self.dt * np.arange(-(zz.size - self.horizon - 1), self.horizon + 1) / T
        c = np.polyfit(tau, zz, self.poly_degree)
        m = min(n, self.horizon)
        tt = self.dt * np.arange(m + 1) / T
        # z: the smoothed polynomial now (the k = 0 prediction is the noisy sample itself),
        # blending linearly into the direct prediction over ``z_blend`` intervals
        g = np.clip(1.0 - np.arange(m + 1) / max(self.z_blend, 1e-9), 0.0, 1.0)
        out[:m + 1, 0] = g * np.polyval(c, tt) + (1.0 - g) * zf[:m + 1]
        out[:m + 1, 1] = np.polyval(np.polyder(c, 1), tt) / T
        out[:m + 1, 2] = np.polyval(np.polyder(c, 2), tt) / T ** 2
        if n > m:                                       # beyond the fitted horizon: constant velocity
            k = np.arange(1, n - m + 1)
            out[m + 1:, 0] = out[m, 0] + out[m, 1] * self.dt * k
            out[m + 1:, 1] = out[m, 1]
        return out


def prediction_error_bound(spectrum, dt: float, noise_std: float, steps, n: int = 2 ** 18) -> np.ndarray:
    """RMS error of the best linear predictor of a stationary heave k samples ahead [m].

    The bound no linear heave predictor can beat, given the whole noisy past:
    the samples y_j = z(j dt) + e_j (white noise of std ``noise_std``) of a
    Gaussian heave with one-sided spectral density ``spectrum(f)`` [m^2/Hz]
    (zero above the Nyquist frequency).  Spectral factorisation via the
    cepstrum (Kolmogorov-Szego): the noisy sequence's innovation filter h gives
    the k-step error of y, sum_{j<k} h_j^2, minus the unpredictable noise variance.

    Parameters
    ----------
    spectrum : callable
        f [Hz] -> S(f) [m^2/Hz], one-sided (e.g. ``excitation.jonswap_spectrum``).
    dt : float [s]
        Sample interval.
    noise_std : float [m]
        White measurement noise; must be > 0 (without noise a band-limited sea is
        perfectly predictable and the factorisation does not exist).
    steps : int or sequence of int
        Prediction distances k >= 1 [samples].
    n : int
        FFT length of the factorisation.

    Returns
    -------
    ndarray : RMS error of z(t + k dt) for each k [m].
    """
    if not noise_std > 0:
        raise ValueError("prediction_error_bound: noise_std must be > 0")
    f = np.fft.fftfreq(n, dt)
    phi = np.asarray(spectrum(np.abs(f)), dtype=float) / 2.0 / dt + noise_std ** 2   # two-sided, per sample
    c = np.fft.ifft(np.log(phi)).real
    c[0] *= 0.5
    c[n // 2 + 1:] = 0.0                                   # causal (minimum-phase) half of the cepstrum
    h = np.fft.ifft(np.exp(np.fft.fft(c))).real            # innovation filter, sum h^2 = var(y)
    k = np.atleast_1d(np.asarray(steps, dtype=int))
    if np.any(k < 1):
        raise ValueError("prediction_error_bound: steps must be >= 1")
    ey = np.cumsum(h ** 2)[k - 1]
    return np.sqrt(np.maximum(ey - noise_std ** 2, 0.0))


class ARBlockPredictor:
    """Online AR heave predictor on 5 Hz block means, Kalman-filtered (the former predictor).

    Converges within seconds but predicts an irregular sea poorly (11 cm RMS 1 s ahead on
    the JONSWAP sea of the module docstring); :class:`HeavePredictor` uses it for its
    first ``handover`` seconds only.

    Parameters
    ----------
    dt : float [s]
        Sample interval of the measured heave (the control interval).
    order : int
        AR order p on the block means.
    window : float [s]
        Fit window.
    decimate : int
        Samples per block (default 4: 20 Hz -> 5 Hz).
    past_blocks : int
        Measured block means (the latest) that, with the AR forecast, carry the least-squares
        polynomial the predicted trajectory comes from.
    poly_degree : int
        Degree of that polynomial (its derivatives give the velocity and acceleration).
    """

    def __init__(self, dt: float, order: int = 10, window: float = 60.0, decimate: int = 4,
                 past_blocks: int = 10, poly_degree: int = 4):
        self.dt, self.order, self.window, self.decimate = dt, int(order), float(window), int(decimate)
        self.past_blocks, self.poly_degree = int(past_blocks), int(poly_degree)
        self.reset()

    def reset(self):
        self._buf: list[float] = []
        self._bt: list[float] = []
        self.block_t: list[float] = []
        self.block_z: list[float] = []   # raw block means
        self.block_f: list[float] = []   # Kalman-filtered block means
        self.coef_ = None
        self.noise_var_ = None           # estimated sensor noise variance of one sample [m^2]
        self._raw = []
        self._d2 = None
        self._since_fit = 0
        self.z_last = 0.0
        self._xs = None                  # filtered AR state [z_n, z_{n-1}, ...]
        self._P = None

    def update(self, t: float, z: float) -> None:
        """Add one measured heave sample z [m] at time t [s]."""
        self.z_last = z
        self._raw = (self._raw + [z])[-3:]
        if len(self._raw) == 3:
            # second differences of the raw samples: 6 sigma^2 for white noise (the wave's
            # own second difference at 20 Hz is ~1e-3 m, negligible)
            d2 = (self._raw[2] - 2 * self._raw[1] + self._raw[0]) ** 2 / 6.0
            self._d2 = d2 if self._d2 is None else 0.995 * self._d2 + 0.005 * d2
            self.noise_var_ = self._d2
        self._buf.append(z)
        self._bt.append(t)
        if len(self._buf) == self.decimate:
            self.block_t.append(float(np.mean(self._bt)))
            zb = float(np.mean(self._buf))
            self.block_z.append(zb)
            self.block_f.append(self._filter(zb))
            self._buf, self._bt = [], []
            self._since_fit += 1
            nmax = int(self.window / (self.dt * self.decimate)) + self.order + 1
            if len(self.block_z) > 2 * nmax:
                del self.block_z[:-nmax], self.block_t[:-nmax], self.block_f[:-nmax]
            if self._since_fit >= max(1, int(round(1.0 / (self.dt * self.decimate)))) or self.coef_ is None:
                self._fit()

    def _filter(self, zb: float) -> float:
        """Kalman filter of the block means with the AR model in companion form."""
        if self.coef_ is None:
            return zb
        p = self.order
        a, c0 = self.coef_[:p], self.coef_[p]
        r = (self.noise_var_ or 0.0) / self.decimate + 1e-12
        if self._xs is None:
            self._xs = np.asarray(self.block_z[-p:][::-1], dtype=float) if len(self.block_z) >= p else np.full(p, zb)
            self._P = np.eye(p) * r
        F = np.zeros((p, p))
        F[0] = a
        F[1:, :-1] = np.eye(p - 1)
        xs = F @ self._xs
        xs[0] += c0
        P = F @ self._P @ F.T
        P[0, 0] += self.q_
        S = P[0, 0] + r
        K = P[:, 0] / S
        xs = xs + K * (zb - xs[0])
        self._P = P - np.outer(K, P[0, :])
        self._xs = xs
        return float(xs[0])

    def _fit(self):
        p = self.order
        nwin = int(self.window / (self.dt * self.decimate))
        src = self.block_f if self.coef_ is not None else self.block_z
        z = np.asarray(src[-nwin:])
        if z.size < 3 * p + 5:
            return
        X = np.column_stack([z[p - i - 1:z.size - i - 1] for i in range(p)] + [np.ones(z.size - p)])
        coef, *_ = np.linalg.lstsq(X, z[p:], rcond=None)
        # keep the model stable: a root outside the unit circle (noise, a fit during the
        # fade-in) would blow up the forecast, so such roots are pulled onto radius 0.999
        roots = np.roots(np.r_[1.0, -coef[:p]])
        mag = np.abs(roots)
        if np.any(mag > 0.999):
            roots = np.where(mag > 0.999, roots / np.maximum(mag, 1e-12) * 0.999, roots)
            coef[:p] = -np.real(np.poly(roots))[1:]
        resid = z[p:] - X @ coef
        self.q_ = max(float(np.var(resid)), 1e-10)  # innovation variance of the AR model [m^2]
        self.coef_ = coef
        self._since_fit = 0

    def trajectory(self, t: float, n: int) -> np.ndarray:
        """Predicted (z, dz, ddz) at t + k dt, k = 0..n, as an (n+1, 3) array [m, m/s, m/s^2]."""
        times = t + self.dt * np.arange(n + 1)
        out = np.zeros((n + 1, 3))
        if self.coef_ is None or len(self.block_z) < self.order + 4:
            out[:, 0] = self.z_last
            return out
        p = self.order
        Tb = self.dt * self.decimate
        src = self.block_f
        hist = list(src[-p:])
        tb = list(self.block_t[-self.past_blocks:])
        zb = list(src[-self.past_blocks:])
        tnext = self.block_t[-1]
        while tnext < times[-1] + 2 * Tb:
            znew = float(np.dot(self.coef_[:p], hist[::-1][:p]) + self.coef_[p])
            hist.append(znew)
            hist = hist[-p:]
            tnext += Tb
            tb.append(tnext)
            zb.append(znew)
        # a least-squares polynomial through the recent block means and the forecast
        # (not an interpolant: it smooths the measurement noise before differentiating)
        tau = (np.asarray(tb) - t) / 2.0
        c = np.polyfit(tau, np.asarray(zb), self.poly_degree)
        tt = (times - t) / 2.0
        out[:, 0] = np.polyval(c, tt)
        out[:, 1] = np.polyval(np.polyder(c, 1), tt) / 2.0
        out[:, 2] = np.polyval(np.polyder(c, 2), tt) / 4.0
        return out


def seen_states(A, C) -> np.ndarray:
    """Indices of the states of x+ = A x, y = C x that the outputs see: directly (a nonzero column of
    ``C``) or through a seen state they drive (a nonzero entry of ``A`` in a seen state's row).  The others
    never reach an output: they span part of the unobservable subspace.

    Parameters
    ----------
    A : (n, n) array
        State transition.
    C : (m, n) array
        Output map.

    Returns
    -------
    numpy.ndarray
        Sorted indices of the seen states.
    """
    A, C = np.asarray(A), np.asarray(C)
    hidden = ~np.any(C != 0, axis=0)
    while hidden.any():
        drives = np.any(A[np.ix_(~hidden, hidden)] != 0, axis=0)  # a hidden state driving a seen one is seen
        if not drives.any():
            break
        hidden[np.flatnonzero(hidden)[drives]] = False
    return np.flatnonzero(~hidden)


class DisturbanceObserver:
    """Steady-state Kalman filter for x = [s, v, y_b, v_b] and the force disturbance d.

    Parameters
    ----------
    model : DiscreteModel
    sigma_y : (3,) array [m, Pa, N]
        Measurement noise std of stroke, pressure, WOB.
    sigma_d : float [N]
        Random-walk std of d per control interval (how fast friction may change).
    sigma_f : float [N]
        Unmodelled force noise on the top mass per interval.
    """

    def __init__(self, model, sigma_y=(1e-3, 5e3, 500.0), sigma_d: float = 8e3, sigma_f: float = 1e3):
        from scipy.linalg import solve_discrete_are

        self.model = model
        n = model.Ad.shape[0]
        A = np.zeros((n + 1, n + 1))
        A[:n, :n] = model.Ad
        A[:n, n:] = model.Bf
        A[n, n] = 1.0
        # measurements ordered like model.C rows: wob, stroke, pressure
        C = np.hstack([model.C, np.zeros((3, 1))])
        sy = np.asarray(sigma_y, dtype=float)
        R = np.diag([sy[2] ** 2, sy[0] ** 2, sy[1] ** 2])
        Gf = np.vstack([model.Bf, [[0.0]]])
        Q = sigma_f ** 2 * (Gf @ Gf.T) + np.diag([1e-10] * n + [sigma_d ** 2])
        # the filter corrects the states the outputs see; a state no output sees, directly or through the
        # states it drives (an effect's memory the linear model leaves out of the friction, e.g.
        # friction_memory's direction state: at rest an integrator of v), follows the model (gain rows 0):
        # with it in, (A, C) is not detectable and the Riccati equation has no solution
        k = seen_states(A, C)
        P = solve_discrete_are(A[np.ix_(k, k)].T, C[:, k].T, Q[np.ix_(k, k)], R)
        Ck = C[:, k]
        self.L = np.zeros((n + 1, C.shape[0]))
        self.L[k] = P @ Ck.T @ np.linalg.inv(Ck @ P @ Ck.T + R)
        self.A, self.Cm = A, C
        self.n = n
        self.reset()

    def reset(self):
        self.xa = np.zeros(self.n + 1)
        self._pending = None

    def predict(self, u: float, w: np.ndarray, f_ff: float) -> None:
        """Time update over one interval with input u [N], heave w = (z, dz, ddz) and friction f_ff [N]."""
        m = self.model
        self.xa = self.A @ self.xa
        self.xa[:self.n] += (m.Bu[:, 0] * u + m.Bw @ w + m.Bf[:, 0] * f_ff)

    def correct(self, y: np.ndarray, w: np.ndarray) -> None:
        """Measurement update with y = (wob, stroke, pressure) [N, m, Pa]."""
        m = self.model
        innov = y - m.y0 - (self.Cm @ self.xa + m.Dw @ w)
        self.xa = self.xa + self.L @ innov

    @property
    def x(self) -> np.ndarray:
        """State estimate (deviation) [m, m/s, m, m/s]."""
        return self.xa[:self.n]

    @property
    def d(self) -> float:
        """Estimated force disturbance on the top mass [N] (acts like friction)."""
        return float(self.xa[self.n])
