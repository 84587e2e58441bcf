"""``string_hysteresis`` (a Bouc-Wen share of the string's stiffness, issue 30 item 4): its loop, its
equation-error feature pinned to its own rate, and its null."""

import numpy as np
import pytest

from heavecomp.effects.features import hysteretic_displacement
from heavecomp.effects.string_hysteresis import StringHysteresis as SH


def _euler(e, zy, n, sub=400):
    """z = w + e by the effect's own ``string_rates`` (of w) in fine explicit steps of the stretch."""
    z = [0.0]
    w = -e[0]
    for k in range(e.size - 1):
        d = (e[k + 1] - e[k]) / sub
        for j in range(sub):
            w += SH.string_rates(d, e[k] + j * d, (w,), None, 1.0, zy, n)[0]
        z.append(w + e[k + 1])
    return np.array(z)


@pytest.mark.parametrize("n", [1.0, 2.0])
def test_the_feature_loop_is_the_effects_own_rate(n):
    e = 0.006 * np.sin(np.linspace(0, 6 * np.pi, 120)) * np.linspace(0.3, 1.0, 120)
    zy = 2e-3
    fast, ref = hysteretic_displacement(e, zy, n), _euler(e, zy, n)
    assert np.max(np.abs(fast - ref)) < 0.02 * zy


def test_the_element_yields_at_its_displacement_and_unloads_elastically():
    zy = 2e-3
    e = np.concatenate([np.linspace(0, 0.02, 200), np.linspace(0.02, 0.0, 200)[1:]])
    z = hysteretic_displacement(e, zy)
    assert z[199] == pytest.approx(zy, rel=1e-3)  # saturated after 10 z_y of loading
    # unloading: elastic until z crosses 0 (one z_y of stretch back), dz/de = 1
    back = z[199] - z[210]
    assert back == pytest.approx(e[199] - e[210], rel=1e-6)


def test_a_closed_stretch_cycle_dissipates_per_cycle_not_per_rate():
    """The loop's area (energy per cycle, the integral of h (z - e) de around it) is the same at any
    speed of the cycle: the law is rate independent, unlike a dashpot; and it is positive (it dissipates)."""
    zy, h = 2e-3, 5e5
    areas = []
    for samples in (200, 2000):
        e = 0.008 * np.sin(np.linspace(0, 4 * np.pi, samples))
        z = hysteretic_displacement(e, zy)
        half = samples // 2  # the second cycle, on the loop
        f = h * (z - e)  # the element's part of the tension: the work the stretch does on it over a cycle
        areas.append(float(np.sum(0.5 * (f[half + 1:] + f[half:-1]) * np.diff(e[half:]))))
    assert areas[0] > 0
    assert areas[0] == pytest.approx(areas[1], rel=0.02)
    # an elastic-perfectly-plastic element at this amplitude: 4 h z_y (A - z_y); the smooth knee (n = 1) is less
    assert areas[0] < 4 * h * zy * (0.008 - 0.0) and areas[0] > 0.5 * 4 * h * zy * (0.008 - zy)


def test_zero_stiffness_is_the_nominal_string():
    T = 1e5 + 2e6 * 0.003
    assert SH.string(0.1, T, (0.001,), np.full(20, 2e6), 0.0, 2e-3, 1.0) == T


def test_the_linear_model_at_rest_is_the_nominal_one():
    """Linearised at rest the element is elastic: its state's rate has no first-order term (a zero row, held
    by the frequency analysis), so the linear model is the nominal one (its static gain included)."""
    from heavecomp.analysis.frequency import dc_gain, drift_states
    from heavecomp.analysis.linear import linearise
    from heavecomp.params import paper_a

    p = paper_a("none")
    sys = linearise(p, effects=[SH(share=0.3, yield_displacement=2e-3)])
    assert drift_states(sys) == ["string_hysteresis.w"]
    assert dc_gain(sys, hold=drift_states(sys)) == pytest.approx(dc_gain(linearise(p, effects=[])), rel=1e-9)


def test_its_equation_error_form_sees_the_loop_not_a_stiffness_that_is_off():
    """On a string residual that is a stiffness error (a force along the stretch) the loop's column shrinks
    nothing held out (that is parameter_mismatch's); on a Bouc-Wen residual it finds the loop's h and z_y."""
    from heavecomp.diagnosis import equation_error as EE

    rng = np.random.default_rng(3)
    t = np.arange(6000) * 0.1
    e = 0.006 * np.sin(2 * np.pi * t / 11.0) + 0.003 * np.sin(2 * np.pi * t / 7.3 + 1.0)
    from heavecomp.plants.cmc import KDS

    PP = np.zeros(KDS + 1)
    PP[KDS] = 2e6
    sig = {"t": t, "dz": e, "PP": PP}
    fit, validate = t < 400, t >= 400
    noise = 400.0 * rng.normal(size=t.size)
    stiff = EE.rank_effects(-2e5 * e + noise, sig, [SH], fit, validate)[0]
    assert stiff["shrink"] < EE.MIN_SHRINK
    h, zy = 5e5, 2e-3
    loop = -h * (hysteretic_displacement(e, zy) - e)  # the WOB the element takes off: -h (z - e)
    found = EE.rank_effects(loop + noise, sig, [SH], fit, validate)[0]
    start = SH.from_equation_error(found, sig)
    # what is left of the loop once a stiffness has taken its part along the stretch is all the column's
    X = np.column_stack([np.ones(t.size), e])
    rest = loop - X @ np.linalg.lstsq(X, loop, rcond=None)[0]
    assert EE.rank_effects(rest + 0.1 * noise, sig, [SH], fit, validate)[0]["shrink"] > 0.9
    assert start["yield_displacement"] == pytest.approx(zy, rel=0.5)
    assert start["share"] == pytest.approx(h / 2e6, rel=0.3)
