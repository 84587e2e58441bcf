"""The schema-2 effects (asymmetric_friction, position_friction, gas_leak, sensor_gain, sensor_offset,
heave_reference) and the warming of gas_heat_transfer: each does the physics it names, in
``simulate`` (plant, heave and channel hooks) and in the casadi model (linearise, MPCs).

The conformance battery (tests/test_conformance.py) runs the plant effects through the common
checks; here each effect's own behaviour is measured on a simulated run."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from heavecomp.effects.base import Effect
from heavecomp.effects.registry import effect_class
from heavecomp.errors import ParameterError
from heavecomp.friction import laws
from heavecomp.params import paper_a
from heavecomp.params.core import q
from heavecomp.plants import cmc
from heavecomp.simulate import simulate

DUR = 60.0


def _run(p, effects=(), duration=DUR, **kw):
    return simulate(p, duration, rate=20.0, effects=effects, **kw)


@pytest.fixture(scope="module")
def nominal():
    return _run(paper_a("stribeck"))


def _law_jump(res, p):
    """The nominal law's J at the recorded |v| and pressure (the part the seal effects act on)."""
    plant = cmc.plant_vectors(p)
    v, pr = res["stroke_velocity"], res["pressure"]
    return laws.friction_jump(plant.code, np.abs(v), pr, plant.FP), plant.FP[laws.CV] * v


def test_asymmetric_friction_ratio_of_extension_to_retraction():
    """J (1 + a) extending, J (1 - a) retracting: the measured friction, less the viscous part,
    over the law's J is 1.3 and 0.7 for a = 0.3 (ratio 1.86)."""
    p = paper_a("stribeck")
    res = _run(p, [effect_class("asymmetric_friction")(asymmetry=0.3)])
    J, visc = _law_jump(res, p)
    v = res["stroke_velocity"]
    sliding = res["stuck"] < 0.5
    ext, ret = sliding & (v > 0.02), sliding & (v < -0.02)
    assert ext.sum() > 100 and ret.sum() > 100
    f_ext = np.mean((res["friction"][ext] - visc[ext]) / J[ext])
    f_ret = np.mean(-(res["friction"][ret] - visc[ret]) / J[ret])
    assert f_ext == pytest.approx(1.3, rel=1e-6) and f_ret == pytest.approx(0.7, rel=1e-6)
    assert np.all(res["friction"][sliding] * v[sliding] >= 0.0)  # still dissipative


def _breakaway_forces(res, direction):
    """|friction| at the last stuck sample before each slip in ``direction`` (the holding force as the
    static limit gives way) [N]."""
    stuck, v, f = res["stuck"] > 0.5, res["stroke_velocity"], np.abs(res["friction"])
    i = np.flatnonzero(stuck[:-1] & ~stuck[1:])
    return f[i[np.sign(v[i + 1]) == direction]]


@pytest.mark.parametrize("breakaway,ratio", [(1.0, 1.3 / 0.7), (0.0, 1.0)])
def test_asymmetric_friction_breakaway_share(breakaway, ratio):
    """``breakaway`` b: the static limit carries the share b of the asymmetry.  With a = 0.3 the
    holding force at breakaway extending over retracting is (1 + a)/(1 - a) for b = 1 and 1 for
    b = 0, while fast sliding (|v| >> v_S) keeps J (1 +- a) either way."""
    p = paper_a("stribeck")
    res = _run(p, [effect_class("asymmetric_friction")(asymmetry=0.3, breakaway=breakaway)])
    up, down = _breakaway_forces(res, +1), _breakaway_forces(res, -1)
    assert up.size >= 3 and down.size >= 3
    assert np.median(up) / np.median(down) == pytest.approx(ratio, rel=0.1)
    J, visc = _law_jump(res, p)
    v = res["stroke_velocity"]
    fast = (res["stuck"] < 0.5) & (v > 10 * cmc.plant_vectors(p).FP[laws.VS])
    assert fast.sum() > 50
    assert np.mean((res["friction"][fast] - visc[fast]) / J[fast]) == pytest.approx(1.3, rel=0.01)


