"""scenarios/campaign_default.py --quick: runs, writes its report, and friction orders the band exceedance."""

import json
import runpy
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_campaign_default_quick(tmp_path):
    main = runpy.run_path(str(ROOT / "scenarios" / "campaign_default.py"), run_name="scenario")["main"]
    assert main(["--quick", "--out", str(tmp_path)]) == 0  # in this process: the script's own work only
    m = json.loads((tmp_path / "metrics.json").read_text())
    lt = m["long_term"]
    assert m["n_runs"] == 81
    # paper A section 4 over a whole scatter diagram: no friction < eq. 7 < eq. 4 in time outside the band
    assert lt["none/base"]["frac_outside_band"] < lt["rotating_eq7/base"]["frac_outside_band"] \
        < lt["stribeck/base"]["frac_outside_band"]
    assert m["verdict"]["ordered_none_eq7_stribeck"]
    assert 0 < m["verdict"]["share_won_back_by_eq7"] < 1
    for g in lt.values():
        assert 0 <= g["p_leave_exposure"] <= 1
        # the deviation exceeded 0.1 % of the time lies beyond the one exceeded 1 % of the time
        assert g["dev_exceeded_1e-3"] > g["dev_exceeded_1e-2"] > 0
    for f in ("report.md", "exceedance_long_term.png", "exceedance_short_term.png", "band_by_sea_state.png"):
        assert (tmp_path / f).stat().st_size > 1000
