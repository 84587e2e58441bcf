"""The calibrated model written from a verdict (issue 22 item 2): what each verdict kind writes."""

from __future__ import annotations

import math

import pytest

from heavecomp.diagnosis.calibrate import calibrate, to_toml
from heavecomp.effects import spec
from heavecomp.params import loads, paper_a

NOM = paper_a()


def _diag(effect, parameters=None, **verdict):
    return {"verdict": {"effect": effect, "confidence": "high", "parameters": parameters or {}, "shrink": 0.6,
                        "shrink_channel": "wob", **verdict}, "split": {"fit": [0, 100], "validate": [100, 150]}}


def _round_trip(cal):
    """The file as `heavecomp params` reads it: TOML text, parsed, [[effects]] checked."""
    p = loads(to_toml(cal))
    spec.check(p)
    return p


def test_none_and_inconclusive_write_the_nominal_and_say_why():
    for eff, why in (("none", "agrees with this model"), ("inconclusive", "explains only 12 %")):
        cal = calibrate(NOM, _diag(eff, note="best candidate flow_loss explains only 12 % of the held-out gap"))
        assert cal.params == NOM and cal.changes == [] and cal.expected_shrink == 0.0
        text = to_toml(cal)
        assert why in text and f"verdict: {eff}" in text
        assert _round_trip(cal) == NOM


def test_a_plant_effect_becomes_an_effects_entry_with_the_fitted_values():
    cal = calibrate(NOM, _diag("string_damping", {"damping": 4.7e4}))
    # a verdict without the exponent (fitted last, optional in a file) is the linear dashpot: written out as n = 1
    assert cal.params.effects == (("string_damping", {"damping": 4.7e4, "exponent": 1.0}),)
    assert cal.changes == [{"kind": "effect", "name": "string_damping", "role": "plant",
                            "parameters": {"damping": 4.7e4, "exponent": 1.0}}]
    assert cal.expected_shrink == 0.6
    p = _round_trip(cal)
    assert [e.name for e in spec.plant_effects(p)] == ["string_damping"]
    # the rest of the model is the nominal's
    assert p.replace(effects=()) == NOM


def test_a_gas_effect_whose_null_needs_the_plant_becomes_an_effects_entry():
    """gas_heat_transfer's null index is the plant's own: calibrate, which has no plant, still writes
    the fitted gas law (it crashed the loop scenario's first named gas_heat_transfer verdict)."""
    par = {"effective_index": 1.12, "loss_coefficient": 3e4, "warming": 0.02, "warming_time": 400.0}
    cal = calibrate(NOM, _diag("gas_heat_transfer", par))
    assert cal.params.effects == (("gas_heat_transfer", par),)
    assert [e.name for e in spec.plant_effects(_round_trip(cal))] == ["gas_heat_transfer"]


def test_a_file_effect_refitted_is_replaced_not_doubled():
    nom = NOM.replace(effects=[("string_damping", {"damping": 1e4})])
    cal = calibrate(nom, _diag("string_damping", {"damping": 4.7e4}))
    assert cal.params.effects == (("string_damping", {"damping": 4.7e4, "exponent": 1.0}),)


def test_parameter_mismatch_writes_the_refitted_values_with_the_fit_clip():
    fs, fc = NOM.friction.static_force, NOM.friction.coulomb_force
    par = {"compensator.gas_stiffness": 1.3 * NOM.compensator.gas_stiffness, "friction.static_force": fs,
           "friction.coulomb_force": 1.5 * fs, "drill_string.stiffness": NOM.drill_string.stiffness}
    cal = calibrate(NOM, _diag("parameter_mismatch", par))
    p = _round_trip(cal)
    assert p.compensator.gas_stiffness == pytest.approx(1.3 * NOM.compensator.gas_stiffness)
    assert p.friction.coulomb_force == fs  # F_C clipped to F_S, as ParameterMismatch.apply does
    assert p.effects == ()
    assert {c["name"] for c in cal.changes} == {"compensator.gas_stiffness", "friction.coulomb_force"}
    assert fc != fs


