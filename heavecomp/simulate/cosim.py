"""The CMC as a co-simulation slave: heave in, WOB, stroke, pressure and friction out, step by step.

What ``heavecomp export-fmu`` packs into an FMU (:mod:`heavecomp.simulate.fmu`), usable from Python as
it is.  It runs the project's own compiled stepper (:func:`heavecomp.simulate.stepper.plant_stepper`:
exact stick-slip, the parameter file's plant effects at their hooks), from rest at the operating
point as :func:`heavecomp.simulate.simulate` starts.

A co-simulation master gives a slave its inputs at the communication points only.  Over a step
[t, t + H] the heave is the polynomial through the last :data:`HISTORY` inputs (cubic once four are in;
constant at the first), extrapolated over the step: for a wave of frequency omega it is off by about
(omega H)^4 of the heave's amplitude one step ahead (5e-6 m for 1 m at 8 s and H = 0.05 s).  Each
step is cut into RK4 steps of at most the default step (:func:`heavecomp.simulate.core.default_dt`),
with every stick-slip event located as in ``simulate``.  The heave is taken relative to its first
input, as ``simulate`` takes a heave file (first sample = reference).
"""

from __future__ import annotations

import math

import numpy as np

from heavecomp.effects.registry import split_effects
from heavecomp.effects.spec import effects_for
from heavecomp.errors import ParameterError
from heavecomp.plants.cmc import plant_vectors
from heavecomp.simulate.core import default_dt
from heavecomp.simulate.layout import CHANNELS, NCH, STATS, STUCK, Drive
from heavecomp.simulate.stepper import plant_stepper

#: inputs used for the heave polynomial over a step (4: a cubic)
HISTORY = 4
#: outputs of the slave: channel -> unit (the FMU's output variables)
OUTPUTS = {"wob": "N", "stroke": "m", "pressure": "Pa", "friction": "N", "stroke_velocity": "m/s", "tension": "N"}