def test_position_friction_only_inside_its_band(nominal):
    """dF added inside the band of the stroke (centre, width), nothing outside."""
    p = paper_a("stribeck")
    s = nominal["stroke"]
    centre, width = float(np.percentile(s, 70)), 0.2 * float(np.ptp(s))
    res = _run(p, [effect_class("position_friction")(extra_force=4e3, centre=centre, width=width)])
    J, visc = _law_jump(res, p)
    v, st = res["stroke_velocity"], res["stroke"]
    sliding = (res["stuck"] < 0.5) & (np.abs(v) > 0.02)
    extra = np.abs(res["friction"] - visc) - J
    inside = sliding & (np.abs(st - centre) < 0.3 * width)
    outside = sliding & (np.abs(st - centre) > 1.0 * width)
    assert inside.sum() > 20 and outside.sum() > 100
    assert np.median(extra[inside]) == pytest.approx(4e3, rel=0.01)
    assert np.max(np.abs(extra[outside])) < 0.01 * 4e3


def test_gas_leak_moves_the_charge_linearly_in_time():
    """At the measured stroke the gas's absolute pressure is (1 + r t) times the nominal one:
    a leak of -1.5 % over the run (the issue's case)."""
    p = paper_a("stribeck")
    r = -0.015 / DUR
    res = _run(p, [effect_class("gas_leak")(leak_rate=r)])
    PP = cmc.plant_vectors(p).PP
    nominal_gas = cmc.gas_pressure(res["stroke"], PP)
    change = (res["pressure"] + PP[cmc.PATM]) / (nominal_gas + PP[cmc.PATM]) - 1.0
    np.testing.assert_allclose(change, r * res.t, rtol=1e-6, atol=1e-9)
    assert change[-1] == pytest.approx(-0.015, rel=1e-3)


def test_gas_heat_transfer_warming_makes_a_slow_mean_offset(nominal):
    """Under steady cycling the gas warms towards w <v^2> with its time constant: at the
    measured stroke the absolute pressure creeps up by that share (the offset the thermal
    candidate could not make before)."""
    p = paper_a("stribeck")
    n = float(cmc.plant_vectors(p).PP[cmc.N])
    w, tw = 0.05, 10.0
    res = _run(p, [effect_class("gas_heat_transfer")(effective_index=n, loss_coefficient=10.0, warming=w,
                                                     warming_time=tw)], duration=90.0)
    PP = cmc.plant_vectors(p).PP
    v = res["stroke_velocity"]
    theta = (res["pressure"] + 10.0 * v + PP[cmc.PATM]) / (cmc.gas_pressure(res["stroke"], PP) + PP[cmc.PATM]) - 1.0
    late = res.t > 60.0
    expected = w * np.mean(v[late] ** 2)
    assert expected > 1e-3  # a visible offset (> 0.1 % of the absolute pressure)
    assert np.mean(theta[late]) == pytest.approx(expected, rel=0.05)
    assert abs(np.mean(theta[res.t < 2.0])) < 0.1 * expected  # it starts cold


def test_sensor_gain_minus_one_flips_the_sign(nominal):
    res = _run(paper_a("stribeck"), [effect_class("sensor_gain")(channel="wob", factor=-1.0)])
    np.testing.assert_array_equal(res["wob"], -nominal["wob"])
    for c in ("stroke", "pressure", "heave", "friction"):
        np.testing.assert_array_equal(res[c], nominal[c])


def test_sensor_offset_absolute_instead_of_gauge_pressure(nominal):
    res = _run(paper_a("stribeck"), [("sensor_offset", {"channel": "pressure", "offset": 101325.0, "drift": 10.0})])
    np.testing.assert_allclose(res["pressure"] - nominal["pressure"], 101325.0 + 10.0 * res.t, rtol=1e-12)
    np.testing.assert_array_equal(res["wob"], nominal["wob"])


