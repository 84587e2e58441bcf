"""Batch simulation: many CMC runs per call, WOB statistics accumulated on the fly.

:func:`simulate_batch` runs a list of campaign runs through the *same* compiled
exact stick-slip stepper as :func:`heavecomp.simulate.simulate`
(:func:`heavecomp.simulate._kernel.advance`), in parallel over runs
(``numba.prange``), each with its own JONSWAP heave samples
(:func:`heavecomp.simulate.excitation.jonswap`, identical to the single-run
path) and a small reusable output buffer of ``BLOCK`` samples.  Nothing of
length "duration x rate" is kept: per run only sums, extrema and two
histograms survive.

Per run (after the fade-in of ``ramp_periods`` T_p, the window of
:meth:`SimulationResult.metrics`), on the output grid of ``rate`` Hz:

- WOB mean, standard deviation, min, max; stick fraction; max |stroke|;
  min/max cylinder pressure; realised heave H_s = 4 std(z_h);
- a histogram of the WOB deviation dW = W - W_0 on fixed bins over
  ``[-deviation_max, +deviation_max]`` (plus under/overflow) -> time-fraction
  exceedance P(|dW| > x) and P(dW > x);
- a histogram of the *cycle extremes* max |dW| between successive zero
  up-crossings of dW (complete cycles only) -> the distribution of cycle peaks;
- the fraction of samples outside the tolerance band |dW| > b, and the number
  of band exits (inside -> outside transitions of the sampled signal).
"""

from __future__ import annotations

import logging
import math
import time

import numba as nb
import numpy as np

from heavecomp.simulate import _kernel as K, excitation
from heavecomp.errors import ParameterError
from heavecomp.params.budget import HEAVE_BYTES_PER_STEP, MAX_BYTES, check_run_size
from heavecomp.plants.cmc import eigen_rate, plant_vectors
from heavecomp.simulate.core import default_dt

log = logging.getLogger(__name__)

BLOCK = 256  #: output samples per kernel call (the per-run buffer)

#: slots of the per-run accumulator array
ACC = ("n", "sum_dev", "sumsq_dev", "wob_min", "wob_max", "stuck", "stroke_max", "outside", "exits",
       "cycles", "liftoff", "heave_sum", "heave_sumsq", "pressure_min", "pressure_max")
NACC = len(ACC)


@nb.njit(parallel=True, cache=True)
def _batch(codes, FPs, PPs, smooth, hsteps, nsteps, out_every, t_stat, W0, half, Zs, DZs, DDZs,
           kink_step, ddz_left, dev_max, nbins, acc, hist, phist, stats):
    """Parallel driver: ``prange`` over runs, each stepping ``K.advance`` block by block.

    As in :func:`heavecomp.simulate.core.run_kernel`, the steps up to the end of the
    fade-in (``kink_step``, -1 if none) see the left-limit heave acceleration there."""
    nrun = codes.shape[0]
    nbp = nbins // 2
    for r in nb.prange(nrun):
        h = hsteps[r]
        oe = out_every[r]
        sp = 0.5 * h
        out = np.empty((BLOCK + 1, K.NCH))
        state = np.zeros(4)
        mode_dir = np.array([float(K.STUCK), 1.0])
        st = np.zeros(K.NSTATS)
        a = acc[r]
        a[3] = np.inf
        a[4] = -np.inf
        a[13] = np.inf
        a[14] = -np.inf
        prev_out = -1  # unknown until the first sample in the window
        prev_d = 0.0
        started = False
        peak = 0.0
        done = 0
        total = nsteps[r]
        k1 = kink_step[r]
        ddl = DDZs[r][:2 * k1 + 1].copy() if k1 > 0 else DDZs[r][:1].copy()
        if k1 > 0:
            ddl[2 * k1] = ddz_left[r]
        while done < total:
            n = min(BLOCK * oe, total - done)
            if done < k1 < done + n:
                n = k1 - done
            start = 0 if done == 0 else 1
            if done < k1:
                pos = K.advance(state, mode_dir, done * h, n, h, codes[r], FPs[r], PPs[r], smooth[r], 0.0, sp,
                                Zs[r][:2 * k1 + 1].copy(), DZs[r][:2 * k1 + 1].copy(), ddl, out, oe, start, st)
            else:
                pos = K.advance(state, mode_dir, done * h, n, h, codes[r], FPs[r], PPs[r], smooth[r], 0.0, sp,
                                Zs[r], DZs[r], DDZs[r], out, oe, start, st)
            for j in range(start, pos):
                if out[j, 0] < t_stat[r] - 1e-12:
                    continue
                w = out[j, 4]
                d = w - W0[r]
                a[0] += 1.0
                a[1] += d
                a[2] += d * d
                if w < a[3]:
                    a[3] = w
                if w > a[4]:
                    a[4] = w
                a[5] += out[j, 10]
                s_abs = abs(out[j, 2])
                if s_abs > a[6]:
                    a[6] = s_abs
                outside = 1 if abs(d) > half[r] else 0
                a[7] += outside
                if prev_out == 0 and outside == 1:
                    a[8] += 1.0
                prev_out = outside
                if w <= 0.0:
                    a[10] += 1.0
                z = out[j, 1]
                a[11] += z
                a[12] += z * z
                p = out[j, 3]
                if p < a[13]:
                    a[13] = p
                if p > a[14]:
                    a[14] = p
                # histogram of dW: slot 0 underflow, 1..nbins, nbins+1 overflow
                x = (d + dev_max) / (2.0 * dev_max) * nbins
                if x != x:  # NaN: never index with it (int(NaN) is undefined)
                    hist[r, nbins + 1] += 1
                elif x < 0.0:
                    hist[r, 0] += 1
                elif x >= nbins:
                    hist[r, nbins + 1] += 1
                else:
                    hist[r, int(x) + 1] += 1
                # cycle extremes between zero up-crossings of dW
                if a[0] > 1.0 and prev_d < 0.0 and d >= 0.0:
                    if started:
                        y = peak / dev_max * nbp
                        if y >= nbp:
                            phist[r, nbp] += 1
                        else:
                            phist[r, int(y)] += 1
                        a[9] += 1.0
                    started = True
                    peak = 0.0
                if abs(d) > peak:
                    peak = abs(d)
                prev_d = d
            done += n
        for k in range(4):
            stats[r, k] = st[k]


