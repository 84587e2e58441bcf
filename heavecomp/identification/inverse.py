"""Inverse-model least squares for a 1-DOF axis (EMPS benchmark).

    F = M q'' + F_v q' + F_c sign(q') + F_off        (Janot, Gautier, Brunot 2019)

The model is linear in its parameters, so after filtering (see
:mod:`heavecomp.identification.filtering`) the parameters follow from one
ordinary least-squares solve.  :class:`AxisRegression` holds the filtered
signals once, so that any candidate term can be added as a further column
(filtered in parallel exactly like the base columns).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from heavecomp.errors import ParameterError
from heavecomp.identification.filtering import derivatives, parallel_decimate
from heavecomp.plants.axis import BASE_NAMES, AxisRecord

log = logging.getLogger(__name__)


@dataclass
class LSResult:
    """Ordinary least squares: estimate, standard errors, residual sum of squares."""

    theta: np.ndarray
    stderr: np.ndarray
    rss: float
    n: int

    @property
    def rms(self) -> float:
        return float(np.sqrt(self.rss / self.n))


def least_squares(X, y) -> LSResult:
    """theta = argmin |y - X theta|^2 with the classical standard errors
    sqrt(diag(sigma^2 (X^T X)^-1)), sigma^2 = RSS / (n - k).

    The standard errors assume independent residuals; after decimation the
    residual of a real record is still correlated, so read them as a lower bound.

    Parameters
    ----------
    X : (n, k) array
        Regressor matrix (columns in the units that make ``X theta`` a force [N]).
    y : (n,) array
        Measured output (e.g. motor force [N]); needs n > k.
    """
    X = np.asarray(X, dtype=float)
    y = np.asarray(y, dtype=float)
    n, k = X.shape
    if n <= k:
        raise ParameterError(f"least squares needs more samples ({n}) than parameters ({k})")
    theta, *_ = np.linalg.lstsq(X, y, rcond=None)
    r = y - X @ theta
    rss = float(r @ r)
    sigma2 = rss / (n - k)
    cov = sigma2 * np.linalg.pinv(X.T @ X)
    return LSResult(theta=theta, stderr=np.sqrt(np.maximum(np.diag(cov), 0.0)), rss=rss, n=n)


class AxisRegression:
    """Filtered, differentiated and (in parallel) decimated signals of one record.

    Parameters
    ----------
    record : AxisRecord
        Measured run.
    cutoff : float, Hz
        Butterworth cut-off for the position before differentiation.
    order : int
        Butterworth order.
    decimate : int
        Decimation factor of the parallel filter.

    Attributes
    ----------
    q, dq, ddq : ndarray
        Filtered position [m], velocity [m/s], acceleration [m/s^2] at the full rate.
    t_d, q_d, dq_d, ddq_d, force_d : ndarray
        The same (and the force [N]) after parallel decimation.
    """

    def __init__(self, record: AxisRecord, cutoff: float = 50.0, order: int = 4, decimate: int = 10):
        if int(decimate) < 1 or int(decimate) != decimate:
            raise ParameterError(f"decimate must be a positive integer, got {decimate}")
        self.record = record
        self.fs = record.fs
        self.cutoff, self.order, self.factor = float(cutoff), int(order), int(decimate)
        self.q, self.dq, self.ddq = derivatives(record.q, self.fs, self.cutoff, self.order)
        self.t_d = record.t[:: self.factor]
        self.q_d = self.decimate(self.q)
        self.dq_d = self.decimate(self.dq)
        self.ddq_d = self.decimate(self.ddq)
        self.force_d = self.decimate(record.force)

    def decimate(self, x) -> np.ndarray:
        """Parallel filter + decimation of one full-rate column."""
        return parallel_decimate(x, self.factor)

    def base_columns(self) -> list[np.ndarray]:
        """Full-rate regressors of the EMPS model: q'', q', sign(q'), 1."""
        return [self.ddq, self.dq, np.sign(self.dq), np.ones_like(self.dq)]

    def matrix(self, columns) -> np.ndarray:
        """Decimated regression matrix from full-rate columns."""
        return np.column_stack([self.decimate(c) for c in columns])

    def base_matrix(self) -> np.ndarray:
        if not hasattr(self, "_base"):
            self._base = self.matrix(self.base_columns())
        return self._base

    def mask(self, window=None) -> np.ndarray:
        """Boolean mask of decimated samples with ``window[0] <= t < window[1]`` [s]."""
        if window is None:
            return np.ones(self.t_d.size, dtype=bool)
        t0, t1 = window
        return (self.t_d >= t0) & (self.t_d < t1)


class InverseModelLS:
    """Identify M, F_v, F_c, F_off of the EMPS inverse model by least squares.

    Parameters
    ----------
    cutoff : float, Hz
        Butterworth cut-off of the position filter (default 50 Hz at 1 kHz).
    order : int
        Butterworth order (default 4, applied forward and backward).
    decimate : int
        Parallel-filter decimation factor (default 10: 1 kHz -> 100 Hz, decimation
        low-pass at 40 Hz).

    Attributes
    ----------
    params_ : dict
        ``mass`` [kg], ``viscous`` [N s/m], ``coulomb`` [N], ``offset`` [N].
    stderr_ : dict
        Classical least-squares standard errors (same keys; a lower bound, see
        :func:`least_squares`).
    rms_ : float
        Root-mean-square force residual on the fitted samples [N].
    regression_ : AxisRegression
        The filtered signals (reuse them to add candidate terms).
    window_ : tuple or None
        Time window fitted [s] (None = whole record).

    Notes
    -----
    F = M q'' + F_v q' + F_c sign(q') + F_off, EMPS benchmark (Janot et al. 2019),
    solved by ordinary least squares on the parallel-filtered, decimated samples.
    """

    def __init__(self, cutoff: float = 50.0, order: int = 4, decimate: int = 10):
        self.cutoff, self.order, self.decimate = cutoff, order, decimate

    def fit(self, record: AxisRecord | AxisRegression, window=None) -> "InverseModelLS":
        reg = record if isinstance(record, AxisRegression) else AxisRegression(
            record, self.cutoff, self.order, self.decimate)
        m = reg.mask(window)
        res = least_squares(reg.base_matrix()[m], reg.force_d[m])
        self.regression_, self.window_, self.result_ = reg, window, res
        self.theta_ = res.theta
        self.params_ = dict(zip(BASE_NAMES, map(float, res.theta)))
        self.stderr_ = dict(zip(BASE_NAMES, map(float, res.stderr)))
        self.rms_ = res.rms
        log.info("EMPS inverse model (cutoff %g Hz, decimate %d): %s", reg.cutoff, reg.factor,
                 ", ".join(f"{k} = {v:.4g}" for k, v in self.params_.items()))
        return self

    def predict(self, window=None) -> np.ndarray:
        """Model force [N] on the decimated samples of ``window``."""
        reg = self.regression_
        return reg.base_matrix()[reg.mask(window)] @ self.theta_

    def residual(self, window=None) -> np.ndarray:
        """Measured minus model force [N] on the decimated samples of ``window``."""
        reg = self.regression_
        return reg.force_d[reg.mask(window)] - self.predict(window)


def cutoff_sensitivity(record: AxisRecord, cutoffs, decimate: int = 10, order: int = 4) -> dict:
    """Estimates vs Butterworth cut-off: ``{"cutoff": [...], "mass": [...], ...}``.

    Parameters
    ----------
    record : AxisRecord
        The measured axis run (:func:`heavecomp.plants.axis.load_emps`).
    cutoffs : sequence of float [Hz]
        Butterworth cut-offs of the position filter to try.
    decimate : int
        Decimation factor of the parallel filter (1: none).
    order : int
        Butterworth order.
    """
    out = {"cutoff": [float(c) for c in cutoffs], **{k: [] for k in BASE_NAMES}}
    for c in cutoffs:
        est = InverseModelLS(cutoff=c, order=order, decimate=decimate).fit(record)
        for k in BASE_NAMES:
            out[k].append(est.params_[k])
    return out