def test_heave_reference_scales_and_delays_what_the_plant_sees():
    """A frictionless compensator follows the heave it sees: with the seen heave 0.88 x the
    measured one and 0.5 s late, the stroke is 0.88 x the nominal stroke, 0.5 s late; the
    recorded heave stays the measured one."""
    p = paper_a("none")
    ref = _run(p, duration=120.0)
    res = _run(p, [effect_class("heave_reference")(scale=0.88, delay=0.5)], duration=120.0)
    np.testing.assert_allclose(res["heave"], ref["heave"], rtol=0, atol=1e-12)  # (the output times' last bits)
    t, late = ref.t, ref.t > 60.0
    s_ref = ref["stroke"] - np.mean(ref["stroke"][late])
    s = res["stroke"] - np.mean(res["stroke"][late])
    lags = np.arange(0, 21)  # samples of 0.05 s
    err = [np.sum((s[late][k:] - 0.88 * s_ref[late][: s_ref[late].size - k]) ** 2) for k in lags]
    assert lags[int(np.argmin(err))] * 0.05 == pytest.approx(0.5, abs=0.051)
    k = 10
    g = np.dot(s[late][k:], s_ref[late][:-k]) / np.dot(s_ref[late][:-k], s_ref[late][:-k])
    assert g == pytest.approx(0.88, rel=0.02)
    assert np.std(t) > 0


@pytest.mark.parametrize("name, values", [("sensor_gain", {"channel": "stroke", "factor": 1.0}),
                                          ("sensor_offset", {"channel": "wob", "offset": 0.0, "drift": 0.0}),
                                          ("sensor_delay", {"channel": "pressure", "delay": 0.0}),
                                          ("heave_reference", {"scale": 1.0, "delay": 0.0, "lever_arm": 0.0,
                                                               "highpass": 0.0})])
def test_channel_and_heave_effects_at_null_reproduce_the_nominal_run_bit_for_bit(nominal, name, values):
    cls = effect_class(name)
    assert values == {**values, **cls.null(None)}
    res = _run(paper_a("stribeck"), [(name, values)])
    np.testing.assert_array_equal(res.data, nominal.data)


def test_casadi_model_takes_gains_and_refuses_delays_and_drifts():
    """numba = casadi for the static channel/heave maps: the model's WOB reads g times, a heave
    reference gain scales what the plant sees; a delay or a drift is refused (no finite state)."""
    from heavecomp.effects.model import casadi_model

    p = paper_a("none")
    f0 = casadi_model(p)
    fg = casadi_model(p, effects=[effect_class("sensor_gain")(channel="wob", factor=1.08),
                                  effect_class("sensor_offset")(channel="pressure", offset=1e5, drift=0.0)])
    fh = casadi_model(p, effects=[effect_class("heave_reference")(scale=0.9, delay=0.0)])
    rng = np.random.default_rng(3)
    for _ in range(10):
        x = np.r_[rng.uniform(-0.5, 0.5), rng.uniform(-0.3, 0.3), rng.uniform(-0.01, 0.01), rng.uniform(-0.1, 0.1)]
        u = np.r_[rng.uniform(-1, 1), rng.uniform(-0.5, 0.5), rng.uniform(-0.3, 0.3), 0.0]
        xd0, y0 = (np.asarray(a).ravel() for a in f0(x, u))
        xdg, yg = (np.asarray(a).ravel() for a in fg(x, u))
        assert yg[0] == pytest.approx(1.08 * y0[0], rel=1e-12) and yg[2] == pytest.approx(y0[2] + 1e5, rel=1e-12)
        np.testing.assert_array_equal(xdg, xd0)
        xdh, _ = (np.asarray(a).ravel() for a in fh(x, u))
        xd_ref = np.asarray(f0(x, np.r_[0.9 * u[:3], u[3]])[0]).ravel()
        np.testing.assert_allclose(xdh, xd_ref, rtol=1e-12, atol=1e-12)
    for bad in ([effect_class("heave_reference")(scale=0.9, delay=0.3)],
                [effect_class("sensor_offset")(channel="wob", offset=0.0, drift=5.0)],
                [effect_class("sensor_delay")(channel="wob", delay=0.2)]):
        with pytest.raises(ParameterError, match=bad[0].name):
            casadi_model(p, effects=bad)