class CoSimulator:
    """The CMC of ``params`` stepped by a master: :meth:`step` per communication step.

    Parameters
    ----------
    params : CMCParams
        The parameter set (its ``[[effects]]`` plant effects are run; ``[active]`` gives ``u_max``).
    effects : sequence, optional
        Effects instead of the file's (as :func:`heavecomp.simulate.simulate`'s ``effects``).
    dt : float [s], optional
        Largest RK4 step; default :func:`heavecomp.simulate.core.default_dt`.

    Raises
    ------
    ParameterError
        A heave or channel effect (it acts outside the plant: on what a sensor reads, not on what the
        FMU computes), named.
    """

    def __init__(self, params, effects=None, dt=None):
        plant_fx, heave_fx, sensor_fx = split_effects(effects_for(params, effects))
        other = [e.name for e in list(heave_fx) + list(sensor_fx)]
        if other:
            raise ParameterError(f"effect {other[0]}: acts on a measured reading, not on the plant; an FMU "
                                 "carries the plant's effects only (drop it from [[effects]] for the export)")
        self.params = params
        self.h_max = float(dt) if dt is not None else default_dt(params)
        active = params.extra.get("active")
        self.u_max = float(active.u_max) if active is not None else 0.0
        self._advance, self._state, self._plant = plant_stepper(plant_vectors(params), plant_fx)
        self._mode = np.array([float(STUCK), 1.0])
        self._stats = np.zeros(len(STATS))
        self._out = np.zeros((2, NCH))
        self._t: list = []
        self._z: list = []
        self.z_ref = None
        self._first_row()

    def _first_row(self):
        """The outputs at rest, before the first step (the stepper's row at t0)."""
        z = np.zeros(3)
        self._advance(self._state.copy(), self._mode.copy(), 0.0, 0, self.h_max, self._plant,
                      Drive(0.0, 0.5 * self.h_max, z, z, z), self._out, 1, 0, self._stats.copy())
        self._out[1] = self._out[0]

    @property
    def outputs(self) -> dict:
        """The channels at the end of the last step (SI, :data:`OUTPUTS`)."""
        return {k: float(self._out[1, CHANNELS.index(k)]) for k in OUTPUTS}

    def _heave(self, t: float, z: float, dz, ddz, H: float, sp: float, n: int):
        """(Z, DZ, DDZ) at 2n+1 points spaced ``sp`` from ``t``: the polynomial through the last inputs
        (with the heave's rates: the quintic through this and the previous (z, dz, ddz); without: the
        polynomial through the last :data:`HISTORY` heave values), extrapolated over the step."""
        if self.z_ref is None:
            self.z_ref = z
        if self._t and t <= self._t[-1]:  # a step repeated from the same time (no state rollback): keep one
            del self._t[-1], self._z[-1]
        rates = dz is not None
        self._t.append(t)
        self._z.append((z - self.z_ref, float(dz) if rates else 0.0, float(ddz) if rates else 0.0))
        del self._t[:-HISTORY], self._z[:-HISTORY]
        s0 = (np.asarray(self._t) - t) / H  # the inputs' times in units of H (the last one 0)
        if rates:  # conditions on p, p', p'' at the last two inputs (the last one alone at the first step)
            pts = list(zip(s0[-2:], self._z[-2:]))
            rows, rhs = [], []
            for sk, (zk, dk, ak) in pts:
                for order, val in ((0, zk), (1, dk * H), (2, ak * H * H)):
                    rows.append(_basis_row(sk, order, 3 * len(pts)))
                    rhs.append(val)
        else:
            m = len(s0)
            rows = [_basis_row(sk, 0, m) for sk in s0]
            rhs = [zk for zk, _d, _a in self._z]
        c = np.linalg.solve(np.array(rows), np.array(rhs))
        s = np.arange(2 * n + 1) * sp / H  # the step's points in units of H
        p = np.polynomial.polynomial
        return (p.polyval(s, c), p.polyval(s, p.polyder(c)) / H, p.polyval(s, p.polyder(c, 2)) / H ** 2)

    def step(self, t: float, H: float, heave: float, u_active: float = 0.0, heave_velocity=None,
             heave_acceleration=None) -> dict:
        """Advance from ``t`` by ``H`` with the heave ``heave`` [m] at ``t`` (and the active force [N]).

        Parameters
        ----------
        t : float [s]
            The communication point (the start of the step).
        H : float [s]
            The communication step (> 0).
        heave : float [m]
            Platform heave at ``t``.
        u_active : float [N]
            Active-cylinder force at ``t``, held over the step (clipped to the ``[active]`` table's
            ``u_max``; 0 without ``[active]``).
        heave_velocity, heave_acceleration : float [m/s], [m/s^2], optional
            The heave's rates at ``t`` (an MRU measures them): the heave over the step is then the
            quintic through this step's and the last step's (z, dz, ddz), which keeps the heave
            acceleration, and so the static friction's reaction and the breakaway times, as the
            record's.  Both or neither.

        Returns
        -------
        dict
            :attr:`outputs` at ``t + H``.
        """
        if not (H > 0 and math.isfinite(H)):
            raise ParameterError(f"communication step must be a positive number of seconds, got {H}")
        if (heave_velocity is None) != (heave_acceleration is None):
            raise ParameterError("heave_velocity and heave_acceleration: give both or neither")
        n = max(1, int(math.ceil(H / self.h_max - 1e-9)))
        h = H / n
        Z, DZ, DDZ = self._heave(float(t), float(heave), heave_velocity, heave_acceleration, H, 0.5 * h, n)
        u = float(np.clip(u_active, -self.u_max, self.u_max))
        self._advance(self._state, self._mode, 0.0, n, h, self._plant, Drive(u, 0.5 * h, Z, DZ, DDZ), self._out,
                      n, 1, self._stats)
        return self.outputs

    @property
    def stats(self) -> dict:
        """The stepper's counters so far (:data:`heavecomp.simulate.layout.STATS`)."""
        return dict(zip(STATS, self._stats.tolist()))


def _basis_row(s: float, order: int, m: int) -> list:
    """The row of the ``order``-th derivative of the monomials 1, s, ..., s^(m-1) at ``s``."""
    row = []
    for j in range(m):
        if j < order:
            row.append(0.0)
        else:
            coef = math.prod(range(j - order + 1, j + 1))
            row.append(coef * s ** (j - order))
    return row
