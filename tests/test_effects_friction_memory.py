"""``friction_memory`` in the exact stick-slip stepper: a calibrated file with the memory simulates without the
stepper's faults (event cap, friction power F_f v < 0), its stick phases hold, and delta = 0 is the nominal run.

The file (tests/data/friction_memory_cmc.toml: a nominal CMC file on a 1 m, 12 s sine sea plus a calibrated
memory, sigma 5 cm, delta 0.3) once hit the event cap in 85 steps over 120 s and recorded 36 samples of
F_f v < 0: the memory scaled its static limit by its factor twice (once through its ``jump`` hook at v = 0, once
through its ``static`` hook), below the sliding friction it scales once, so at every stop after a slide the holding
force exceeded the limit backwards yet not the friction the reversed motion starts against, and the stepper
reversed again at v = 0 until its cap (the conformance check: tests/test_conformance.py,
``test_static_limit_holds_the_friction_the_motion_starts_against``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from heavecomp.effects.spec import plant_effects
from heavecomp.friction import laws
from heavecomp.params import load
from heavecomp.plants import cmc
from heavecomp.simulate import simulate

CASE = Path(__file__).parent / "data" / "friction_memory_cmc.toml"
DURATION = 120.0  # s: ten sea periods after the 24 s fade-in


@pytest.fixture(scope="module")
def case():
    return load(CASE)


@pytest.fixture(scope="module")
def runs(case):
    """(run with the file's memory, run of the same plant without it)."""
    assert [e.name for e in plant_effects(case)] == ["friction_memory"]
    return simulate(case, DURATION, rate=20.0), simulate(case, DURATION, rate=20.0, effects=[])


def test_the_memory_runs_without_the_steppers_faults(runs):
    """No step hits the event cap (each stop, reversal and breakaway is located) and no recorded sample has the
    friction pushing the stroke (F_f v < 0): the faults the file's run reported."""
    mem, _ = runs
    m = mem.metrics(start=0.0)
    assert m["event_cap_hits"] == 0, m["event_cap_first_t"]
    assert m["n_negative_friction_power"] == 0, m["friction_power_min"]
    assert m["friction_power_min"] >= 0.0


def test_the_stick_phases_hold(case, runs):
    """The memory lowers the friction after a reversal, it does not take the stiction away: the stroke still
    sticks at the sea's turning points (as the nominal run does, at least half as long and as often), and while
    stuck the holding force stays within the nominal static limit F_S + C_p |p| (the memory's factor is at most
    1), at v = 0 exactly."""
    mem, nom = runs
    m, n = mem.metrics(), nom.metrics()
    assert n["n_stick"] > 10 and n["stick_fraction"] > 0.02  # the sea does make the nominal seal stick
    assert m["n_stick"] >= 0.5 * n["n_stick"]
    assert m["stick_fraction"] >= 0.5 * n["stick_fraction"]
    stuck = mem["stuck"] > 0.5
    assert np.all(mem["stroke_velocity"][stuck] == 0.0)
    FP = cmc.plant_vectors(case).FP
    limit = FP[laws.FS] + FP[laws.CP] * np.abs(mem["pressure"][stuck])
    assert np.all(np.abs(mem["friction"][stuck]) <= limit * (1 + 1e-12))
    # and the memory acts: the run is not the nominal one
    assert np.max(np.abs(mem["wob"] - nom["wob"])) > 1e3


def test_a_memory_of_depth_zero_is_the_nominal_run_bit_for_bit(case, runs):
    """delta = 0 on the file's plant: the library's stepper with the memory switched on gives the nominal
    (ahead-of-time or JIT) stepper's run exactly."""
    _, nom = runs
    zero = simulate(case, DURATION, rate=20.0, effects=[("friction_memory", {"relaxation_length": 0.05,
                                                                              "depth": 0.0})])
    np.testing.assert_array_equal(zero.data, nom.data)
