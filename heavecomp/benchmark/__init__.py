"""The withheld-effect benchmark: runs generated with an effect the diagnosis does not know.

It checks :mod:`heavecomp.diagnosis` and sits beside it on the same layer; the diagnosis never
imports it.  A run is described by a :class:`Case` and made by :func:`generate`:

>>> from heavecomp.benchmark import benchmark_case, generate       # doctest: +SKIP
>>> tr = generate(benchmark_case("flow_loss", seed=3))             # doctest: +SKIP
>>> tr.truth["parameters"], tr.to_csv("run.csv")                   # doctest: +SKIP

Each effect is generated with its *truth* law (:mod:`heavecomp.benchmark.truth`, one file each:
the law, its draw, the parameter that sets its size and its cap), never with the candidate's
equations.  Seas are irregular (:mod:`heavecomp.benchmark.sea`: JONSWAP, calm, mixed swell and wind
sea, or measured buoy heave through a vessel RAO), the channels get white measurement noise, and the
nominal parameter set varies between runs (:func:`parameter_sets`).  Plus runs with no effect and
with two effects.  The sets: :func:`benchmark_cases` (the benchmark's own runs) and
:func:`validation_cases` (the tuning and scoring sets of ``scenarios/diagnosis_validation.py``).
A generated run can be post-processed with sampling jitter and dropouts (:func:`corrupt`), and its
arrays into a corrupted log of one of the classes the input checks must catch
(:mod:`heavecomp.benchmark.corruption`: frozen, spikes, time base, clock skew, torn, non-finite, ...).
"""

from heavecomp.benchmark.case import (benchmark_case, benchmark_cases, Case, CASES, NEW_EFFECTS, parameter_sets,
                                      PARAMETER_SETS, TUNING_SETTINGS, TWO_EFFECTS, validation_cases)
from heavecomp.benchmark.corrupt import corrupt
from heavecomp.benchmark.generate import generate, other_sea_run, PITCH_NOISE, TestRun
from heavecomp.benchmark.sea import make_sea, SEAS, VesselRAO
from heavecomp.benchmark.sizing import GAP_MIN, NEAR_NOISE, SECOND_SHARE
from heavecomp.benchmark.testbed import NOISE
from heavecomp.benchmark.truth import COMPONENT, LAWS, OUT_OF_LIBRARY

__all__ = ["Case", "generate", "other_sea_run", "TestRun", "corrupt", "benchmark_case", "benchmark_cases", "validation_cases",
           "parameter_sets", "make_sea", "VesselRAO", "LAWS", "COMPONENT", "OUT_OF_LIBRARY", "CASES", "TWO_EFFECTS",
           "NEW_EFFECTS", "PARAMETER_SETS", "TUNING_SETTINGS", "SEAS", "NOISE", "PITCH_NOISE", "GAP_MIN",
           "NEAR_NOISE", "SECOND_SHARE"]
