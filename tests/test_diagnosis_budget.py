"""A log too long to replay is refused before any work, in one line (the run-size budget)."""

import numpy as np
import pytest

from heavecomp.diagnosis import GapDiagnoser
from heavecomp.diagnosis.data import check_run
from heavecomp.errors import InputError
from heavecomp.params import paper_a


def test_a_30_hour_log_is_refused_naming_its_length():
    p = paper_a("stribeck")
    t = np.arange(0.0, 30 * 3600.0, 1.0)  # 30 h at 1 Hz: 1.08e7 replay steps at the 10 ms replay step
    z = 0.5 * np.sin(2 * np.pi * t / 12.0)
    cols = {"heave": z, "stroke": -z, "pressure": np.full(t.size, 1e7), "wob": np.full(t.size, 2e5)}
    run = check_run(t, cols, params=p, source="long.csv")
    with pytest.raises(InputError) as exc:
        GapDiagnoser(p).fit(run)
    msg = str(exc.value)
    assert "\n" not in msg and msg.startswith("long.csv: the log is 30 h long") and "budget" in msg