def check_budget(campaign, runs, base=None) -> None:
    """Refuse, before any chunk runs, a campaign whose runs or chunks cannot fit the run-size budget
    (:mod:`heavecomp.params.budget`): per run its RK4 steps, per chunk the heave samples of its
    ``chunk_size`` runs, which a chunk holds at once (twice: as generated and padded into one array).
    Raises a one-line :class:`ParameterError`.

    Parameters
    ----------
    campaign : heavecomp.campaign.spec.Campaign
        The campaign (its settings, regimes and variants).
    runs : list of heavecomp.campaign.spec.Run
        The runs to check (one parameter set per regime and variant).
    base : heavecomp.params.CMCParams or None
        The base parameter set, when the caller already built it (None: ``campaign.base_params()``).

    Raises
    ------
    heavecomp.errors.ParameterError
        A run over the run-size budget, or a chunk whose heave samples exceed :data:`MAX_BYTES`.
    """
    s = campaign.settings
    base = base if base is not None else campaign.base_params()
    longest = 0
    seen = set()
    for run in runs:
        key = (run.regime, run.variant)
        if key in seen:
            continue
        seen.add(key)
        p = campaign.params_for(run, base=base)
        h = default_dt(p, s.rate)
        k = int(math.ceil(s.duration / h - 1e-9))
        check_run_size(p, duration=s.duration, h=h, n_steps=k, n_rows=0, n_cols=0, rate=s.rate, rate_fn=eigen_rate)
        longest = max(longest, k)
    per_chunk = min(s.chunk_size, len(runs))
    need = 2.0 * HEAVE_BYTES_PER_STEP * (longest + 1) * per_chunk
    if need > MAX_BYTES:
        raise ParameterError(
            f"settings.chunk_size = {s.chunk_size}: a chunk of {per_chunk} runs of settings.duration = {s.duration:g} s "
            f"holds {need / 1e9:.3g} GB of heave samples, over the {MAX_BYTES / 2 ** 30:g} GiB budget; lower "
            "settings.chunk_size or settings.duration")


