"""Issue 31, the defects of the rig engineer's loop (reproducers 2026-12: D1, D2, D6, D7, D8, U7-U13), each
checked on what the code decides; the files are generated here or kept in tests/data."""

from __future__ import annotations

import json

import numpy as np
import pytest

from _cli import run
from heavecomp.effects import spec
from heavecomp.errors import ParameterError
from heavecomp.params import dumps, loads, paper_a


def _file(tmp_path, extra: str, name="p.toml", params=None) -> str:
    f = tmp_path / name
    f.write_text(dumps(params or paper_a()) + "\n" + extra)
    return str(f)


# ---------------------------------------------------------------- D6: duplicate [[effects]]

GAIN = '[[effects]]\nname = "sensor_gain"\nchannel = "wob"\nfactor = 1.08\n'
DAMP = '[[effects]]\nname = "string_damping"\ndamping = 4.7e4\n'


@pytest.mark.parametrize("entries, words", [
    (GAIN + "\n" + GAIN, ["effects[1]", "effects[0]", "sensor_gain", "wob"]),
    (DAMP + "\n" + GAIN + "\n" + DAMP, ["effects[2]", "effects[0]", "string_damping"]),
])
def test_a_duplicate_effect_is_refused_by_index(tmp_path, entries, words):
    """A WOB gain of 1.08 written twice corrected the reading by 1.1664 without a word (D6)."""
    with pytest.raises(ParameterError) as exc:
        spec.check(loads(dumps(paper_a()) + "\n" + entries))
    assert "\n" not in str(exc.value) and all(w in str(exc.value) for w in words)
    r = run("params", _file(tmp_path, entries))
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and "effects[" in r.stderr


def test_the_same_effect_on_two_channels_is_no_duplicate():
    other = GAIN.replace('"wob"', '"stroke"')
    assert len(spec.check(loads(dumps(paper_a()) + "\n" + GAIN + "\n" + other))) == 2


# ---------------------------------------------------------------- U12: params -q, the file's effects named

def test_params_quiet_is_quiet_and_the_check_names_the_effects(tmp_path):
    f = _file(tmp_path, DAMP + "\n" + GAIN)
    quiet = run("params", f, "-q")
    assert quiet.returncode == 0 and quiet.stdout == "" and quiet.stderr == ""
    loud = run("params", f)
    assert loud.returncode == 0 and "[[effects]]" in loud.stdout
    assert "2 [[effects]]: string_damping (plant), sensor_gain on wob (reading)" in loud.stderr
