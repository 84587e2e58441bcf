"""The calibration validation's scoring guards (issue 22): fresh seeds only, frozen diagnosis settings."""

from __future__ import annotations

import importlib.util

from heavecomp.report.scenario import ROOT


def _scenario():
    spec = importlib.util.spec_from_file_location("calibration_validation",
                                                  ROOT / "scenarios" / "calibration_validation.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_the_seed_base_sets_every_case_seed_and_a_spent_range_is_refused(tmp_path, capsys):
    cv = _scenario()
    assert [c.seed for c in cv.cases(seed0=560000)][:3] == [560000, 560001, 560002]
    # 210000+ is this scenario's own spent first scoring run: refused before any run starts
    assert cv.main(["--seed-base", "210000", "--out", str(tmp_path)]) == 2
    assert "spent" in capsys.readouterr().err
    assert not (tmp_path / "metrics.json").exists()