def prepare(campaign, runs, base=None):
    """Per-run arrays for the compiled driver (parameters, steps, heave samples).

    Parameters
    ----------
    campaign : heavecomp.campaign.spec.Campaign
        The campaign (its settings, regimes and variants).
    runs : list of heavecomp.campaign.spec.Run
    base : heavecomp.params.CMCParams or None
        The base parameter set, when the caller already built it (None: ``campaign.base_params()``).

    Returns
    -------
    dict
        Arrays over the runs: plant codes and vectors (``codes``, ``FPs``, ``PPs``, ``smooth``), step
        ``hsteps`` [s], ``nsteps``, ``out_every``, statistics start ``t_stat`` [s], setpoint ``W0`` [N],
        band half width ``half`` [N], heave ``Zs`` [m], ``DZs`` [m/s], ``DDZs`` [m/s^2] (padded to a
        common length), and the fade-in's end ``kink_step``, ``ddz_left`` [m/s^2].
    """
    s = campaign.settings
    base = base if base is not None else campaign.base_params()
    n = len(runs)
    codes = np.zeros(n, dtype=np.int64)
    smooth = np.zeros(n, dtype=np.bool_)
    FPs = np.zeros((n, 6))
    PPs = None
    hsteps = np.zeros(n)
    nsteps = np.zeros(n, dtype=np.int64)
    out_every = np.zeros(n, dtype=np.int64)
    t_stat = np.zeros(n)
    W0 = np.zeros(n)
    half = np.zeros(n)
    heaves = []
    cache = {}
    spectra = {}
    for i, run in enumerate(runs):
        p = campaign.params_for(run, base=base)
        key = (run.regime, run.variant)
        if key not in cache:
            cache[key] = (plant_vectors(p), default_dt(p, s.rate))
        pv, h = cache[key]
        if PPs is None:
            PPs = np.zeros((n, pv.PP.size))
        codes[i], smooth[i], FPs[i], PPs[i] = pv.code, not pv.has_stiction, pv.FP, pv.PP
        hsteps[i] = h
        out_every[i] = max(1, int(round(1.0 / (s.rate * h))))
        nsteps[i] = int(math.ceil(s.duration / h - 1e-9))
        t_stat[i] = min(p.heave.ramp, 0.5 * s.duration)
        W0[i] = p.operating_point.wob_setpoint
        half[i] = campaign.band.half_width(W0[i])
        heaves.append(jonswap_samples(run.hs, run.tp, s.gamma, run.seed, p.heave.ramp, nsteps[i] * h, 0.5 * h,
                                      spectra))
    kink_step = np.full(n, -1, dtype=np.int64)
    ddz_left = np.zeros(n)
    for i, hv in enumerate(heaves):  # the same condition as simulate.core.run_kernel
        if hv.kink is not None and hv.kink[0] % 2 == 0:
            k1 = hv.kink[0] // 2
            if 0 < k1 <= nsteps[i] and k1 % out_every[i] == 0:
                kink_step[i], ddz_left[i] = k1, hv.kink[1]
    m = max(hv.z.size for hv in heaves)
    Zs, DZs, DDZs = (np.empty((n, m)) for _ in range(3))
    for i, hv in enumerate(heaves):
        for arr, src in ((Zs, hv.z), (DZs, hv.dz), (DDZs, hv.ddz)):
            arr[i, :src.size] = src
            arr[i, src.size:] = src[-1]  # never reached: padding to a common length only
    return dict(codes=codes, FPs=FPs, PPs=PPs, smooth=smooth, hsteps=hsteps, nsteps=nsteps, out_every=out_every,
                t_stat=t_stat, W0=W0, half=half, Zs=Zs, DZs=DZs, DDZs=DDZs, kink_step=kink_step, ddz_left=ddz_left)


def jonswap_samples(hs, tp, gamma, seed, ramp, duration, spacing, spectra=None):
    """:func:`heavecomp.simulate.excitation.jonswap` with its amplitude spectrum cached in
    ``spectra`` (a dict) across the runs of a campaign (one spectrum per sea state).

    Parameters
    ----------
    hs : float [m]
        Significant wave height.
    tp : float [s]
        Peak period.
    gamma : float [-]
        JONSWAP peak enhancement factor.
    seed : int
        Seed of the random phases.
    ramp : float [s]
        Fade-in time of the heave.
    duration : float [s]
        Length to synthesise.
    spacing : float [s]
        Sample spacing.
    spectra : dict or None
        Cache of amplitude spectra, shared across calls.

    Returns
    -------
    heavecomp.simulate.excitation.HeaveSamples
    """
    return excitation.jonswap(hs, tp, gamma, seed, ramp, duration, spacing, spectra=spectra)


