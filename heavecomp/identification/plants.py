"""The 1-DOF axis (EMPS) and the O-ring seal rig as plants of the equation-error diagnosis.

A plant here is what the diagnosis needs of a measured record, whatever the machine:

- ``sig``: the measured signals the effects' :meth:`~heavecomp.effects.base.Effect.features` are
  built from (``t`` [s], ``x`` [m], ``v`` [m/s], ``a`` [m/s^2], ``dwell`` [s], ``p`` [Pa] where the
  plant has a pressure);
- ``y``: the friction component's residual at the regression samples, measured friction minus the
  nominal model's friction [N];
- ``base``, ``base_names``: the nominal model's linear parameters as columns (refitted with every
  candidate; a withheld term is left out), ``nominal`` their nominal values;
- :meth:`features`: an effect's columns at the regression samples;
- :meth:`mask`: the samples of a time window (fit / validate parts);
- ``v_s``, ``x_s``, ``a_s``: velocity, position, acceleration at the regression samples (for "where"),
  ``sig_s`` the signals there (for the open search, :func:`heavecomp.diagnosis.equation_error.open_search`).

Both plants use the same Effect classes and the same feature columns (one candidate abstraction,
issue 11 item 5); they differ only in how the friction is measured.
"""

from __future__ import annotations

import numpy as np

from heavecomp.effects.features import dwell_time
from heavecomp.errors import ParameterError
from heavecomp.identification.inverse import AxisRegression
from heavecomp.identification.seal import BORE_AREA, SealRecord, strokes, velocity_fir
from heavecomp.plants.axis import BASE_NAMES, EMPS_PUBLISHED

#: EMPS inverse-model parameters under their names in the friction language of the effects
#: (``parameter_mismatch``'s features are named by the same keys); the offset F_off is the
#: direction asymmetry of the Coulomb force while the axis moves (``heavecomp.plants.axis``)
AXIS_TERMS = {"mass": "mass", "viscous": "friction.viscous_coefficient", "coulomb": "friction.coulomb_force",
              "offset": "direction_offset"}
#: units of the axis terms
AXIS_UNITS = {"mass": "kg", "friction.viscous_coefficient": "N s/m", "friction.coulomb_force": "N",
              "direction_offset": "N"}
#: O-ring seal nominal, the ``split`` fit of :class:`heavecomp.identification.seal.SealFrictionFit`:
#: F_f = sign(v) (F_C + C_p p) + F_0 + C_0 p
SEAL_TERMS = ("friction.coulomb_force", "friction.pressure_coefficient", "direction_offset",
              "direction_offset_pressure")
SEAL_UNITS = {"friction.coulomb_force": "N", "friction.pressure_coefficient": "N/Pa", "direction_offset": "N",
              "direction_offset_pressure": "N/Pa"}


def _check_withheld(withheld, known):
    for w in withheld:
        if w not in known:
            raise ParameterError(f"withheld term {w!r} is not a term of the nominal model; terms: {', '.join(known)}")


class _Plant:
    """Common part: least-squares pieces and time masks."""

    name = ""
    units: dict = {}

    def mask(self, window=None) -> np.ndarray:
        """Regression samples with ``window[0] <= t < window[1]`` [s] (None: all)."""
        if window is None:
            return np.ones(self.t.size, dtype=bool)
        return (self.t >= window[0]) & (self.t < window[1])


class AxisFriction(_Plant):
    """The EMPS axis: friction = motor force - M q''; nominal F_v q' + F_c sign(q') + F_off.

    Parameters
    ----------
    reg : AxisRegression
        Filtered, decimated record (:mod:`heavecomp.identification.inverse`).
    nominal : dict
        Inverse-model parameters by :data:`~heavecomp.plants.axis.BASE_NAMES` (default: published).
    withheld : tuple of str
        Terms of ``BASE_NAMES`` the nominal model lacks: their value is 0 and their column is not
        refitted (the withheld-term check of issue 12 item 7).
    dead_band : float, m/s
        |v| at or below this counts as rest (``dwell``).

    Notes
    -----
    Features are built at the full rate and decimated in parallel with the force (the way the
    EMPS regression treats every column).  Mass and the nominal parameters are refitted with every
    candidate, so with nothing withheld the residual is that of the least-squares EMPS model.
    """

    name = "EMPS axis"
    units = AXIS_UNITS

    def __init__(self, reg: AxisRegression, nominal=None, withheld=(), dead_band: float = 0.005):
        nominal = dict(EMPS_PUBLISHED if nominal is None else nominal)
        _check_withheld(withheld, BASE_NAMES)
        self.reg, self.withheld = reg, tuple(withheld)
        theta = np.array([0.0 if k in withheld else float(nominal[k]) for k in BASE_NAMES])
        X = reg.base_matrix().copy()
        i = BASE_NAMES.index("offset")
        X[:, i] = _exact_constant(X[:, i])
        keep = [i for i, k in enumerate(BASE_NAMES) if k not in withheld]
        self.t = reg.t_d
        self.y = reg.force_d - X @ theta
        self.base = X[:, keep]
        self.base_names = [AXIS_TERMS[BASE_NAMES[i]] for i in keep]
        self.nominal = {AXIS_TERMS[k]: float(theta[i]) for i, k in enumerate(BASE_NAMES)}
        self.sig = {"t": reg.record.t, "x": reg.q, "v": reg.dq, "a": reg.ddq,
                    "dwell": dwell_time(reg.record.t, reg.dq, dead_band)}
        self.v_s, self.x_s, self.a_s = reg.dq_d, reg.q_d, reg.ddq_d
        self.sig_s = {"t": reg.t_d, "x": reg.q_d, "v": reg.dq_d, "a": reg.ddq_d}

    def features(self, effect, shape=None):
        cols = effect.features(self.sig, shape)
        return None if cols is None else {k: _exact_constant(self.reg.decimate(c)) for k, c in cols.items()}


