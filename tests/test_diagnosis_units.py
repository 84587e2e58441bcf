"""diagnosis.json names the unit of every fitted parameter where it is made (issue 21 item 6): a stroke
offset is in metres and a WOB offset in newtons, though both are called ``offset``."""

from __future__ import annotations

import json

from heavecomp.report.diagnosis import write_json
from heavecomp.report.provenance import annotate_json, stamp


class _Diag:
    """A fitted diagnoser's ``to_json`` output, as far as the units need it."""

    def to_json(self):
        return {"schema": 3,
                "verdict": {"effect": "sensor_offset", "confidence": "high",
                            "parameters": {"channel": "stroke", "offset": 0.012, "drift": 1e-5}, "shrink": 0.7},
                "candidates": [{"effect": "sensor_offset", "parameters": {"channel": "wob", "offset": 2.1e3,
                                                                           "drift": 0.0}},
                               {"effect": "string_damping", "parameters": {"damping": 4.7e4}}]}


def _written(tmp_path):
    p = write_json(_Diag(), tmp_path / "diagnosis.json")
    annotate_json(p, stamp())
    return json.loads(p.read_text())


def test_a_stroke_offset_is_in_metres_and_a_wob_offset_in_newtons(tmp_path):
    d = _written(tmp_path)
    assert d["verdict"]["parameter_units"] == {"offset": "m", "drift": "m/s"}
    assert d["candidates"][0]["parameter_units"]["offset"] == "N"
    assert d["candidates"][1]["parameter_units"] == {"damping": "N s/m"}
    # the file-wide units block does not give the stroke offset a force unit
    assert d["units"].get("offset") == "m"


def test_no_declaration_block_is_left_in_the_file(tmp_path):
    d = _written(tmp_path)
    assert "_units" not in d["verdict"]["parameters"] and "_units" not in d["candidates"][0]["parameters"]