def test_a_sensor_effect_corrects_the_reading_and_leaves_the_plant():
    cal = calibrate(NOM, _diag("sensor_gain", {"channel": "wob", "factor": 1.08}))
    p = _round_trip(cal)
    assert spec.plant_effects(p) == []
    (e,) = spec.reading_effects(p)
    assert (e.name, e.channel, e.values["factor"]) == ("sensor_gain", "wob", 1.08)
    assert cal.changes[0]["role"] == "reading"
    # heave_reference fitted without a logged angle: the lever arm (and a high-pass not fitted) at its null value
    cal = calibrate(NOM, _diag("heave_reference", {"scale": 0.9, "delay": -0.2}))
    (e,) = spec.reading_effects(_round_trip(cal))
    assert e.values == {"scale": 0.9, "delay": -0.2, "lever_arm": 0.0, "highpass": 0.0}


def test_a_discovered_friction_term_is_carried_as_discovered_term():
    d = {"term": "1.9e3*sign(v)*(v>0)", "features": ["sign_v_pos"], "coefficients": {"sign_v_pos": 1.9e3},
         "shrink": 0.6, "component": "friction"}
    cal = calibrate(NOM, _diag("discovered", component="friction", discovered=d))
    (e,) = spec.plant_effects(_round_trip(cal))
    assert e.name == "discovered_term" and e.values["sign_v_pos"] == 1.9e3 and e.values["v"] == 0.0
    assert cal.expected_shrink == 0.0 and cal.changes[0]["component_shrink"] == 0.6  # verdict.shrink is a candidate's
    # a term elsewhere (no model form at its hook): the nominal, and the file says why
    d = dict(d, component="gas_spring", features=["x"], coefficients={"x": 3e5}, term="3e5*(x - mean x)")
    cal = calibrate(NOM, _diag("discovered", component="gas_spring", discovered=d))
    assert cal.params == NOM and cal.changes == [] and "has no model form" in to_toml(cal)


def test_a_second_effect_is_added_and_the_joint_shrink_expected():
    diag = _diag("string_damping", {"damping": 4.7e4},
                 second_effect={"effect": "pressure_friction", "parameters": {"extra_pressure_coefficient": 2e-3},
                                "added_explained": 0.2, "shrink_joint": 0.8})
    cal = calibrate(NOM, diag)
    assert [n for n, _ in cal.params.effects] == ["string_damping", "pressure_friction"]
    assert cal.expected_shrink == 0.8


def test_values_that_cannot_make_a_valid_file_leave_the_nominal_and_say_why(tmp_path):
    from heavecomp.diagnosis.calibrate import write

    # a refit beyond the table's possible range (gas stiffness <= 1e8 N/m)
    cal = write(NOM, _diag("parameter_mismatch", {"compensator.gas_stiffness": 5e8}), tmp_path)
    assert cal.params == NOM and cal.changes == []
    assert "compensator.gas_stiffness" in (tmp_path / "calibrated.toml").read_text()
    # a fit a rounding beyond its bound is written at the bound
    cal = calibrate(NOM, _diag("string_damping", {"damping": 2e6 * (1 + 1e-15)}))
    assert cal.params.effects[0][1]["damping"] == 2e6


def test_what_next_names_the_change_the_file_and_the_commands():
    from heavecomp.report.calibrated import what_next

    par = {"compensator.gas_stiffness": 0.6 * NOM.compensator.gas_stiffness,
           "drill_string.stiffness": 1.001 * NOM.drill_string.stiffness}
    text = "\n".join(what_next(calibrate(NOM, _diag("parameter_mismatch", par)), "out", run_path="log.csv",
                               params_path="rig.toml"))
    assert "Change `compensator.gas_stiffness`" in text and "Change `drill_string.stiffness`" not in text
    assert "heavecomp diagnose log.csv --params out/calibrated.toml" in text
    assert "heavecomp simulate out/calibrated.toml" in text and "--controller linear-mpc" in text
    text = "\n".join(what_next(calibrate(NOM, _diag("sensor_gain", {"channel": "wob", "factor": 1.08})), "out"))
    assert "**wob** sensor misreads" in text
    text = "\n".join(what_next(calibrate(NOM, _diag("none")), "out", params_path="rig.toml"))
    assert "Nothing to change in `rig.toml`" in text
    # issue 31: after `none` no re-diagnosis or calibration check is offered, and the file is not "the nominal"
    assert "heavecomp diagnose" not in text and "rediagnosis" not in text and "the nominal file" not in text
    assert sum(line.startswith("heavecomp ") for line in text.splitlines()) == 2


