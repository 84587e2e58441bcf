"""The independent truth generator (issue 30 item 5): its laws at their literature limits, its
plant against the contract's nominal, its logs against the measured-run contract, and its
clean room (it imports none of the diagnosis' or the simulator's code)."""

from __future__ import annotations

import ast
import json
import math
from pathlib import Path
import subprocess
import sys

import numpy as np
import pytest

from heavecomp.independent import laws
from heavecomp.independent.plant import Heave, Plant, SampledHeave, simulate

from _source import tree as tree_of  # the package's files, parsed once per process

ROOT = Path(__file__).resolve().parents[1]
FORBIDDEN = ("heavecomp.effects", "heavecomp.diagnosis", "heavecomp.benchmark", "heavecomp.plants",
             "heavecomp.friction", "heavecomp.simulate")
SEAL = dict(static_force=23e3, coulomb_force=12e3, stribeck_velocity=0.01, viscous_coefficient=10e3,
            pressure_coefficient=2e-3)


def _imports(path: Path) -> list[str]:
    names = []
    for node in ast.walk(tree_of(path)):
        if isinstance(node, ast.Import):
            names += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            names.append(node.module or "")
    return names


def test_the_clean_room_imports_none_of_the_diagnosis_or_simulator():
    files = sorted((ROOT / "heavecomp" / "independent").glob("*.py")) + sorted(ROOT.glob("scenarios/independent*.py"))
    assert len(files) >= 4
    bad = [f"{f.name}: {m}" for f in files for m in _imports(f)
           if any(m == x or m.startswith(x + ".") for x in FORBIDDEN)]
    assert not bad, bad


def test_the_clean_room_check_sees_a_forbidden_import(tmp_path):
    f = tmp_path / "x.py"
    f.write_text("from heavecomp.effects import registry\nimport heavecomp.simulate.core\n")
    assert [m for m in _imports(f) if any(m.startswith(x) for x in FORBIDDEN)] == ["heavecomp.effects",
                                                                                   "heavecomp.simulate.core"]


# ---- LuGre ---------------------------------------------------------------------------------------

def _eq4(v, p):
    """Paper A eq. 4, written out here (not the law's helper)."""
    s = math.copysign(1.0, v)
    return ((12e3 + 11e3 * math.exp(-abs(v) / 0.01)) * s + 10e3 * v + 2e-3 * abs(p) * s)


@pytest.mark.parametrize("v", [-0.3, -0.02, -0.004, 0.001, 0.01, 0.05, 0.5])
def test_lugre_steady_state_is_the_stribeck_curve(v):
    lug = laws.LuGre(**SEAL, relaxation_length=0.04, micro_damping=5e4)
    p, z = 2.4e6, 0.0
    # integrate the bristle at constant v over 40 relaxation lengths (exact exponential step)
    dist = 40 * 0.04 * max(1.0, 23e3 / lug.level(v, p))
    n = 4000
    dt = dist / abs(v) / n
    for _ in range(n):
        zss = lug.level(v, p) * math.copysign(1.0, v) / lug.sigma0
        z = zss + (z - zss) * math.exp(-lug.sigma0 * abs(v) / lug.level(v, p) * dt)
    f, zd = lug.force(z, v, p)
    assert abs(zd) < 1e-9
    assert f == pytest.approx(_eq4(v, p), rel=1e-6)


def _loop_work(force_of, x, dt):
    """Work done on the element over a closed path x(t): integral of F dx (>= 0: it dissipates)."""
    w = 0.0
    for k in range(1, len(x)):
        w += 0.5 * (force_of[k] + force_of[k - 1]) * (x[k] - x[k - 1])
    return w


@pytest.mark.parametrize("amp", [2e-3, 0.02, 0.3])
def test_lugre_dissipates_energy_every_cycle(amp):
    lug = laws.LuGre(**SEAL, relaxation_length=0.04, micro_damping=2.0 * 0.5 * math.sqrt(23e3 / 0.04 * 8e4))
    per, n = 10.0, 20000
    dt = 3 * per / n
    t = np.arange(n + 1) * dt
    x, v = amp * np.sin(2 * np.pi * t / per), amp * 2 * np.pi / per * np.cos(2 * np.pi * t / per)
    z, f = 0.0, []
    for k in range(n + 1):
        fk, zd = lug.force(z, float(v[k]), 2.4e6)
        f.append(fk)
        z += zd * dt
    last = t >= 2 * per - 1e-9  # the third cycle, after the start
    w = _loop_work(np.array(f)[last], x[last], dt)
    assert w > 0.0
    assert w <= 4 * amp * (23e3 + 2e-3 * 2.4e6) + 10e3 * (2 * np.pi / per * amp) ** 2 * per / 2 * 1.05


