"""Structural isolability (heavecomp.diagnosis.structure): the fault signature follows the model's
equations, and the published tables are the code's."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from heavecomp.diagnosis import components as CR
from heavecomp.diagnosis import structure as S
from heavecomp.errors import InputError
from heavecomp.params.sets import paper_a

ALL = ("heave", "stroke", "pressure", "wob")


def _same_group(iso, a, b):
    return any(a in g and b in g for g in iso["groups"])


def test_equation_channels_are_what_the_equations_read():
    """Perturb one channel at a time in components.equations: exactly the equations the table says
    read it change (the table is checked against the equations themselves, not restated)."""
    p = paper_a("stribeck")
    t = np.arange(0.0, 120.0, 0.02)
    rng = np.random.default_rng(1)
    base = {"heave": 1.2 * np.sin(2 * np.pi * t / 10.0), "stroke": -0.5 * np.sin(2 * np.pi * t / 10.0 + 0.2),
            "pressure": p.p0 + 3e5 * np.sin(2 * np.pi * t / 10.0 + 0.2),
            "wob": p.operating_point.wob_setpoint + 2e4 * np.sin(2 * np.pi * t / 10.0 + 1.0)}
    r0, _, _ = CR.equations(t, base["heave"], base["stroke"], base["pressure"], base["wob"], p)
    table = S.equation_channels()
    for ch in ALL:
        pert = dict(base)
        pert[ch] = base[ch] * (1.0 + 0.05 * np.sin(2 * np.pi * t / 7.0)) + 0.01 * np.std(base[ch]) * rng.normal(size=t.size)
        r1, _, _ = CR.equations(t, pert["heave"], pert["stroke"], pert["pressure"], pert["wob"], p)
        moved = {e for e in r0 if (np.isfinite(r0[e]) & np.isfinite(r1[e])).any()
                 and np.nanmax(np.abs(r1[e] - r0[e])) > 1e-9 * np.nanmax(np.abs(r0[e]) + 1.0)}
        assert moved == {e for e, chs in table.items() if ch in chs}, ch


def test_every_candidate_detectable_with_all_four_channels():
    iso = S.isolability(ALL)
    assert iso["undetectable"] == []
    assert set(iso["detectable"]) >= {"friction_lag", "flow_loss", "gas_leak", "string_damping", "sensor_gain:wob",
                                      "heave_reference", "parameter_mismatch"}


def test_without_pressure_gas_spring_and_flow_line_collapse():
    """gas_leak (gas spring) and flow_loss (line) differ only in the gas law, which needs the pressure:
    with it they are isolable, without it they fall into one group (seen by the replay only)."""
    assert not _same_group(S.isolability(ALL), "gas_leak", "flow_loss")
    iso = S.isolability(("heave", "stroke", "wob"))
    assert _same_group(iso, "gas_leak", "flow_loss")
    assert "gas_leak" in iso["detectable"]  # the WOB replay still sees it


def test_wob_gain_and_string_damping():
    """A WOB gain misreads W in the lower-mass AND the top-mass balance; string damping enters the
    lower-mass balance only: isolable with all four channels, not when the top-mass balance (which
    needs the pressure) is lost."""
    assert not _same_group(S.isolability(ALL), "sensor_gain:wob", "string_damping")
    assert _same_group(S.isolability(("heave", "stroke", "wob")), "sensor_gain:wob", "string_damping") is False
    # without the stroke no equation residual is left: only the WOB replay, which sees both
    assert _same_group(S.isolability(("heave", "pressure", "wob")), "sensor_gain:wob", "string_damping") is False
    assert _same_group(S.isolability(("heave", "wob")), "sensor_gain:wob", "string_damping")


def test_heave_only_detects_nothing_and_heave_is_required():
    assert S.isolability(("heave",))["detectable"] == []
    with pytest.raises(InputError, match="heave"):
        S.isolability(("stroke", "wob"))
    with pytest.raises(InputError, match="'presure'"):
        S.isolability(("heave", "presure"))


def test_heave_gain_is_the_heave_reference():
    """A heave sensor misreading and a heave the compensator does not see enter the same equations:
    structurally one group whatever the sensors."""
    for s in S.SENSOR_SETS[:-1]:
        assert _same_group(S.isolability(s), "sensor_gain:heave", "heave_reference"), s


def test_shape_level_splits_friction_by_its_signals():
    st, sh = S.isolability(ALL), S.isolability(ALL, level="shape")
    assert _same_group(st, "pressure_friction", "position_friction")
    assert not _same_group(sh, "pressure_friction", "position_friction")
    # a refinement: every shape group lies inside one structural group
    for g in sh["groups"]:
        assert any(set(g) <= set(h) for h in st["groups"])


def test_group_of():
    iso = S.isolability(("heave", "stroke", "wob"), ["flow_loss", "gas_leak", "string_damping", "sensor_gain"])
    assert S.group_of("flow_loss", iso) == ["flow_loss", "gas_leak"]
    assert S.group_of("string_damping", iso) == ["string_damping"]
    assert S.group_of("sensor_gain:pressure", iso) == []  # no pressure channel: not a candidate
    assert S.group_of("sensor_gain", iso)[0].startswith("sensor_gain:")


def test_published_tables_are_current():
    path = Path(__file__).resolve().parents[1] / "scripts" / "isolability_doc.py"
    spec = importlib.util.spec_from_file_location("isolability_doc", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    for page in mod.PAGES:  # docs/diagnosis.md publishes it (issue 23 item 3), docs/monitoring.md carries it too
        assert mod.current(page.read_text(encoding="utf-8")) == mod.section(), \
            f"docs/{page.name} is out of date: run python scripts/isolability_doc.py"
