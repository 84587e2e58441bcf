"""One drawn sea with its clean truth runs: simulate planted laws and measure their own gap
against the noise floor of the run."""

from __future__ import annotations

import math

import numpy as np

from heavecomp.benchmark.sea import make_sea
from heavecomp.benchmark.truth import truth_composition
from heavecomp.diagnosis.data import heave_samples, MeasuredRun
from heavecomp.diagnosis.stepper import CHANNELS as SC, run_fx, step_within
from heavecomp.plants.cmc import plant_vectors


def truth_dt(nominal, rate: float | None = None) -> float:
    """RK4 step of the generated truth [s]: h * lambda_max <= 0.25 and at most 10 ms (a divisor of the
    log's interval 1/rate).  Finer than the diagnosis' replay step
    (:func:`heavecomp.diagnosis.stepper.replay_dt`, at most 20 ms): a rig's plant is continuous, so
    the replay's own discretisation error is part of the gap the diagnosis sees here, as on a real log
    (0.4 N rms of WOB and 0.05 Pa of pressure on the paper-A plant, against a noise floor of hundreds of N
    and kPa, ``docs/numerics.md``).

    Parameters
    ----------
    nominal : heavecomp.params.CMCParams
        The nominal plant (its fastest eigen-rate bounds the step).
    rate : float [Hz], optional
        Logging rate the step must divide; None: any step.
    """
    return step_within(nominal, 0.01, rate)

NOISE = {"heave": 0.002, "stroke": 0.002, "pressure": 2e3, "wob": 400.0}  #: 1-sigma sensor noise [SI]
OUT = ("stroke", "pressure", "wob")  #: the channels the plant answers with


class Testbed:
    """A drawn sea on the nominal plant, with its clean no-effect run, noise floor and stick statistics.

    Parameters
    ----------
    nominal : heavecomp.params.CMCParams
        The nominal parameters (the truth model's, before any planted law).
    rng : numpy.random.Generator
        The case's stream: draws the sea, then the heave noise.
    duration : float [s]
    rate : float [Hz]
        Logging rate.
    sea : str
        Kind of sea (:func:`heavecomp.benchmark.sea.make_sea`).
    noise : float [-]
        Sensor noise as a multiple of :data:`NOISE`.
    """

    __test__ = False  # not a pytest class

    OUT = OUT

    def __init__(self, nominal, rng, duration, rate, sea, noise):
        self.nominal = nominal
        self.noise = {c: noise * v for c, v in NOISE.items()}
        self.h = h = truth_dt(nominal, rate)
        self.out_every = max(1, int(round(1.0 / (rate * h))))
        self.n_steps = int(math.ceil(duration / h - 1e-9))
        self.hs, self.info = make_sea(sea, rng, self.n_steps * h, 0.5 * h)
        self._rep_clean = None
        self.t, self.base, grid = self.sim([], grid=True)
        self.heave_noise = rng.normal(0.0, self.noise["heave"], self.t.size)
        self.mask = self.t >= min(30.0, 0.1 * duration)  # the diagnosis' default settling window
        self.floor = self._floor()
        stuck = grid[:, SC.index("stuck")] > 0.5
        edges = np.diff(np.r_[0, stuck.astype(int), 0])
        dwell = (np.flatnonzero(edges == -1) - np.flatnonzero(edges == 1)) * (self.t[1] - self.t[0])
        self.stick = {"stuck_share": float(stuck.mean()), "stick_phases": int(dwell.size),
                      "median_dwell": float(np.median(dwell)) if dwell.size else 0.0}

    def sim(self, parts, hs=None, grid=False):
        """Clean channels of the truth model with the planted ``parts``
        (:class:`heavecomp.benchmark.truth.Part`), driven by this sea or by ``hs``.

        Returns
        -------
        (t, cols) or (t, cols, grid)
            Time [s], channel -> array [SI] (``heave`` and :data:`OUT`, plus what an output law adds),
            and the stepper's full output grid.
        """
        effects = []
        prm = self.nominal
        post = []
        for part in parts:
            effects += part.effects
            if part.changes is not None:
                prm = prm.replace(**part.changes)
            elif part.output is not None:
                post.append(part)
        comps = {truth_composition(e.name) for e in effects}
        if len(comps) > 1:
            raise ValueError(f"truth laws {[e.name for e in effects]} live in different compositions")
        comp = comps.pop() if comps else truth_composition()
        out = run_fx(plant_vectors(prm), comp, comp.ep(effects), self.hs if hs is None else hs, self.h,
                     self.n_steps, self.out_every)
        t = out[:, 0].copy()
        cols = {c: out[:, SC.index(c)].copy() for c in ("heave",) + self.OUT}
        for part in post:
            cols = part.output(t, cols, **part.parameters)
        return (t, cols, out) if grid else (t, cols)

    def heave_samples(self, heave):
        """The heave samples the diagnosis replays from a logged ``heave`` [m] on this run's clock."""
        return heave_samples(MeasuredRun(self.t, {"heave": heave}), self.h, self.n_steps)

    def rep_clean(self):
        """The nominal model replayed from the clean heave through the diagnosis' heave pre-processing."""
        if self._rep_clean is None:
            self._rep_clean = self.sim([], hs=self.heave_samples(self.base["heave"]))[1]
        return self._rep_clean

    def _floor(self):
        """Noise floor per channel [SI]: the output noise and the residual of the nominal model replayed
        from this run's noisy, filtered heave (what a run with no effect shows to the diagnosis; exact
        stiction makes it well above the sensor noise), in quadrature."""
        _, rep = self.sim([], hs=self.heave_samples(self.base["heave"] + self.heave_noise))
        m = self.mask
        return {c: float(math.hypot(self.noise[c], np.sqrt(np.mean((rep[c][m] - self.base[c][m]) ** 2))))
                for c in self.OUT}

    def gap(self, parts):
        """Own gap of planted ``parts``: per channel rms(with - without) / noise floor [-], and the
        largest channel's ratio in the weaker half of the run (an effect that shows in one burst
        only cannot be fitted on one part of the run and checked on the other)."""
        _, cols = self.sim(parts)
        heave = [p for p in parts if p.on_heave]
        if heave:  # a wrong heave signal: what the diagnosis sees is the replay from it
            _, rep = self.sim([p for p in parts if not p.on_heave], hs=self.heave_samples(cols["heave"]))
            cols = {c: cols[c] + rep[c] - self.rep_clean()[c] for c in self.OUT}
        m = self.mask
        mid = 0.5 * (self.t[m][0] + self.t[-1])

        def ratio(k):
            return {c: float(np.sqrt(np.mean((cols[c][k] - self.base[c][k]) ** 2)) / self.floor[c]) for c in self.OUT}

        return ratio(m), min(max(ratio(m & (self.t < mid)).values()), max(ratio(self.t >= mid).values()))
