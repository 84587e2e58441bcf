"""One run from one case: :func:`generate`."""

from __future__ import annotations

import dataclasses

import numpy as np

from heavecomp.benchmark.case import Case, parameter_sets
from heavecomp.benchmark.sizing import energy, NEAR_NOISE, plant, SECOND_SHARE
from heavecomp.benchmark.testbed import Testbed
from heavecomp.benchmark.truth import COMPONENT, LAWS, Setting
from heavecomp.diagnosis.data import check_run

PITCH_NOISE = 2e-4  #: 1-sigma noise of a logged pitch angle [rad]


@dataclasses.dataclass
class TestRun:
    """A generated run: arrays, the nominal parameters to diagnose against, and the truth.

    Attributes
    ----------
    t : numpy.ndarray [s]
    columns : dict
        Logged channel -> array [SI] (``heave``, ``stroke``, ``pressure``, ``wob``, maybe ``pitch``).
    nominal : heavecomp.params.CMCParams
        The nominal parameters the diagnosis is given.
    truth : dict
        What was planted (:func:`generate`).
    replays : dict or None
        Clean replays from the logged heave of the nominal model (``nominal``) and of the true model
        (``truth``), channel -> array, for :meth:`true_shrink`.
    rng : numpy.random.Generator or None
        The case's random stream after the run was made: a post-processing step (a corrupted log,
        :mod:`heavecomp.benchmark.corrupt`) continues it, so its run is reproducible from the case.
    """

    __test__ = False  # not a pytest class

    t: np.ndarray
    columns: dict
    nominal: object
    truth: dict
    replays: dict | None = None
    rng: np.random.Generator | None = None

    def to_run(self):
        """The run as the diagnosis reads it (:class:`heavecomp.diagnosis.MeasuredRun`)."""
        return check_run(self.t, self.columns, params=self.nominal, source=f"generated:{self.truth['label']}")

    def to_csv(self, path):
        """Write the run as a contract CSV (SI units) to ``path``; returns ``path``."""
        cols = ["t", "heave", "stroke", "pressure", "wob"] + sorted(set(self.columns) - {"heave", "stroke", "pressure", "wob"})
        data = np.column_stack([self.t] + [self.columns[c] for c in cols[1:]])
        np.savetxt(path, data, delimiter=",", header=",".join(cols), comments="", fmt="%.10g")
        return path

    def cropped(self, cut):
        """The same run with its first ``cut`` [s] removed and the clock restarted at 0 (a log that
        starts mid-operation)."""
        k = self.t >= self.t[0] + cut
        rep = None if self.replays is None else {m: {c: y[k] for c, y in r.items()} for m, r in self.replays.items()}
        truth = dict(self.truth, cut=self.truth.get("cut", 0.0) + cut)
        return TestRun(self.t[k] - self.t[k][0], {c: y[k] for c, y in self.columns.items()}, self.nominal, truth, rep,
                       self.rng)

    def replay_rms(self, model, channel, start, end, validate):
        """Held-out rms of the measured ``channel`` minus the clean replay ``model`` (``nominal`` or
        ``truth``) [SI], on the samples a replay of the log's span (``start``, ``end``) [s] holds out:
        from ``validate`` [s] on the span's clock (:func:`heavecomp.diagnosis.replay_files`' ``span``
        and ``split``)."""
        t = self.t - self.t[0]
        k = (t >= start - 1e-9) & (t <= end + 1e-9)
        k &= t - t[k][0] >= validate
        r = self.columns[channel][k] - self.replays[model][channel][k]
        return float(np.sqrt(np.mean(r ** 2)))

    def true_shrink(self, split=0.67):
        """Held-out shrink the true model reaches, per channel: 1 - rms(measured - true replay) /
        rms(measured - nominal replay) on the part after ``split`` of the run (the diagnosis' held-out
        part) [-]."""
        if self.replays is None:
            return None
        k = self.t >= self.t[0] + split * (self.t[-1] - self.t[0])
        out = {}
        for c in ("wob", "stroke", "pressure"):
            before = np.sqrt(np.mean((self.columns[c][k] - self.replays["nominal"][c][k]) ** 2))
            after = np.sqrt(np.mean((self.columns[c][k] - self.replays["truth"][c][k]) ** 2))
            out[c] = float(1.0 - after / before) if before > 0 else 0.0
        return out


