"""One-degree-of-freedom axis with friction: the EMPS benchmark plant.

The electro-mechanical positioning system (EMPS) of Janot, Gautier and Brunot
(2019) is a prismatic axis driven by a motor through a ball screw, position
controlled by a PD loop.  Its published inverse dynamic model is

    F = M q'' + F_v q' + F_c sign(q') + F_off                      (EMPS eq.)

with ``F = g_tau * v_ir`` the motor force on the load [N], ``q`` the measured
position [m], ``M`` the moving mass [kg], ``F_v`` the viscous coefficient
[N s/m], ``F_c`` the Coulomb force [N] and ``F_off`` a constant offset [N]
(amplifier offset and/or friction asymmetry: with the axis moving,
``F_off + F_c sign(q')`` is the same as an asymmetric Coulomb force
``F_c+ = F_c + F_off``, ``F_c- = F_c - F_off``).

The equations are written once, as scalar ``np.*`` functions (usable on
numpy arrays, by numba and by casadi).  :func:`load_emps` reads the benchmark
file into an :class:`AxisRecord`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from heavecomp.errors import DataError
from heavecomp.io.series import short

#: Published inverse-model parameters of the EMPS benchmark (Janot et al. 2019), SI.
EMPS_PUBLISHED = {"mass": 95.1089, "viscous": 203.5034, "coulomb": 20.3935, "offset": -3.1648}
#: Units of the inverse-model parameters.
EMPS_UNITS = {"mass": "kg", "viscous": "N s/m", "coulomb": "N", "offset": "N"}
#: Order of the base regressors / parameters.
BASE_NAMES = ("mass", "viscous", "coulomb", "offset")


def inverse_force(ddq, dq, M, Fv, Fc, Foff):
    """Motor force of the 1-DOF axis inverse model [N] (EMPS eq.).

    Parameters
    ----------
    ddq : float or array, m/s^2
        Acceleration q''.
    dq : float or array, m/s
        Velocity q'.
    M : float, kg
        Moving mass.
    Fv : float, N s/m
        Viscous coefficient.
    Fc : float, N
        Coulomb friction force.
    Foff : float, N
        Constant force offset.

    Notes
    -----
    F = M q'' + F_v q' + F_c sign(q') + F_off (Janot, Gautier, Brunot 2019).
    """
    return M * ddq + Fv * dq + Fc * np.sign(dq) + Foff


def friction_force(dq, Fv, Fc, Foff):
    """Friction plus offset of the EMPS inverse model [N]: F_v q' + F_c sign(q') + F_off.

    Parameters
    ----------
    dq : float or array [m/s]
        Velocity q'.
    Fv : float [N s/m]
        Viscous coefficient.
    Fc : float [N]
        Coulomb friction force.
    Foff : float [N]
        Constant force offset.
    """
    return Fv * dq + Fc * np.sign(dq) + Foff


def forward_accel(dq, F, M, Fv, Fc, Foff):
    """Acceleration q'' [m/s^2] of the axis under motor force ``F`` [N] while sliding.

    Parameters
    ----------
    dq : float or array [m/s]
        Velocity q' (non-zero: sliding).
    F : float or array [N]
        Motor force on the load.
    M : float [kg]
        Moving mass.
    Fv : float [N s/m]
        Viscous coefficient.
    Fc : float [N]
        Coulomb friction force.
    Foff : float [N]
        Constant force offset.

    Notes
    -----
    q'' = (F - F_v q' - F_c sign(q') - F_off) / M — the EMPS inverse model solved
    for q''.  Valid while sliding (q' != 0); sticking needs an event-based stepper.
    """
    return (F - friction_force(dq, Fv, Fc, Foff)) / M


@dataclass(frozen=True)
class AxisRecord:
    """A measured run of a 1-DOF axis (SI units, uniform sampling).

    Attributes
    ----------
    t : ndarray, s
        Time, uniform.
    q : ndarray, m
        Measured position.
    force : ndarray, N
        Motor force on the load.
    q_ref : ndarray or None, m
        Reference position of the position loop.
    name : str
        Where the record came from.
    """

    t: np.ndarray
    q: np.ndarray
    force: np.ndarray
    q_ref: np.ndarray | None = None
    name: str = ""

    @property
    def fs(self) -> float:
        """Sampling rate [Hz]."""
        return float(1.0 / np.median(np.diff(self.t)))

    def __len__(self) -> int:
        return len(self.t)


def _column(data: dict, key: str, path: str) -> np.ndarray:
    if key not in data:
        raise DataError(f"{path}: missing variable '{key}'")
    x = np.asarray(data[key], dtype=float).ravel()
    if not np.all(np.isfinite(x)):
        i = int(np.flatnonzero(~np.isfinite(x))[0])
        raise DataError(f"{path}: variable '{key}' is not finite at sample {i}")
    return x


def load_emps(path) -> AxisRecord:
    """Read the EMPS benchmark file (MATLAB v5: ``t``, ``qm``, ``qg``, ``vir``, ``gtau``).

    Parameters
    ----------
    path : str or Path
        ``DATA_EMPS.mat``.

    Returns
    -------
    AxisRecord
        ``force = gtau * vir`` [N], ``q = qm`` [m], ``q_ref = qg`` [m].

    Raises
    ------
    DataError
        Missing file or variable, non-finite samples, mismatched lengths or a
        non-increasing / non-uniform time vector (one line naming the variable).
    """
    import scipy.io


    path = Path(path)
    try:
        found = path.is_file()
    except OSError as exc:  # e.g. a file name too long for the file system
        raise DataError(f"{short(path)}: cannot read ({exc.strerror or type(exc).__name__})") from None
    if not found:
        raise DataError(f"{short(path)}: no such file")
    try:
        data = scipy.io.loadmat(str(path))
    except Exception as exc:  # scipy raises several types for a bad file
        raise DataError(f"{path}: not a MATLAB file ({type(exc).__name__})") from None
    t = _column(data, "t", str(path))
    qm = _column(data, "qm", str(path))
    vir = _column(data, "vir", str(path))
    gtau = _column(data, "gtau", str(path))
    qg = _column(data, "qg", str(path)) if "qg" in data else None
    if gtau.size != 1 or not gtau[0] > 0:
        raise DataError(f"{path}: variable 'gtau' must be one positive number [N/V]")
    for key, x in (("qm", qm), ("vir", vir)) + ((("qg", qg),) if qg is not None else ()):
        if x.size != t.size:
            raise DataError(f"{path}: variable '{key}' has {x.size} samples, 't' has {t.size}")
    dt = np.diff(t)
    if t.size < 10 or np.any(dt <= 0):
        raise DataError(f"{path}: variable 't' must be strictly increasing (at least 10 samples)")
    if np.max(np.abs(dt - np.median(dt))) > 0.01 * np.median(dt):
        raise DataError(f"{path}: variable 't' is not uniformly sampled (1 % tolerance)")
    return AxisRecord(t=t, q=qm, force=gtau[0] * vir, q_ref=qg, name=path.name)