def test_what_next_of_a_segment_acts_on_the_segment():
    """A diagnosed segment of ``monitor --diagnose`` (or a ``diagnose --span``): the replay and the re-diagnosis
    lacked ``--span`` and ``simulate --heave-file`` drove the log from 0 (F1); every printed command that reads the
    log acts on the span, the one that cannot is left out, and the span's rule says the monitor chose it."""
    from heavecomp.diagnosis import span as SP
    from heavecomp.report.calibrated import what_next

    sp = SP.segment(3600.0, 1200.0, 1800.0, 1)
    assert sp.rule == "monitor" and "monitor's segment 1" in sp.reason and "asked for" not in sp.reason
    par = {"compensator.gas_stiffness": 0.6 * NOM.compensator.gas_stiffness}
    for cal in (calibrate(NOM, _diag("parameter_mismatch", par)), calibrate(NOM, _diag("none"))):
        lines = [x for x in what_next(cal, "out", run_path="log.csv", params_path="rig.toml", duration=600.0,
                                      span=sp) if x.startswith("heavecomp ")]
        reads = [x for x in lines if "log.csv" in x]
        assert all("--span 1200:1800" in x for x in reads), reads
        assert not any("--heave-file" in x or x.startswith("heavecomp monitor") for x in lines), lines
    lines = what_next(calibrate(NOM, _diag("parameter_mismatch", par)), "out", run_path="log.csv",
                      span=SP.choose(600.0, None))
    assert any("--heave-file log.csv" in x for x in lines) and not any("--span" in x for x in lines)


def test_the_monitors_diagnose_line_names_the_segments_exact_span_and_the_logs_mapping():
    """monitor's "the same diagnosis" line rounded the span to whole seconds and dropped --columns/--units (F1)."""
    from heavecomp.report.monitor import diagnosed_lines

    line = diagnosed_lines({1: (1200.5, 1800.25)}, "log.csv", "rig.toml", "mon", columns={"wob": "WOB kN"},
                           units={"wob": "kN"})[0]
    assert "--span 1200.5:1800.25" in line and "--columns 'wob=WOB kN' --units wob=kN" in line, line


def test_what_next_commands_carry_the_logs_mapping_quoted():
    """issue 31: a command that reads the log with the file the diagnosis ran against carries --columns/--units
    (the re-diagnosis reads calibrated.toml's [measurement]); paths with spaces are quoted."""
    from heavecomp.report.calibrated import what_next

    par = {"compensator.gas_stiffness": 0.6 * NOM.compensator.gas_stiffness}
    text = "\n".join(what_next(calibrate(NOM, _diag("parameter_mismatch", par)), "my out", run_path="rig log.csv",
                               params_path="rig.toml", columns={"t": "TIME_MS"}, units={"t": "ms"}))
    assert ("heavecomp replay 'rig log.csv' --params rig.toml --params 'my out/calibrated.toml' --out 'my out/replay' "
            "--columns t=TIME_MS --units t=ms") in text
    assert "heavecomp diagnose 'rig log.csv' --params 'my out/calibrated.toml' --out 'my out/rediagnosis'\n" in text


def test_a_static_force_refitted_below_the_nominal_coulomb_force_clips_it_as_the_fit_does():
    """Study rerun of spent 560028: F_S refitted to 11.2 kN, F_C left at its nominal 12 kN; the fit's model
    uses min(F_C, F_S), so the file must too (it was refused as invalid and the nominal written)."""
    fc = NOM.friction.coulomb_force
    cal = calibrate(NOM, _diag("parameter_mismatch", {"friction.static_force": 0.9 * fc,
                                                      "friction.coulomb_force": fc}))
    p = _round_trip(cal)
    assert p.friction.static_force == p.friction.coulomb_force == pytest.approx(0.9 * fc)


