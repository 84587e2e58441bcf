"""Sim-to-real gap diagnosis of the CMC (issue 4): measured runs, replay, where, which effect, how far.

>>> from heavecomp.diagnosis import GapDiagnoser, load_run      # doctest: +SKIP
>>> run = load_run("run.csv", nominal)                           # doctest: +SKIP
>>> d = GapDiagnoser(nominal, split=0.67).fit(run)               # doctest: +SKIP
>>> d.verdict_, d.candidates_, d.where_, d.to_json()             # doctest: +SKIP
>>> replay_files("run.csv", ["nominal.toml", "diag/calibrated.toml"]).ranking()  # doctest: +SKIP

Parts: :mod:`~heavecomp.diagnosis.replay` (the run prepared once), :mod:`~heavecomp.diagnosis.fitting`
(the fitting strategies), :mod:`~heavecomp.diagnosis.screen` (equation error: pre-screen, open search),
:mod:`~heavecomp.diagnosis.joint` (a second effect), :mod:`~heavecomp.diagnosis.verdict` (the pure
verdict) and :mod:`~heavecomp.diagnosis.policy` (every threshold).

Heavy modules (numba, scipy) load on first use.
"""

from heavecomp.diagnosis.data import MeasuredRun, check_run, load_run
from heavecomp.diagnosis.estimator import GapDiagnoser
from heavecomp.diagnosis.policy import VerdictPolicy
from heavecomp.diagnosis.compare import ReplayComparison, replay_files

__all__ = ["GapDiagnoser", "VerdictPolicy", "load_run", "check_run", "MeasuredRun", "ReplayComparison", "replay_files"]
