"""The benchmark's generator (issue 4): every planted effect is detectable (its own gap is at least
GAP_MIN x the noise floor), a dwell stiction is planted only where the compensator sticks, a second
effect is a real fraction of the dominant one, a case makes the same run every time, and a
corrupted log continues the case's random stream (the truth laws' own battery:
``test_benchmark_truth.py``).

The gaps are recomputed here from the recorded truth (parameters, sea) with the stepper directly,
not with the generator's own helpers."""

import math

import numpy as np
import pytest

import heavecomp.benchmark as B
from heavecomp.benchmark import benchmark_case, benchmark_cases, corrupt, generate
from heavecomp.benchmark.truth import LAWS, TRUTH, truth_composition
from heavecomp.benchmark.testbed import truth_dt
from heavecomp.diagnosis.stepper import CHANNELS as SC, run_fx
from heavecomp.plants.cmc import plant_vectors
from heavecomp.simulate import excitation

DUR = 120.0
OUT = ("stroke", "pressure", "wob")
STICK_MIN = LAWS["dwell_stiction"].min_stuck_share


def _truth(name, prm):
    """The truth effect built from its recorded parameters (plant effects only)."""
    return [TRUTH[name](**prm)]


def _clean(tr, effects):
    """Clean truth channels of the recorded sea with the truth ``effects`` on the nominal parameters."""
    nominal, sea = tr.nominal, tr.truth["sea"]
    h = truth_dt(nominal, 50.0)  # the generator's step
    n = int(math.ceil(DUR / h - 1e-9))
    hs = excitation.jonswap(sea["hs"], sea["tp"], 3.3, sea["phase_seed"], 2 * sea["tp"], n * h, 0.5 * h)
    comp = truth_composition()
    out = run_fx(plant_vectors(nominal), comp, comp.ep(effects), hs, h, n, int(round(0.02 / h)))
    return out[:, 0], {c: out[:, SC.index(c)] for c in OUT + ("stuck",)}


@pytest.mark.slow
@pytest.mark.parametrize("name,pset,seed", [("dwell_stiction", "paper_a", 3), ("string_damping", "light_friction", 4),
                                            ("friction_lag", "light_friction", 5)])
def test_planted_effect_is_above_the_noise_floor(name, pset, seed):
    """The weakest effects of the benchmark, on their hardest parameter sets: recomputed from the
    recorded truth, the effect moves some channel by >= GAP_MIN x the recorded noise floor in each
    half of the run; the floor is itself at least the output noise."""
    tr = generate(benchmark_case(name, seed=seed, duration=DUR, param_set=pset))
    t, base = _clean(tr, [])
    _, with_effect = _clean(tr, _truth(name, tr.truth["parameters"][name]))
    floor = tr.truth["noise_floor"]
    m = t >= 0.1 * DUR

    def gap(k):
        return {c: float(np.sqrt(np.mean((with_effect[c][k] - base[c][k]) ** 2))) / floor[c] for c in OUT}

    assert all(floor[c] >= B.NOISE[c] for c in OUT)
    assert gap(m) == pytest.approx(tr.truth["gap_channels"][name], rel=1e-6)
    mid = 0.5 * (0.1 * DUR + DUR)  # in each half of the run, not in one burst only
    for half in (m & (t < mid), t >= mid):
        assert max(gap(half).values()) >= B.GAP_MIN
    # the measured data really differ from the no-effect model by more than the noise
    meas = tr.columns
    c = max(gap(m), key=gap(m).get)
    assert np.sqrt(np.mean((meas[c][m] - base[c][m]) ** 2)) > 2 * B.NOISE[c]
    if name == "dwell_stiction":  # planted where the compensator sticks
        assert np.mean(base["stuck"] > 0.5) >= STICK_MIN
        assert tr.truth["stick"]["stuck_share"] >= STICK_MIN