@pytest.mark.parametrize("amp", [1e-3, 0.01, 0.05])
def test_bouc_wen_dissipates_and_yields(amp):
    bw = laws.BoucWen(2.08e6, alpha=0.7, yield_force=5e3, exponent=1.5)
    per, n = 10.0, 20000
    dt = 3 * per / n
    t = np.arange(n + 1) * dt
    x, xd = amp * np.sin(2 * np.pi * t / per), amp * 2 * np.pi / per * np.cos(2 * np.pi * t / per)
    w, f, wmax = 0.0, [], 0.0
    for k in range(n + 1):
        f.append(bw.force(float(x[k]), w))
        w += bw.w_dot(w, float(xd[k])) * dt
        wmax = max(wmax, abs(w))
    last = t >= 2 * per - 1e-9
    e = _loop_work(np.array(f)[last], x[last], dt)
    assert e >= 0.0
    assert wmax <= bw.w_ultimate * 1.001  # the hysteretic part never passes its yield force
    if amp > 3 * bw.w_ultimate:  # well past yield: the loop's area is near 4 F_y x amplitude
        assert e > 0.5 * 4 * bw.yield_force * amp


# ---- gas -----------------------------------------------------------------------------------------

def _compress(tau, gamma=1.4, ratio=0.8, seconds=5.0):
    g = laws.ThermalGas(gamma, tau)
    v0, p0, n = 10.0, 2.5e6, 50000
    dt = seconds / n
    th, vol = 1.0, v0
    dv = (ratio - 1.0) * v0 / seconds
    for _ in range(n):
        if tau == 0.0:  # the isothermal limit is the wall's temperature
            th = 1.0
        else:
            th += g.theta_dot(th, vol, dv) * dt
        vol += dv * dt
    return g.p_abs(p0, v0, vol, th) / p0


def test_thermal_gas_limits_are_isothermal_and_adiabatic():
    assert _compress(1e-4) == pytest.approx(1 / 0.8, rel=1e-3)       # tau -> 0: p V = const
    assert _compress(1e7) == pytest.approx(0.8 ** -1.4, rel=1e-3)     # tau -> inf: p V^gamma = const
    mid = _compress(2.0)
    assert 1 / 0.8 < mid < 0.8 ** -1.4


# ---- sensors ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("period, gain", [(100.0, 1 / math.sqrt(2)), (10.0, 1.0), (1000.0, 0.01)])
def test_mru_highpass_gain(period, gain):
    t = np.arange(0.0, 20 * max(period, 100.0), 0.5)
    y = laws.mru_highpass(t, np.sin(2 * np.pi * t / period), corner_period=100.0)
    tail = t > 10 * max(period, 100.0)
    amp = np.sqrt(2 * np.mean(y[tail] ** 2))
    assert amp == pytest.approx(gain, rel=0.02 if gain > 0.1 else 0.05)


def test_quantiser_error_bounds():
    y = np.random.default_rng(0).normal(0, 1e5, 10000)
    e = laws.quantise(y, 0.25e5) - y
    assert np.abs(e).max() <= 0.25e5 / 2 + 1e-6
    assert np.std(e) == pytest.approx(0.25e5 / math.sqrt(12), rel=0.05)  # uniform error
    q = laws.adc16(y + 2.5e5, 0.0, 5e5)
    assert len(np.unique(np.round(np.diff(np.unique(q)) / (5e5 / 65535)))) >= 1
    assert np.abs(q - np.clip(y + 2.5e5, 0, 5e5)).max() <= 5e5 / 65535 / 2 + 1e-6


