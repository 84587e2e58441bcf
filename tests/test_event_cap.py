"""The stepper's event cap (issue 14.9): a motion that starts at v = 0 (right after a
reversal or a breakaway) and stops again inside the same step is located, not re-found
at the start of the sub-step until the 8-event cap finishes the step without events.

Before the fix the zero of v was "found" at t = 0 of the remaining sub-step (the cubic
guess returned its trivial root), the same reversal was taken again and again, the cap
ended the step sliding the wrong way and left a sample with F_f v < 0
(24 h JONSWAP, H_s 1 m, T_p 12 s: 8 cap hits at the default step, F_f v down to -11.3 W;
H_s 2 m: 57; docs/numerics.md).
The two reproducers below hit the cap before the fix (checked against the previous
kernel: 8 reversals in one step; a 41 s sine run with F_f v = -0.10 W at t = 36.15 s).
"""

from __future__ import annotations

import logging

import numpy as np
import pytest

from heavecomp.params import paper_a
from heavecomp.simulate import _kernel as K
from heavecomp.simulate import simulate
from heavecomp.plants.cmc import plant_vectors
from heavecomp.simulate.core import check_events, default_dt
from heavecomp.simulate.excitation import make_heave
from heavecomp.simulate.layout import SLIDING, STATS, STUCK, Drive, Plant

# paper-A case with a sine heave whose 5th reversal (t ~ 36 s) leaves the static limit by
# so little that the motion stops again within 10 ms: inside one 25 ms step
SINE = {"amplitude": 1.176, "period": 9.65, "ramp": 2.67}


def _events(res):
    return tuple(int(res.stats[k]) for k in ("n_stick", "n_breakaway", "n_reversal"))


def test_short_slip_after_a_reversal_is_located_at_the_default_step():
    """41 s from rest: no step hits the cap, friction never feeds power into the stroke,
    and the default step sees the same events (and stuck time) as a step 8x smaller."""
    p = paper_a("stribeck").replace(heave=SINE)
    h = default_dt(p, 20.0)
    res = simulate(p, 37.0)
    fine = simulate(p, 37.0, dt=h / 8)
    for r in (res, fine):
        assert r.event_cap_hits == 0 and r.metrics()["event_cap_hits"] == 0
        assert r.metrics()["event_cap_first_t"] is None
        power = r.friction_power()
        assert np.all(power >= 0.0), power.min()
        assert np.all(power[r["stuck"] == 1.0] == 0.0)
    assert _events(res) == _events(fine)
    assert res.stats["n_reversal"] >= 4 and res.stats["n_stick"] >= 4
    assert abs(res.stats["stuck_time"] - fine.stats["stuck_time"]) < 1e-3


def test_one_step_from_a_saved_jonswap_state_reverses_then_sticks():
    """The first cap hit of a 1 h JONSWAP run (H_s 1 m, T_p 12 s, seed 0), t = 479.625 s:
    sliding down at 3.8 mm/s, the stroke stops after 5.5 ms with the holding force just
    above the static limit (28.8 kN vs 27.9 kN), reverses, and stops again ~18 ms later
    when the holding force has fallen below the friction: one reversal, one stick, at rest
    for the last 1.03 ms of the step (1.0297 ms in 5 and in 25 steps of h/5, h/25)."""
    p = paper_a("stribeck").replace(heave={"kind": "jonswap", "hs": 1.0, "tp": 12.0, "seed": 0,
                                           "amplitude": None, "period": None, "ramp": None})
    h = 0.025
    hs = make_heave(p.heave, 3600.0, 0.5 * h)
    pv = plant_vectors(p)
    state = np.array([-0.4330494954617954, -0.0038108388064242715, 0.020136018167088973, 0.05464465285339529, 0.0])
    mode_dir = np.array([float(SLIDING), -1.0])
    stats = np.zeros(len(STATS))
    out = np.zeros((2, K.NCH))
    K.advance(state, mode_dir, 479.625, 1, h, Plant(pv.code, pv.FP, pv.PP, np.zeros(0), False),
              Drive(0.0, 0.5 * h, hs.z, hs.dz, hs.ddz), out, 1, 0, stats)
    st = dict(zip(STATS, stats))
    assert st["event_cap_hits"] == 0
    assert (st["n_reversal"], st["n_stick"], st["n_breakaway"]) == (1, 1, 0)
    assert mode_dir[0] == STUCK and state[1] == 0.0
    assert abs(st["stuck_time"] - 1.0297e-3) < 1e-4
    friction, v = out[:, K.CHANNELS.index("friction")], out[:, K.CHANNELS.index("stroke_velocity")]
    assert np.all(friction * v >= 0.0)


@pytest.mark.parametrize("a0, v1, a1", [(0.01, -2e-4, -0.03), (-0.4, 1e-3, 0.5), (1e-6, -1e-9, -1e-5)])
def test_rest_root_is_the_stop_of_the_motion_not_its_start(a0, v1, a1):
    """From v = 0 the Hermite cubic's root at t = 0 is the event already taken; the
    location returns the interior root, where the cubic changes sign."""
    H = 0.02
    tz = K._cubic_root(0.0, a0, v1, a1, H)
    assert 0.0 < tz < H

    def cubic(t):
        th = t / H
        return (th ** 3 - 2 * th ** 2 + th) * H * a0 + (-2 * th ** 3 + 3 * th ** 2) * v1 + (th ** 3 - th ** 2) * H * a1

    assert abs(cubic(tz)) < 1e-12 * max(abs(a0) * H, abs(v1))
    assert np.sign(cubic(0.999 * tz)) == np.sign(a0) and np.sign(cubic(tz + 1e-3 * (H - tz))) == np.sign(v1)


def test_cap_hits_and_negative_friction_power_are_reported_with_their_time(caplog):
    """The stepper's own diagnostics: a cap hit and a sample with F_f v < 0 are logged
    with the time (here fed by hand: the stepper no longer produces them)."""
    data = np.zeros((3, K.NCH))
    data[:, 0] = [0.0, 0.05, 0.1]
    data[1, K.CHANNELS.index("friction")] = 2.0e4
    data[1, K.CHANNELS.index("stroke_velocity")] = -6e-4
    stats = dict(zip(STATS, [0.0] * len(STATS)))
    with caplog.at_level(logging.WARNING, logger="heavecomp.simulate.core"):
        assert check_events(data[[0, 2]], stats) == 0
    assert caplog.records == []
    stats.update(event_cap_hits=3.0, event_cap_first_t=12.5)
    with caplog.at_level(logging.WARNING, logger="heavecomp.simulate.core"):
        assert check_events(data, stats) == 1
    text = caplog.text
    assert "event cap hit in 3 step(s), first at t = 12.5 s" in text
    assert "-12 W at t = 0.05 s" in text