def generate(case: Case, other_sea: bool = False):
    """The run of ``case``, its truth laws planted at a detectable strength.

    Each law is drawn (its own file in :mod:`heavecomp.benchmark.truth`) and sized on the drawn sea
    (:func:`heavecomp.benchmark.sizing.plant`): alone it must move at least one channel by
    ``GAP_MIN`` x the noise floor in each half of the run (rms of with-minus-without the effect over
    the floor: output noise plus the residual of the nominal model replayed from this run's noisy,
    filtered heave), near the floor for ``case.near``; a second law is sized so that its own squared
    gap is a share of ``SECOND_SHARE`` of the first's.  If a sea cannot carry them, the sea and the
    laws are redrawn, up to ``case.max_draws`` seas.  Then sensor noise, and a log start
    mid-operation (``case.start``).

    Parameters
    ----------
    case : Case

    other_sea : bool
        Also make the same truth plant's log in another sea (:func:`other_sea_run`).

    Returns
    -------
    TestRun, or (TestRun, TestRun) with ``other_sea``
        ``truth`` holds the label, the planted laws (``effects``, dominant first), their component,
        whether it is a contract name (``named``, ``out_of_library``), the case, the parameter set,
        seed, seas drawn, the sea, the noise floor per channel, the planted parameters, each law's
        own gap per channel (``gap_channels``), its largest (``gap_to_noise``) and squared sum
        (``gap_alone``), the second law's share, and the stick statistics of the no-effect run.

    Raises
    ------
    RuntimeError
        No sea of ``case.max_draws`` carries the case.
    """
    rng = np.random.default_rng(case.seed)
    nominal = parameter_sets()[case.params]
    total = case.duration + case.start
    labels = case.effects
    for draw in range(1, case.max_draws + 1):
        bed = Testbed(nominal, rng, total, case.rate, case.sea, case.noise)
        setting = Setting(nominal, total, case.variant, bed.base)
        planted, target = [], None
        for i, lab in enumerate(labels):
            if target is not None:
                target = (target[0], float(rng.uniform(*SECOND_SHARE)))
            band = (NEAR_NOISE if case.near else case.size) if i == 0 else None
            got = plant(LAWS[lab], rng, bed, setting, target, near=band)
            if got is None:
                break
            planted.append((lab,) + got)
            target = (energy(got[2]), None)
        else:
            break
    else:
        # the text is the one the scoring report records
        raise RuntimeError(f"no sea of {case.max_draws} carries {case.label} ({case.variant})")
    parts = [p for _, _, p, _ in planted]
    t, cols, replays = _log(bed, parts, rng)
    lab = case.label
    truth = {"label": lab, "effects": list(labels) or ["none"], "component": COMPONENT.get(lab),
             "named": lab != "none" and LAWS[lab].named, "out_of_library": lab != "none" and not LAWS[lab].named,
             "case": dataclasses.asdict(case), "param_set": case.params, "seed": case.seed, "draws": draw,
             "sea": bed.info, "noise_floor": bed.floor,
             "parameters": {e: LAWS[e].record(d.parameters, nominal) for e, d, _, _ in planted},
             "gap_channels": {e: g for e, _, _, g in planted},
             "gap_to_noise": {e: max(g.values()) for e, _, _, g in planted},
             "gap_alone": {e: energy(g) for e, _, _, g in planted}, "stick": bed.stick}
    if len(planted) > 1:
        truth["second_share"] = truth["gap_alone"][labels[1]] / truth["gap_alone"][labels[0]]
    tr = TestRun(t=t, columns=cols, nominal=nominal, truth=truth, replays=replays, rng=rng)
    tr = tr.cropped(case.start) if case.start > 0 else tr
    return (tr, other_sea_run(case, parts, truth)) if other_sea else tr


def _log(bed, parts, rng):
    """The logged channels of the truth model with ``parts`` on ``bed`` (sensor noise drawn from ``rng``) and
    the clean replays from the logged heave: the nominal model, and the true model (plant and sensor laws
    known, driven by the heave the compensator saw plus the same heave noise)."""
    t, clean = bed.sim(parts)
    cols = dict(clean)
    cols["heave"] = clean["heave"] + bed.heave_noise
    for c in bed.OUT:
        cols[c] = clean[c] + rng.normal(0.0, bed.noise[c], t.size)
    if "pitch" in cols:
        cols["pitch"] = clean["pitch"] + rng.normal(0.0, PITCH_NOISE, t.size)
    replays = {"nominal": bed.sim([], hs=bed.heave_samples(cols["heave"]))[1],
               "truth": bed.sim([p for p in parts if not p.on_heave],
                                hs=bed.heave_samples(bed.base["heave"] + bed.heave_noise))[1]}
    return t, cols, replays


#: the stream key of the second sea of a case: ``default_rng([case.seed, OTHER_SEA_STREAM])`` never
#: meets the case's own stream ``default_rng(case.seed)`` (a different seed sequence entropy)
OTHER_SEA_STREAM = 1


def other_sea_run(case: Case, parts, truth: dict) -> TestRun:
    """The same truth plant's log in another sea: the planted ``parts`` of ``case`` as drawn (laws and
    parameters unchanged, not re-sized), on a new :class:`Testbed` whose sea of the same kind is drawn
    from its own stream (``default_rng([case.seed, OTHER_SEA_STREAM])``: another H_s, T_p and phases),
    with its own heave and sensor noise and its own nominal and truth replays; cut at ``case.start`` as
    the first.  The test of a calibrated model on a log it was not fitted on (issue 30 item 6).

    Parameters
    ----------
    case : Case
    parts : list of heavecomp.benchmark.truth.Part
        The laws planted in the case's first log.
    truth : dict
        The first log's ``truth``; the second's is a copy with its own ``sea``, ``noise_floor`` and
        ``stick``, and ``other_sea: True``.

    Returns
    -------
    TestRun
    """
    rng = np.random.default_rng([case.seed, OTHER_SEA_STREAM])
    nominal = parameter_sets()[case.params]
    bed = Testbed(nominal, rng, case.duration + case.start, case.rate, case.sea, case.noise)
    t, cols, replays = _log(bed, parts, rng)
    tr = TestRun(t=t, columns=cols, nominal=nominal,
                 truth=dict(truth, sea=bed.info, noise_floor=bed.floor, stick=bed.stick, other_sea=True,
                            first_sea=truth["sea"]), replays=replays, rng=rng)
    return tr.cropped(case.start) if case.start > 0 else tr