def test_mains_hum_aliases_to_the_offset():
    t = np.arange(0.0, 600.0, 0.1)
    y = laws.mains_hum(t, 1.0, 50.02, 0.3)
    assert np.allclose(y, np.sin(2 * np.pi * 0.02 * t + 0.3), atol=1e-6)


def test_line_inertance_and_loss():
    line = laws.Line(0.3, 6.0, 3.0)
    assert line.inertance == pytest.approx(870 * 6.0 / (math.pi * 0.09 / 4))
    assert line.drop(0.1) > 0 and line.drop(-0.1) == pytest.approx(-line.drop(0.1))
    assert 1e3 < line.drop(0.1) < 1e5  # kPa-order at 0.1 m^3/s through a 0.3 m line


# ---- plant ---------------------------------------------------------------------------------------

def test_jonswap_heave_has_its_significant_height():
    h = Heave(2.0, 11.0, seed=3, ramp=0.0)
    t = np.arange(0.0, 3600.0, 0.5)
    assert 4 * np.std(h.series(t)) == pytest.approx(2.0, rel=0.1)


def test_the_plant_rests_at_its_operating_point():
    from heavecomp.params import paper_a

    p = paper_a()
    pl = Plant.from_params(p)
    r = simulate(pl, SampledHeave(np.array([0.0, 1.0, 2.0, 3.0, 4.0, 5.0]), np.zeros(6)), 4.0, rate=10.0)
    assert np.allclose(r["wob"], p.operating_point.wob_setpoint, atol=1.0)
    assert np.allclose(r["pressure"], p.p0, atol=1.0)
    assert np.abs(r["stroke"]).max() < 1e-6


def test_static_gain_is_k_eff():
    """cmc-reference.md: a slow heave moves the WOB by k_eff per metre (frictionless)."""
    from heavecomp.params import paper_a

    p = paper_a("none")
    pl = Plant.from_params(p)
    t = np.linspace(0.0, 400.0, 401)
    z = 0.2 * np.sin(np.pi / 2 * np.minimum(t / 300.0, 1.0)) ** 2
    r = simulate(pl, SampledHeave(t, z), 380.0, rate=1.0)
    dw = r["wob"][-1] - r["wob"][0]
    assert dw / 0.2 == pytest.approx(-p.k_eff, rel=0.01)


@pytest.mark.slow
def test_the_nominal_plant_is_the_simulators_to_within_the_noise(tmp_path):
    """Against `heavecomp simulate` (exact stiction) run as a user would, under the same heave file."""
    from heavecomp.params import dumps, paper_a

    p = paper_a()
    h = Heave(2.0, 11.0, seed=1)
    r = simulate(Plant.from_params(p), h, 120.0, rate=20.0)
    t = np.arange(0.0, 125.0, 0.02)
    np.savetxt(tmp_path / "heave.csv", np.c_[t, h.series(t)], delimiter=",", header="t,heave", comments="")
    q = p.replace(heave={"kind": "file", "path": "heave.csv", "amplitude": None, "period": None, "ramp": None})
    (tmp_path / "x.toml").write_text(dumps(q))
    subprocess.run([sys.executable, "-m", "heavecomp", "simulate", str(tmp_path / "x.toml"), "--duration", "120",
                    "--rate", "20", "--out", str(tmp_path / "run")], check=True, capture_output=True, cwd=ROOT)
    d = np.genfromtxt(tmp_path / "run" / "timeseries.csv", delimiter=",", names=True)
    for k, noise in (("stroke", 2e-3), ("pressure", 2e3), ("wob", 400.0)):
        n = min(len(d[k]), len(r[k]))
        assert np.sqrt(np.mean((d[k][200:n] - r[k][200:n]) ** 2)) < 0.5 * noise, k


# ---- cases ---------------------------------------------------------------------------------------

CONTRACT_EFFECTS = {"friction_lag", "dwell_stiction", "pressure_friction", "gas_heat_transfer", "flow_loss",
                    "string_damping", "sensor_delay", "parameter_mismatch", "asymmetric_friction",
                    "position_friction", "gas_leak", "sensor_gain", "sensor_offset", "heave_reference", "none"}
COMPONENTS = {"friction", "gas_spring", "flow_line", "string_formation", "sensors", "heave_input"}


