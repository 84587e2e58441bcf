"""Eigenfrequency map over drill-string length and formation stiffness (issue 3)."""

import numpy as np
import pytest

from heavecomp.analysis.frequency import modes
from heavecomp.analysis.linear import linearise
from heavecomp.analysis.sweeps import DrillPipe, eigenfrequency_map
from heavecomp.params import paper_a


def test_pipe_properties_reproduce_the_paper_a_string():
    pipe = DrillPipe()
    assert pipe.steel_area == pytest.approx(3.40e-3, rel=2e-3)
    assert pipe.mass_per_length == pytest.approx(29.0, rel=2e-3)
    assert pipe.lower_mass(300.0) == pytest.approx(30e3, rel=1e-3)
    assert pipe.stiffness(300.0) == pytest.approx(2.38e6, rel=1e-2)  # paper A set: 2.08 MN/m


def test_map_equals_linearised_model_at_sampled_points():
    p = paper_a("none")
    L, kF = np.array([300.0, 1700.0, 3000.0]), np.array([2e4, 1e6])
    m = eigenfrequency_map(p, L, kF)
    pipe = DrillPipe()
    for i, li in enumerate(L):
        for j, kj in enumerate(kF):
            q = p.replace(drill_string={"stiffness": float(pipe.stiffness(li)), "lower_mass": float(pipe.lower_mass(li))},
                          formation={"stiffness": float(kj)})
            np.testing.assert_allclose(m["omega"][i, j], modes(linearise(q))["natural_frequencies"], rtol=1e-9)
            assert m["k_eff_static"][i, j] == pytest.approx(q.k_eff, rel=1e-12)


def test_paper_a_closing_argument():
    """Hard formation + short string: both modes above the wave band (5-20 s);
    a soft formation brings the lower mode into the band and amplifies the heave disturbance."""
    p = paper_a("none")
    m = eigenfrequency_map(p, [300.0, 3000.0], [1e4, 1e6], wave_periods=[12.0])
    assert not m["in_wave_band"][0, 1].any()  # paper-A case
    assert m["omega"][0, 1, 0] > 2 * np.pi / 5
    assert m["in_wave_band"][:, 0, 0].all()  # soft formation: resonance in the wave band
    assert (m["transmissibility"][:, 0, 0] > 1.5).all()
    # longer string = softer: lower eigenfrequencies
    assert (m["omega"][1, :, :] < m["omega"][0, :, :]).all()