def test_linearise_with_a_wob_gain_scales_the_wob_row():
    from heavecomp.analysis.linear import linearise

    p = paper_a("none")
    a = linearise(p, friction="none")
    b = linearise(p, friction="none", effects=[("sensor_gain", {"channel": "wob", "factor": -1.0})])
    i = list(a.output_labels).index("wob")
    np.testing.assert_allclose(b.C[i], -a.C[i], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(b.D[i], -a.D[i], rtol=1e-12, atol=1e-12)


def test_channel_effect_names_its_channel():
    with pytest.raises(ParameterError, match="unknown channel 'wobb'.*did you mean 'wob'"):
        effect_class("sensor_gain")(channel="wobb", factor=1.1)


class _Drifts(Effect):
    """Test effect with two states drifting at constant rates (a gas spring term 0 x[0])."""

    name = "_drifts"
    hook = "gas_spring"
    states = ("a", "b")

    @dataclass(frozen=True)
    class Params:
        rate: float = q(1.0, "1/s", bounds=(0.0, 10.0), symbol="r", doc="rate of the first state")

    @staticmethod
    def gas(s, v, p, x, PP, rate):
        return p + 0.0 * x[0] * x[1]

    @staticmethod
    def rates(s, v, p, x, PP, FP, rate):
        return (rate + 0.0 * v, 2.0 * rate + 0.0 * v)

    @staticmethod
    def initial(FP, PP, rate):
        return (0.0, 1.0)


def test_a_composition_has_as_many_state_slots_as_its_effects():
    """The library's state effects (five states today) plus one with two states: as many effect states as
    they have together (the stepper's state was once limited to three), laid out after the plant's four."""
    from heavecomp.effects.compose import composition
    from heavecomp.effects.model import casadi_model
    from heavecomp.effects.registry import library

    classes = tuple(c for c in library().values() if c.kind == "plant" and c.states) + (_Drifts,)
    n_lib = sum(len(c.states) for c in classes[:-1])
    assert n_lib >= 4
    comp = composition(classes)
    assert comp.n_states == n_lib + 2 and comp.slots["_drifts"] == (4 + n_lib, 5 + n_lib)
    plant = cmc.plant_vectors(paper_a())
    EP = comp.ep([_Drifts(rate=0.5)])
    X0 = comp.initial_state(plant.FP, plant.PP, EP)
    assert X0.shape == (4 + n_lib + 3,) and X0[5 + n_lib] == 1.0
    fn = comp.functions
    X = tuple(X0[:6 + n_lib])
    k = fn["state_dot"](0.1, 0.2, 0.3, 0.4, 0.0, 0.1, 2e6, 0.0, 0.0, X, plant.PP, plant.FP, EP)
    assert k == (0.1, 0.2, 0.3, 0.4) + (0.0,) * n_lib + (0.5, 1.0)
    f = casadi_model(paper_a("none"), effects=[_Drifts(rate=0.5)])
    xd = np.asarray(f(np.r_[0.0, 0.1, 0.0, 0.0, 0.0, 1.0], np.zeros(4))[0]).ravel()
    assert xd.size == 6 and xd[4] == 0.5 and xd[5] == 1.0


@pytest.mark.slow
def test_every_stateful_effect_composed_with_a_two_state_one_compiles_and_integrates():
    """The stepper compiled for every stateful library effect plus a two-state test effect (seven effect
    states today; the count grows with the library) integrates them (constant rates: exact)."""
    from heavecomp.effects.compose import composition
    from heavecomp.effects.registry import library
    from heavecomp.diagnosis.stepper import simulate_fx

    stateful = [c for c in library().values() if c.kind == "plant" and c.states]
    # gas_leak first: its state in the first effect slot, one of the few the stepper records
    classes = tuple(sorted(stateful, key=lambda c: c.name != "gas_leak")) + (_Drifts,)
    comp = composition(classes)
    res = simulate_fx(paper_a(), 20.0, [_Drifts(rate=0.5), ("gas_leak", {"leak_rate": -1e-4})], rate=10.0,
                      comp=comp)
    np.testing.assert_allclose(res[f"effect_state_{comp.slots['gas_leak'][0]}"], -1e-4 * res["t"], rtol=1e-9,
                               atol=1e-15)


def test_controllers_predict_with_the_heave_the_plant_sees():
    """A heave reference the controller knows: its earth-frame model is built on the seen heave
    (dX/dt = V exactly, no heave acceleration left in the dynamics), and both MPCs refuse a delay."""
    from heavecomp.controllers.linear_mpc import LinearMPC
    from heavecomp.controllers.model import controller_model
    from heavecomp.controllers.nonlinear_mpc import NonlinearMPC

    p = paper_a("stribeck")
    f = controller_model(p, eps=1e-3, effects=[("heave_reference", {"scale": 0.9, "delay": 0.0})])
    rng = np.random.default_rng(2)
    for _ in range(5):
        xe = np.r_[rng.uniform(-1, 1), rng.uniform(-0.5, 0.5), rng.uniform(-0.01, 0.01), rng.uniform(-0.1, 0.1)]
        u = np.r_[rng.uniform(-1, 1), rng.uniform(-0.5, 0.5), rng.uniform(-0.3, 0.3), 0.0]
        xd = np.asarray(f(xe, u)[0]).ravel()
        assert xd[0] == pytest.approx(xe[1], abs=1e-12)
    LinearMPC(p, None, effects=[("heave_reference", {"scale": 0.9, "delay": 0.0})])
    for cls in (LinearMPC, NonlinearMPC):
        with pytest.raises(ParameterError, match="heave_reference.*delay"):
            cls(p, None, effects=[("heave_reference", {"scale": 0.9, "delay": 0.3})])


def test_position_friction_start_from_its_equation_error_is_the_same_band():
    """The equation-error fit's band is in shares of the travelled stroke; the replay's start it stands
    for (``from_equation_error``) is that band in metres, so the kernel's band at those parameters is
    the feature column the fit used, and its coefficient the extra force (at least the lower bound)."""
    import numpy as np
    from heavecomp.effects.position_friction import PositionFriction

    t = np.linspace(0.0, 60.0, 3001)
    x = -0.3 + 0.8 * (0.5 + 0.5 * np.sin(2 * np.pi * t / 9.0))  # travels -0.3 .. 0.5 m
    sig = {"t": t, "x": x, "v": np.gradient(x, t)}
    shape = (0.3, 0.2)
    start = PositionFriction.from_equation_error({"shape": shape, "coefficients": {"position_friction": 4.2e3}}, sig)
    assert start["centre"] == pytest.approx(-0.3 + 0.3 * 0.8, abs=1e-4)
    assert start["width"] == pytest.approx(0.2 * 0.8, abs=1e-4)
    assert start["extra_force"] == pytest.approx(4.2e3)
    column = PositionFriction.features(sig, shape)["position_friction"]
    band = np.sign(sig["v"]) * PositionFriction.band(x, start["centre"], start["width"])
    assert np.allclose(column, band)
    low = PositionFriction.from_equation_error({"shape": shape, "coefficients": {"position_friction": -50.0}}, sig)
    assert low["extra_force"] == PositionFriction.Params.__dataclass_fields__["extra_force"].metadata["bounds"][0]