@pytest.mark.parametrize("cls", ["two_effects", "quantised_hum"])
def test_a_case_follows_the_measured_run_contract(tmp_path, cls):
    from heavecomp.independent import make_case
    from heavecomp.io.series import read_series
    from heavecomp.params import load

    truth = make_case(9000001, cls, tmp_path, duration=30.0)
    for name in ("log.csv", "log_sea2.csv", "truth_channels.csv", "truth_channels_sea2.csv"):
        s = read_series(tmp_path / name, required=("t", "heave", "stroke", "pressure", "wob"))
        assert np.all(np.diff(s["t"]) > 0) and not s.warnings
    head = (tmp_path / "log.csv").read_text().splitlines()[0]
    assert head == "t,heave,stroke,pressure,wob"
    log = np.genfromtxt(tmp_path / "log.csv", delimiter=",", names=True)
    p = load(tmp_path / "nominal.toml")
    assert p.heave.kind == "jonswap"
    assert abs(np.median(log["wob"]) - p.operating_point.wob_setpoint) < 0.3 * p.operating_point.wob_setpoint
    assert abs(np.median(log["pressure"]) - p.p0) < 0.1 * p.p0
    tj = json.loads((tmp_path / "truth.json").read_text())
    assert tj == json.loads(json.dumps(truth, default=float))
    assert tj["component"] in COMPONENTS
    assert set(tj["verdicts"]) <= CONTRACT_EFFECTS
    if cls == "two_effects":
        assert tj["dominant"] in [e["class"] for e in tj["effects"]]


def test_every_class_has_a_distribution_and_a_component():
    from heavecomp.independent.cases import CLASSES, COMPONENT, DISTRIBUTIONS, OUT_OF_LIBRARY, SINGLE

    assert set(DISTRIBUTIONS) >= set(CLASSES)
    assert set(COMPONENT) == set(SINGLE) | set(OUT_OF_LIBRARY)
    assert set(COMPONENT.values()) == COMPONENTS


# ---- the scorer ----------------------------------------------------------------------------------

def _scenario():
    import importlib.util

    spec = importlib.util.spec_from_file_location("scenario_independent_truth", ROOT / "scenarios" / "independent_truth.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("verdict, right, group, wrong, comp", [
    ({"effect": "flow_loss", "confidence": "high", "component": "flow_line"}, True, False, False, True),
    ({"effect": "gas_heat_transfer", "confidence": "medium", "component": "gas_spring",
      "group": ["gas_heat_transfer", "flow_loss"]}, True, True, False, False),
    ({"effect": "gas_heat_transfer", "confidence": "low", "component": "gas_spring",
      "group": ["gas_heat_transfer", "flow_loss", "gas_leak", "string_damping"]}, False, False, False, False),
    ({"effect": "gas_heat_transfer", "confidence": "medium", "component": "gas_spring"}, False, False, True, False),
    ({"effect": "inconclusive", "confidence": "low", "component": "flow_line"}, False, False, False, True),
    ({"effect": "sensor_offset", "confidence": "medium", "component": "sensors",
      "group": ["sensor_offset:pressure", "flow_loss"]}, True, True, False, False),
])
def test_the_scorer_counts_names_groups_and_confident_wrong(verdict, right, group, wrong, comp):
    truth = {"class": "line_dynamics", "verdicts": ["flow_loss"], "components": ["flow_line"], "component": "flow_line"}
    s = _scenario()._verdict_score(truth, verdict)
    assert (s["right"], s["right_group"], s["confident_wrong"], s["right_component"]) == (right, group, wrong, comp)


def test_the_scorer_on_a_no_effect_log():
    sc = _scenario()._verdict_score
    truth = {"class": "none", "verdicts": ["none"], "component": None}
    assert sc(truth, {"effect": "none", "confidence": "high"})["right"]
    assert sc(truth, {"effect": "flow_loss", "confidence": "medium"})["confident_wrong"]
    assert not sc(truth, {"effect": "inconclusive", "confidence": "medium"})["confident_wrong"]


def test_shrink_ratio():
    r = _scenario()._ratio
    assert r(10.0, 4.0, 2.0) == pytest.approx(0.75)
    assert r(2.0, 1.0, 2.0) is None  # no gap to close: undefined, not infinite
