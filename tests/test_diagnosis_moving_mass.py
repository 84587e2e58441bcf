"""A heavier moving mass is a parameter error (issue 30 items 3 and 4).

The compensator's top mass 10-25 % heavier than the parameter file, run as a rig runs it: the charge
raised in the same gas bank until the WOB is the driller's set-point again (the benchmark generator's own
law, ``parameter_mismatch`` variant ``moving_mass``).  The log's pressure then sits a constant above the
nominal's, which a pressure ``sensor_gain`` or ``sensor_offset`` matches on that channel alone; only the
refit of the nominal's own top mass explains the stroke and WOB too.  The diagnosis names
``parameter_mismatch`` with the mass moved near its truth, ``calibrated.toml`` carries it, and replaying
the log under that file gives the shrink the diagnosis reported.
"""

from __future__ import annotations

import json

import pytest

from heavecomp.cli import main
from heavecomp.diagnosis.calibrate import replay_shrink
from heavecomp.diagnosis.policy import VerdictPolicy
from heavecomp.diagnosis.screen import mismatch_room
from heavecomp.effects.candidates import MISMATCH_KEYS, ParameterMismatch
from heavecomp.effects.spec import load
from heavecomp.params import dumps, paper_a
from heavecomp.params.core import G

MASS = "compensator.moving_mass"


def _multipliers(**moved):
    return {f.name: moved.get(f.name, 1.0) for f in ParameterMismatch.fields()}


def test_a_refitted_heavier_mass_keeps_the_set_point_in_the_same_gas_bank():
    """The refit's mass multiplier is a heavier top mass run at the same WOB set-point: the operating
    point's charge carries the extra weight (p_0 A = (M_c + m_b) g - W_0) and the gas bank's volume is
    the file's, so the gas stiffness rises with the absolute charge; the gas multiplier still scales the
    bank alone."""
    p = paper_a()
    heavy = ParameterMismatch.apply(p, _multipliers(moving_mass=1.18))
    dm = 0.18 * p.compensator.moving_mass
    assert heavy.compensator.moving_mass == pytest.approx(1.18 * p.compensator.moving_mass)
    assert (heavy.p0 - p.p0) * p.area == pytest.approx(dm * G, rel=1e-9)
    assert heavy.gas_volume == pytest.approx(p.gas_volume, rel=1e-12)
    assert heavy.compensator.gas_stiffness / p.compensator.gas_stiffness == pytest.approx(
        (heavy.p0 + 101325.0) / (p.p0 + 101325.0), rel=1e-3)
    both = ParameterMismatch.apply(p, _multipliers(moving_mass=1.18, gas_stiffness=0.8))
    assert both.gas_volume == pytest.approx(p.gas_volume / 0.8, rel=1e-12)
    # the reported values are the model's
    named = ParameterMismatch.named_values(p, _multipliers(moving_mass=1.18))
    assert named[MASS] == heavy.compensator.moving_mass
    assert named["compensator.gas_stiffness"] == pytest.approx(heavy.compensator.gas_stiffness)


def test_the_refit_leaves_the_mass_out_only_when_neither_equation_it_enters_shows_a_gap():
    """A heavier mass enters the gas law (the charge it sets) and the top-mass balance (its weight and
    inertia): the stepwise refit may release it when either shows a gap, and leaves it out, saying why,
    when both are quiet."""
    P = VerdictPolicy()
    comps = ("friction", "gas_spring", "flow_line", "string_formation", "sensors", "heave_input")
    seen = {c: True for c in comps}
    i = [k for k, _, _ in MISMATCH_KEYS].index(MASS)

    def room(**gaps):
        gap = {c: gaps.get(c, 0.0) for c in comps}
        total = sum(gap.values()) or 1.0
        return mismatch_room(gap, {c: g / total for c, g in gap.items()}, seen, {}, P)

    quiet = room(string_formation=500.0)
    assert i not in quiet["room"] and MASS in quiet["left_out"]
    assert i in room(gas_spring=500.0)["room"]
    assert i in room(friction=500.0)["room"]


@pytest.fixture(scope="module")
def diagnosed(tmp_path_factory):
    """A 90 s log of a top mass 10-25 % heavier than the file (benchmark generator), diagnosed by the CLI."""
    from heavecomp.benchmark import Case, generate

    d = tmp_path_factory.mktemp("mass")
    tr = generate(Case("parameter_mismatch", 7, "named", duration=90.0, variant="moving_mass"))
    log, nom = tr.to_csv(d / "run.csv"), d / "nominal.toml"
    nom.write_text(dumps(tr.nominal))
    assert main(["diagnose", str(log), "--params", str(nom), "--out", str(d / "diag"), "--quiet"]) == 0
    return d, tr, json.loads((d / "diag" / "diagnosis.json").read_text())


@pytest.mark.slow
def test_a_heavier_moving_mass_is_diagnosed_as_a_parameter_mismatch_and_calibrated(diagnosed):
    """~11 s of CPU: one 90 s diagnosis through the CLI."""
    d, tr, diag = diagnosed
    truth = tr.truth["parameters"]["parameter_mismatch"]
    v = diag["verdict"]
    print(json.dumps({k: v.get(k) for k in ("effect", "confidence", "component", "group", "shrink", "parameters")}))
    assert v["effect"] == "parameter_mismatch"
    got = v["parameters"]
    assert got[MASS] == pytest.approx(truth[MASS], rel=0.03)
    # the friction, string and formation stay the file's: the mass alone explains the log
    for key, table, name in MISMATCH_KEYS:
        if table in ("friction", "drill_string", "formation"):
            assert got[key] == getattr(getattr(tr.nominal, table), name), key
    # calibrated.toml carries the mass, and replaying the log under it gives the reported shrink
    cal = load(d / "diag" / "calibrated.toml")
    assert cal.compensator.moving_mass == pytest.approx(got[MASS])
    assert any(c["name"] == MASS for c in diag["calibrated"]["changes"])
    r = replay_shrink(d / "run.csv", cal, load(d / "nominal.toml"), diag)
    assert r["reported"] == pytest.approx(diag["calibrated"]["expected_shrink"])
    assert abs(r["shrink"] - r["reported"]) <= 0.1 * r["reported"]
    assert r["reported"] > 0.9