def _exact_constant(c: np.ndarray) -> np.ndarray:
    """A column the decimation filter left constant to rounding (the offset's ones, |sign v| while
    always moving) made exactly constant: a spread of 1e-16 must not count as signal (the engine
    scales each column by its spread).  Its value (the filter's DC gain, 0.9886 for the EMPS
    decimation, applied alike to the force) is rounded to 2^-20 so that its mean, and so its
    spread, is exact (a change of < 1e-6 relative)."""
    m = float(np.max(np.abs(c))) if c.size else 0.0
    if m > 0 and float(np.std(c)) < 1e-12 * m:
        return np.full(c.size, round(float(np.mean(c)) * 2 ** 20) / 2 ** 20)
    return c


class SealFriction(_Plant):
    """The O-ring seal rig: friction F_f = force - p A on the steady strokes of several files.

    Parameters
    ----------
    records : list of SealRecord
        Constant-pressure files (:func:`heavecomp.identification.seal.load_seal_csv`).
    nominal : dict
        Values of :data:`SEAL_TERMS` (e.g. from :class:`~heavecomp.identification.seal.SealFrictionFit`'s
        ``split`` fit: ``F_C``, ``C_p``, ``F_0``, ``C_0``).
    withheld : tuple of str
        Terms of :data:`SEAL_TERMS` the nominal lacks.
    v_min, trim : float
        Steady-sliding selection of :func:`~heavecomp.identification.seal.strokes` (m/s, fraction).
    area : float, m^2
        Piston area of F_f = force - p A (default the rig's bore).

    Notes
    -----
    The regression samples are those of the steady strokes (both directions); every file's time
    starts at 0, so a window ``(0, 45)`` s fits the first 45 s of every file.  The features run
    over each whole file (a lag needs the history) on the velocity of paper B's FIR derivative, and
    are then cut to the steady samples.
    """

    name = "O-ring seal rig"
    units = SEAL_UNITS

    def __init__(self, records, nominal: dict, withheld=(), v_min: float = 2e-3, trim: float = 0.2,
                 area: float = BORE_AREA):
        _check_withheld(withheld, SEAL_TERMS)
        self.withheld = tuple(withheld)
        self.nominal = {k: 0.0 if k in withheld else float(nominal[k]) for k in SEAL_TERMS}
        self.sigs, self.keep = [], []
        t, y, v, x, a, p_s, t_run, base = [], [], [], [], [], [], [], []
        elapsed = 0.0
        for rec in records:
            if not isinstance(rec, SealRecord):
                raise ParameterError(f"SealFriction needs SealRecord objects, got {type(rec).__name__}")
            vf = velocity_fir(rec.t, rec.x)
            sig = {"t": rec.t - rec.t[0], "x": rec.x, "v": vf, "a": np.gradient(vf, rec.t), "p": rec.p,
                   "dwell": dwell_time(rec.t, vf, v_min)}
            sel = np.zeros(rec.t.size, dtype=bool)
            for s in strokes(rec, v_min, trim, area=area):
                sel |= (rec.t >= s["t0"]) & (rec.t <= s["t1"])
            d = np.sign(vf[sel])
            p = rec.p[sel]
            cols = {"friction.coulomb_force": d, "friction.pressure_coefficient": d * np.abs(p),
                    "direction_offset": np.ones_like(p), "direction_offset_pressure": p}
            f_nom = sum(self.nominal[k] * c for k, c in cols.items())
            self.sigs.append(sig)
            self.keep.append(sel)
            t.append(sig["t"][sel])
            y.append(rec.friction(area)[sel] - f_nom)
            v.append(vf[sel])
            x.append(rec.x[sel])
            a.append(sig["a"][sel])
            p_s.append(p)
            t_run.append(sig["t"][sel] + elapsed)
            elapsed += float(sig["t"][-1]) + 1.0
            base.append(np.column_stack([c for k, c in cols.items() if k not in withheld]))
        self.t, self.y, self.v_s, self.x_s, self.a_s = (np.concatenate(z) for z in (t, y, v, x, a))
        self.base = np.vstack(base)
        # the regression samples for the open search, files one after the other on one clock
        self.sig_s = {"t": np.concatenate(t_run), "x": self.x_s, "v": self.v_s, "a": self.a_s,
                      "p": np.concatenate(p_s)}
        self.base_names = [k for k in SEAL_TERMS if k not in withheld]

    def features(self, effect, shape=None):
        out = {}
        for sig, sel in zip(self.sigs, self.keep):
            cols = effect.features(sig, shape)
            if cols is None:
                return None
            for k, c in cols.items():
                out.setdefault(k, []).append(np.asarray(c)[sel])
        return {k: np.concatenate(c) for k, c in out.items()}
