"""scenarios/frequency_response.py --quick: the metrics say what the physics says."""

import json
import runpy
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_frequency_response_scenario(tmp_path):
    mod = runpy.run_path(str(ROOT / "scenarios" / "frequency_response.py"), run_name="scenario")
    assert mod["main"](["--quick", "--out", str(tmp_path)]) == 0
    m = json.loads((tmp_path / "metrics.json").read_text())
    assert m["k_eff_dc"] == pytest.approx(m["k_eff_eq14"], rel=1e-9)
    # paper A: both eigenfrequencies above the wave band (periods 5-20 s)
    assert min(m["natural_frequencies"]) > 2 * 3.141592653589793 / 5 and not any(m["modes_in_wave_band"])
    # soft formations bring the lower mode into the band, at every string length of the map
    assert all(k is not None and k < 1e6 for k in m["map_kF_max_with_mode_in_band"])
    # describing function within its stated tolerance while sliding; the locked-stroke limit exact
    assert m["df_max_rel_error_sliding"] < m["df_tolerance"]
    assert m["df_max_rel_error_locked"] < 1e-3
    # viscous friction damps the lower mode more than the frictionless model's formation damping
    assert m["viscous"]["damping_ratios"][0] > m["damping_ratios"][0]
    for f in ("report.md", "eigenfrequency_map.png", "describing_function.png", "paper_a/analysis.json",
              "paper_a/bode.png", "paper_a/frequency_response.csv"):
        assert (tmp_path / f).is_file()
