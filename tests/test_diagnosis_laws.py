"""Laws that span the physics (issue 30 item 4): each new family recovers its own parameters from a log the
benchmark generator makes with its *truth* law (heavecomp.benchmark.truth, never the candidate's equation)
at the benchmark's noise, and a run without any effect does not pick it."""

import numpy as np
import pytest

from heavecomp.benchmark import Case, generate
from heavecomp.diagnosis.data import check_run
from heavecomp.diagnosis.estimator import GapDiagnoser

SIZE = (4.5, 5.5)  #: the planted effect's largest channel gap over the noise floor [-]


def _fitted(case, candidates):
    tr = generate(case)
    run = check_run(tr.t, tr.columns, params=tr.nominal)
    return tr, GapDiagnoser(tr.nominal, candidates, n_jobs=1, second=0).fit(run)


@pytest.mark.slow
def test_friction_memory_recovers_a_lugre_bristle(once):
    """A LuGre bristle (relaxation length L_c 3-6 cm at the Coulomb level, longer near rest; its share of the
    friction sized to 5 x the noise floor) read by the distance memory: sigma of the bristle's order, the
    share it carries, and the log explained; the time memory (friction_lag) explains less of it."""
    tr, d = once(_fitted, Case("friction_memory", 300101, "named", duration=300.0, size=SIZE),
                 ["friction_memory", "friction_lag"])
    rows = {c["effect"]: c for c in d.candidates_}
    got = rows["friction_memory"]["parameters"]
    truth = tr.truth["parameters"]["friction_memory"]
    assert 0.3 * truth["relaxation_length"] < got["relaxation_length"] < 3.0 * truth["relaxation_length"], (got, truth)
    assert 0.5 * truth["share"] < got["depth"] < 2.0 * truth["share"], (got, truth)
    assert rows["friction_memory"]["explained"] > 0.5
    assert rows["friction_memory"]["explained"] > rows["friction_lag"]["explained"]


@pytest.mark.slow
def test_string_damping_carries_the_shape_of_a_quadratic_drag(once):
    """The generator's quadratic drag c_q dv|dv| is read with an exponent near 2, not as a linear dashpot."""
    _, d = once(_fitted, Case("string_damping", 300102, "named", duration=300.0, size=SIZE), ["string_damping"])
    got = d.candidates_[0]["parameters"]
    assert 1.5 < got["exponent"] < 2.6, got
    assert d.candidates_[0]["explained"] > 0.7


@pytest.mark.slow
def test_a_run_without_effect_picks_no_new_family(once):
    """No effect: the verdict is none, and neither new family explains the (noise) gap."""
    _, d = once(_fitted, Case("none", 300103, "none", duration=300.0), ["friction_memory", "string_damping"])
    assert d.verdict_["effect"] == "none", d.verdict_
    assert all(c["explained"] < 0.5 for c in d.candidates_)
