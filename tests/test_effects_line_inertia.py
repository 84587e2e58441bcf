"""``line_inertia`` (the line's oil as a mass on the stroke, issue 30 item 4): the cylinder reads the
inertial drop, and a vanishing mass is the laminar line (the stroke's M_c + m: the casadi model and
the stepper pinned together by ``tests/test_conformance.py``)."""

import numpy as np
import pytest

from heavecomp.diagnosis.stepper import simulate_fx
from heavecomp.effects.registry import effect_class
from heavecomp.params import paper_a
from heavecomp.plants.cmc import A, plant_vector


@pytest.fixture(scope="module")
def runs():
    p = paper_a()
    li = effect_class("line_inertia")
    return (p, simulate_fx(p, 60.0, [li(added_mass=2e4, resistance=2e4)], rate=50.0),
            simulate_fx(p, 60.0, [li(added_mass=1e-9, resistance=2e4)], rate=50.0))


def test_the_cylinder_reads_the_oil_columns_inertial_drop(runs):
    p, r, _ = runs
    t, v = r["t"], r["stroke_velocity"]
    a = np.gradient(v, t)
    drop = 2e4 * a / plant_vector(p)[A]
    k = (t > 20) & (r["stuck"] == 0)
    k[1:] &= r["stuck"][:-1] == 0
    k[:-1] &= r["stuck"][1:] == 0  # away from stick events, where the sampled gradient smears a jump
    err = r["pressure"] - (r["gas_pressure"] - 2e4 * v - drop)
    assert np.sqrt(np.mean(err[k] ** 2)) < 0.05 * np.sqrt(np.mean(drop[k] ** 2))


def test_a_vanishing_mass_is_the_laminar_line(runs):
    """m -> 0 leaves flow_loss's law: p_cyl = p_gas - R v exactly, while stuck and sliding."""
    _, _, r0 = runs
    np.testing.assert_allclose(r0["pressure"], r0["gas_pressure"] - 2e4 * r0["stroke_velocity"], rtol=0, atol=1e-3)

