"""Post-processing of a generated run into a corrupted log (what a real logger does to it).

Each step takes a :class:`~heavecomp.benchmark.generate.TestRun` and returns a new one, drawing from
the run's own random stream (``TestRun.rng``, the case's stream after :func:`generate`), so a
corrupted run is reproducible from its case alone.  The truth records every step (``corrupted``).
"""

from __future__ import annotations

import dataclasses

import numpy as np


def corrupt(run, *, jitter=False, dropouts=False):
    """``run`` with a logger's defects (the diagnosis' loader must treat them).

    Parameters
    ----------
    run : heavecomp.benchmark.TestRun
        A generated run with its random stream (``run.rng``).
    jitter : bool
        Non-uniform sampling: each sample time moved by up to +-0.3 of the step, the channels
        interpolated onto the moved clock (the first sample stays at 0).
    dropouts : bool
        One burst of 3-19 missing samples (NaN) in each of heave, wob and pressure.

    Returns
    -------
    TestRun
    """
    if run.rng is None:
        raise ValueError("corrupt: the run carries no random stream (TestRun.rng); generate it with generate(case)")
    rng = run.rng
    t, cols = run.t, dict(run.columns)
    if jitter:
        tj = t + rng.uniform(-0.3, 0.3, t.size) * (t[1] - t[0])
        tj[0] = 0.0
        cols = {c: np.interp(tj, t, y) for c, y in cols.items()}
        t = tj
    if dropouts:
        for c in ("heave", "wob", "pressure"):
            y = cols[c] = np.array(cols[c], dtype=float)
            i = int(rng.integers(100, t.size - 100))
            y[i:i + int(rng.integers(3, 20))] = np.nan
    steps = [s for s, on in (("jitter", jitter), ("dropouts", dropouts)) if on]
    truth = dict(run.truth, corrupted=run.truth.get("corrupted", []) + steps)
    replays = None if jitter else run.replays  # the replays sit on the uniform clock
    return dataclasses.replace(run, t=t, columns=cols, truth=truth, replays=replays)