def test_two_effect_run_second_is_a_real_fraction():
    tr = generate(benchmark_case(("friction_lag", "sensor_delay"), seed=7, duration=DUR, param_set="soft_formation"))
    first, second = tr.truth["effects"]
    gaps = tr.truth["gap_alone"]
    assert (first, second) == ("friction_lag", "sensor_delay")
    share = gaps[second] / gaps[first]
    assert B.SECOND_SHARE[0] <= share <= B.SECOND_SHARE[1]
    assert share == pytest.approx(tr.truth["second_share"])
    assert tr.truth["gap_to_noise"][first] >= B.GAP_MIN


def test_no_effect_run_has_no_planted_gap():
    tr = generate(benchmark_case("none", seed=2, duration=DUR, param_set="paper_a"))
    t, base = _clean(tr, [])
    assert tr.truth["gap_alone"] == {} and tr.truth["parameters"] == {}
    for c in OUT:  # the measured channels are the no-effect truth plus white noise of the stated level
        r = tr.columns[c] - base[c]
        assert np.std(r) == pytest.approx(B.NOISE[c], rel=0.1)


def test_benchmark_meets_every_case_on_two_parameter_sets():
    cases = benchmark_cases()
    for e in B.CASES:
        sets = [c.params for c in cases if c.label == e and c.second is None]
        assert len(sets) == 2 and len(set(sets)) == 2, (e, sets)
    assert "light_friction" not in [c.params for c in cases if "dwell_stiction" in c.effects]


def test_a_case_makes_the_same_run_and_a_corrupted_log_continues_its_stream():
    """generate(case) is a function of the case; corrupt() draws from the case's stream after it,
    so the corrupted log is reproducible too, and the clean run it started from is untouched."""
    case = benchmark_case("flow_loss", seed=5, duration=60.0)
    a, b = generate(case), generate(case)
    assert all(np.array_equal(a.columns[c], b.columns[c]) for c in a.columns) and a.truth == b.truth
    ca, cb = corrupt(a, jitter=True, dropouts=True), corrupt(b, jitter=True, dropouts=True)
    assert np.array_equal(ca.t, cb.t) and not np.array_equal(ca.t, a.t)
    assert all(np.array_equal(ca.columns[c], cb.columns[c], equal_nan=True) for c in a.columns)
    assert {c for c in ca.columns if np.isnan(ca.columns[c]).any()} == {"heave", "wob", "pressure"}
    assert not any(np.isnan(a.columns[c]).any() for c in a.columns)
    assert ca.truth["corrupted"] == ["jitter", "dropouts"]


def test_the_other_sea_log_has_the_same_planted_plant_in_another_sea():
    """generate(case, other_sea=True): the first log is generate(case)'s bit for bit; the second carries the
    same planted laws and parameters, in another sea of the same kind (another H_s, T_p and phases), with
    its own sensor noise, and its own truth replay that explains its log where the nominal's does not."""
    case = benchmark_case("flow_loss", seed=5, duration=DUR)
    alone = generate(case)
    first, other = generate(case, other_sea=True)
    assert all(np.array_equal(alone.columns[c], first.columns[c]) for c in alone.columns) and alone.truth == first.truth
    assert other.truth["parameters"] == first.truth["parameters"] and other.truth["effects"] == ["flow_loss"]
    sa, sb = first.truth["sea"], other.truth["sea"]
    assert sb["kind"] == sa["kind"] and other.truth["first_sea"] == sa
    assert sb["hs"] != sa["hs"] and sb["tp"] != sa["tp"] and sb["phase_seed"] != sa["phase_seed"]
    assert np.array_equal(other.t, first.t) and not np.allclose(other.columns["heave"], first.columns["heave"])
    # the truth replay explains the second log down to its own noise floor; the nominal's does not
    k = other.t >= 30.0
    gap = {m: {c: np.sqrt(np.mean((other.columns[c][k] - other.replays[m][c][k]) ** 2)) / other.truth["noise_floor"][c]
               for c in OUT} for m in ("truth", "nominal")}
    assert max(gap["truth"].values()) < 1.5 and max(gap["nominal"].values()) > 2.0, gap
    assert other.truth["noise_floor"] != first.truth["noise_floor"]