def hist_columns(nbins: int) -> tuple[list[str], list[str]]:
    """Column names of the dW histogram (under, bins, over) and of the cycle-peak histogram.

    Parameters
    ----------
    nbins : int
        Bins of the WOB deviation histogram (the cycle-peak histogram has half as many).

    Returns
    -------
    (list of str, list of str)
    """
    dev = ["dev_under"] + [f"dev_{k:03d}" for k in range(nbins)] + ["dev_over"]
    pk = [f"peak_{k:03d}" for k in range(nbins // 2)] + ["peak_over"]
    return dev, pk


def simulate_batch(campaign, runs, *, threads: int | None = None, base=None) -> list[dict]:
    """Simulate ``runs`` (a list of :class:`~heavecomp.campaign.spec.Run`) and
    return one table row (dict) per run.

    Parameters
    ----------
    campaign : Campaign
    runs : list of Run
    threads : int, optional
        numba threads for this call (default: numba's current setting).
    base : heavecomp.params.CMCParams, optional
        The base parameter set, when the caller already built it (default: ``campaign.base_params()``).

    Returns
    -------
    list of dict
        One row per run, in the order of ``runs``: the columns of ``runs.csv`` [SI].

    Notes
    -----
    Same stepper, step, output grid and heave as :func:`heavecomp.simulate.simulate`
    (paper A CMC, ``cmc-reference.md``), so each row equals the single run's
    :meth:`~heavecomp.simulate.core.SimulationResult.metrics` (tested).
    """
    if not runs:
        return []
    t0 = time.perf_counter()
    a = prepare(campaign, runs, base=base)
    t_prep = time.perf_counter() - t0
    n = len(runs)
    o = campaign.outputs
    acc = np.zeros((n, NACC))
    hist = np.zeros((n, o.bins + 2), dtype=np.int64)
    phist = np.zeros((n, o.bins // 2 + 1), dtype=np.int64)
    stats = np.zeros((n, 4))
    prev = nb.get_num_threads()
    if threads is not None:  # for this call only: numba's thread count is process-global
        nb.set_num_threads(max(1, min(int(threads), nb.config.NUMBA_NUM_THREADS)))
    try:
        _batch(a["codes"], a["FPs"], a["PPs"], a["smooth"], a["hsteps"], a["nsteps"], a["out_every"], a["t_stat"],
               a["W0"], a["half"], a["Zs"], a["DZs"], a["DDZs"], a["kink_step"], a["ddz_left"],
               float(o.deviation_max), int(o.bins), acc, hist,
               phist, stats)
    finally:
        nb.set_num_threads(prev)
    wall = time.perf_counter() - t0
    log.debug("batch of %d runs: %.2f s (heave synthesis %.2f s)", n, wall, t_prep)
    dev_cols, pk_cols = hist_columns(o.bins)
    rows = []
    for i, run in enumerate(runs):
        c = dict(zip(ACC, acc[i]))
        cnt = c["n"]
        mean_dev = c["sum_dev"] / cnt
        hm = c["heave_sum"] / cnt
        row = {"run_id": run.run_id, "sea_state": run.sea_state, "hs": run.hs, "tp": run.tp,
               "probability": run.probability, "regime": run.regime, "variant": run.variant, "seed": run.seed,
               "duration": campaign.settings.duration, "dt": a["hsteps"][i], "stats_start": a["t_stat"][i],
               "n_samples": int(cnt), "wob_setpoint": a["W0"][i], "band_half_width": a["half"][i],
               "wob_mean": a["W0"][i] + mean_dev,
               "wob_std": math.sqrt(max(c["sumsq_dev"] / cnt - mean_dev ** 2, 0.0)),
               "wob_min": c["wob_min"], "wob_max": c["wob_max"],
               "stick_fraction": c["stuck"] / cnt, "stroke_max": c["stroke_max"],
               "pressure_min": c["pressure_min"], "pressure_max": c["pressure_max"],
               "frac_outside_band": c["outside"] / cnt, "n_band_exits": int(c["exits"]),
               "liftoff_fraction": c["liftoff"] / cnt, "n_cycles": int(c["cycles"]),
               "heave_hs": 4.0 * math.sqrt(max(c["heave_sumsq"] / cnt - hm * hm, 0.0)),
               "n_stick": int(stats[i, 1]), "n_breakaway": int(stats[i, 2]), "n_reversal": int(stats[i, 3]),
               "batch_wall_s": wall / n}
        for key, value in campaign.variant(run.variant).overrides:
            row[key] = value
        row.update(zip(dev_cols, hist[i].tolist()))
        row.update(zip(pk_cols, phist[i].tolist()))
        rows.append(row)
    return rows


def run_chunk(campaign, run_ids, threads: int | None = 1) -> list[dict]:
    """Task unit for process pools and Dask workers: simulate the runs named by ``run_ids``.

    Parameters
    ----------
    campaign : heavecomp.campaign.spec.Campaign
        The campaign (its settings, regimes and variants).
    run_ids : sequence of str
        ``run_id`` of each run to simulate (runs of ``campaign``).
    threads : int or None
        numba threads for this call (None: numba's current setting).

    Returns
    -------
    list of dict
        The table rows (:func:`simulate_batch`).
    """
    by_id = {r.run_id: r for r in campaign.runs()}
    return simulate_batch(campaign, [by_id[i] for i in run_ids], threads=threads)