def test_a_named_verdicts_search_form_is_carried_in_place_of_the_named_law():
    """A laminar flow_loss verdict whose line the open search fits better as K v|v| (verdict.form,
    heavecomp.diagnosis.screen.named_form): the file carries line_term, not flow_loss; its shrink is
    measured by replaying the log (0 promised here), as a discovered term's."""
    form = {"term": "-3.79e+05*v*|v|", "features": ["v_abs_v"], "coefficients": {"v_abs_v": -3.79e5},
            "shrink": 0.93, "component": "flow_line", "replaces": "flow_loss",
            "named": {"shrink": 0.69, "bic": 76.9, "coefficients": {"flow_loss": 1.13e5}}}
    cal = calibrate(NOM, _diag("flow_loss", {"resistance": 1.14e5}, form=form))
    (e,) = spec.plant_effects(_round_trip(cal))
    assert e.name == "line_term" and e.values["v_abs_v"] == -3.79e5 and e.values["v"] == 0.0
    assert cal.expected_shrink == 0.0 and "carried in the form the open search gave" in to_toml(cal)
    # a form with no model form at its hook (the acceleration): the named law is carried
    form = dict(form, features=["a"], coefficients={"a": -9e4})
    cal = calibrate(NOM, _diag("flow_loss", {"resistance": 1.14e5}, form=form))
    assert cal.params.effects == (("flow_loss", {"resistance": 1.14e5}),) and cal.expected_shrink == 0.6


def test_a_refit_is_anchored_to_the_first_file_so_a_re_diagnosis_cannot_step_past_its_bound():
    """Spent 590029 (a seal that warms): the refit landed at 0.2 x the file's F_S (23 -> 4.6 kN) and the
    re-diagnosis of that file at 0.2 x again (0.92 kN).  The calibrated file records the values it was
    refitted from ([anchor]); a refit of it searches 0.2-5 x of those, so F_S cannot go below 4.6 kN, and
    a refit at that edge is flagged at its (anchored) bound."""
    from heavecomp.diagnosis.fitting import at_bounds
    from heavecomp.effects.candidates import ParameterMismatch as PM

    fs = NOM.friction.static_force
    first = _round_trip(calibrate(NOM, _diag("parameter_mismatch", {"friction.static_force": 0.2 * fs,
                                                                    "friction.coulomb_force": 0.2 * fs})))
    assert first.extra["anchor"].static_force == fs
    names = [f.name for f in PM.fields()]
    j = names.index("static_force")
    lo, hi = PM.search_box(first)
    assert math.exp(lo[j]) * first.friction.static_force == pytest.approx(first.friction.static_force)
    assert math.exp(hi[j]) * first.friction.static_force == pytest.approx(5 * fs)
    lo0, _ = PM.search_box(NOM)  # the nominal (no anchor): 0.2 x of its own value
    assert math.exp(lo0[j]) == pytest.approx(0.2)
    # a second refit that lands on the anchored edge is flagged there, with the bound as a multiplier of this file
    vals = {f.name: 1.0 for f in PM.fields()}
    hit = at_bounds("parameter_mismatch", vals, params=first)
    assert [(h["parameter"], h["side"]) for h in hit] == [("friction.static_force", "lower")]
    assert hit[0]["bound"] == pytest.approx(1.0)
    assert at_bounds("parameter_mismatch", vals) == []  # unanchored, 1 x is mid-box
    # a third file keeps the first anchor, not the second file's values
    second = _round_trip(calibrate(first, _diag("parameter_mismatch", {"friction.viscous_coefficient":
                                                                       2 * NOM.friction.viscous_coefficient})))
    assert second.extra["anchor"].static_force == fs
    assert second.extra["anchor"].viscous_coefficient == NOM.friction.viscous_coefficient


def test_a_re_diagnosis_term_is_added_to_the_files_own_term_not_put_in_its_place():
    """The component equations include the file's own memoryless terms, so a re-diagnosis' open-search term
    is what the file's term leaves: it is added to that term (same centre), never put in its place (the
    file's rel coefficient used to be lost); taken from another centre it cannot be summed into one entry,
    and the file's term is kept with the reason written."""
    first = NOM.replace(effects=[("string_term", {"rel": 2e5, "rel_median": 0.01})])

    def again(median):
        return _diag("discovered", discovered={"component": "string_formation", "features": ["rel_cubed"],
                                               "coefficients": {"rel_cubed": 3e9}, "term": "3e9*(rel-m)^3",
                                               "levels": {"rel_median": median}, "shrink": 0.3})

    (e,) = spec.plant_effects(_round_trip(calibrate(first, again(0.01))))
    assert e.name == "string_term" and e.values["rel"] == 2e5 and e.values["rel_cubed"] == 3e9
    cal = calibrate(first, again(0.02))
    (e,) = spec.plant_effects(_round_trip(cal))
    assert e.values["rel"] == 2e5 and e.values["rel_cubed"] == 0.0 and e.values["rel_median"] == 0.01
    assert cal.changes == [] and "cannot be added" in to_toml(cal)
