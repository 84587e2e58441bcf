"""Paper A's friction test rig: eq. 12 reads the model's friction; Fig. 7 hysteresis; Fig. 8 rotation."""

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

from heavecomp.test_rig import plant as TR

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def p():
    return TR.RigParams()


def test_eq12_reading_equals_model_friction_within_inertia(p):
    r = TR.run(p, rotation=False, cycles=1, fs=200)
    err = r["friction_eq12"] - r["friction"]
    np.testing.assert_allclose(err, p.moving_mass * r["a"], atol=1e-6)  # the only approximation of eq. 12
    assert np.max(np.abs(err)) <= r["inertia_bound"] + 1e-9
    assert r["inertia_bound"] < 0.002 * 580.0


def test_hysteresis_without_rotation(p):
    v = np.array([0.01, 0.01, -0.01, -0.01])
    a = np.array([1.0, -1.0, -1.0, 1.0])
    F = TR.rig_friction(p, v, a, 0.0)
    assert F[0] > F[1] > 0 and F[2] < F[3] < 0  # accelerating above decelerating (Fig. 7)
    assert TR.rig_friction(p, 1e-9, 1.0, 0.0) == pytest.approx(580.0, rel=1e-5)  # F_S legible in table 2


def test_rotation_removes_the_static_peak(p):
    r0 = TR.run(p, rotation=False, cycles=1, fs=400)
    r1 = TR.run(p, rotation=True, cycles=1, fs=400)
    near = np.abs(r0["v"]) < 2e-3
    assert np.max(np.abs(r0["friction"][near])) > 0.9 * 580.0
    assert np.max(np.abs(r1["friction"][near])) < 0.1 * 580.0
    # viscous-like through zero: slope of eq. 7 at v_a = 0 is F_0(v_t)/v_t + C_v
    par = p.quadrants[0]
    vt = p.tangential_velocity
    slope = (par.coulomb_force + (par.static_force - par.coulomb_force) * np.exp(-vt / par.stribeck_velocity)) / vt \
        + par.viscous_coefficient
    assert TR.rig_friction(p, 1e-6, 1.0, vt) == pytest.approx(slope * 1e-6, rel=1e-3)
    # outside the rotation band the friction is eq. 4's again (Coulomb remains)
    far = np.abs(r1["v"]) > p.rotation_band
    np.testing.assert_allclose(r1["friction"][far], r0["friction"][far])


def test_quadrant_fit_recovers_planted_table2(p):
    r = TR.run(p, rotation=False, cycles=2, fs=200, pressure_noise=2e3, seed=3)
    fit = TR.fit_quadrants(r["v"], r["friction_eq12"], r["quadrant"])
    for f, q in zip(fit, p.quadrants):
        assert f.static_force == pytest.approx(q.static_force, rel=0.08)
        assert f.coulomb_force == pytest.approx(q.coulomb_force, rel=0.08)


def test_scenario_quick(tmp_path):
    spec = importlib.util.spec_from_file_location("sc_test_rig", ROOT / "scenarios" / "test_rig.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert mod.main(["--quick", "--out", str(tmp_path)]) == 0
    m = json.loads((tmp_path / "metrics.json").read_text())
    assert m["peak_friction_near_zero_rotation_N"] < 0.2 * m["peak_friction_near_zero_no_rotation_N"]
    assert m["eq12_max_error_noise_free_N"] <= m["inertia_bound_N"] + 1e-9
    assert (tmp_path / "friction_loops.png").stat().st_size > 10_000
