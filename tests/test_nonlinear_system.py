"""Issue 13.5: a python-control nonlinear system of the CMC whose linearisation agrees with linearise()."""

import numpy as np
import pytest

from heavecomp.analysis import linear as L
from heavecomp.analysis.nonlinear_system import cmc_nlsys, heave_to_output_response
from heavecomp.errors import ParameterError
from heavecomp.params import paper_a

OMEGA = np.geomspace(0.05, 50.0, 40)


def _lti_response(sys, out, inp, omega):
    return np.array([sys(1j * w)[sys.output_labels.index(out), sys.input_labels.index(inp)] for w in omega])


def test_named_signals_and_the_operating_point():
    p = paper_a("none")
    sys = cmc_nlsys(p)
    assert sys.state_labels == list(L.RAW_STATES)
    assert sys.output_labels == ["wob", "stroke", "pressure", "tension", "friction"]
    xdot = sys.dynamics(0.0, sys.x0, sys.u0)
    y = sys.output(0.0, sys.x0, sys.u0)
    np.testing.assert_allclose(xdot, 0.0, atol=1e-6)  # at rest at the operating point
    assert y[0] == pytest.approx(p.operating_point.wob_setpoint, rel=1e-12)
    assert y[2] == pytest.approx(p.p0, rel=1e-9)


@pytest.mark.parametrize("case", ["none", "sliding"])
def test_linearize_agrees_with_linearise(case):
    import control as ct  # here, not at collection: python-control imports scipy.signal and matplotlib
    if case == "none":
        p, v0, eps = paper_a("none"), None, None
        ref = L.linearise_details(p, friction="none")
    else:
        p, v0 = paper_a("stribeck"), 0.1
        eps = v0 / 25
        ref = L.linearise_details(p, friction="sliding", velocity=v0, eps=eps)
    sys = cmc_nlsys(p, eps=eps)
    op = ref.op
    lin = ct.linearize(sys, op.x, op.u)
    # same state coordinates as the raw jacobians: A and C agree entry by entry (finite differences vs AD)
    np.testing.assert_allclose(lin.A, ref.A, rtol=1e-5, atol=1e-6 * np.abs(ref.A).max())
    np.testing.assert_allclose(lin.C[:4], ref.C[:4], rtol=1e-5, atol=1e-6 * np.abs(ref.C[:4]).max())
    # and the input-output behaviour equals linearise()'s proper LTI model (state-shifted heave input)
    g_nl = heave_to_output_response(lin.A, lin.B, lin.C, lin.D, OMEGA, output=0)
    g_ref = _lti_response(ref.sys, "wob", "heave", OMEGA)
    np.testing.assert_allclose(g_nl, g_ref, rtol=1e-4)
    k_nl = np.array([lin(1j * w)[0, 3] for w in OMEGA])
    np.testing.assert_allclose(k_nl, _lti_response(ref.sys, "wob", "u_active", OMEGA), rtol=1e-4)
    if case == "none":  # paper A eq. 14 at DC
        assert abs(g_nl[0]) == pytest.approx(p.k_eff, rel=1e-3)


def test_stiction_needs_a_smoothing_width():
    with pytest.raises(ParameterError, match="eps"):
        cmc_nlsys(paper_a("stribeck"))


def test_simulates_with_input_output_response():
    import control as ct  # here, not at collection: python-control imports scipy.signal and matplotlib
    p = paper_a("stribeck")
    sys = cmc_nlsys(p, eps=1e-3)
    t = np.linspace(0, 2.0, 201)
    w = 2 * np.pi / 12
    u = np.vstack([0.01 * np.sin(w * t), 0.01 * w * np.cos(w * t), -0.01 * w * w * np.sin(w * t), 0 * t])
    r = ct.input_output_response(sys, t, u, sys.x0)
    df = r.to_pandas()
    assert {"time", "wob", "heave", "stroke"} <= set(df.columns)
    assert np.isfinite(df["wob"]).all() and df["wob"].std() > 0


def test_linearize_keeps_signal_names_with_copy_names():
    """The documented door: ``ct.linearize(..., copy_names=True)`` keeps the nlsys' signal names (without it
    python-control names them generically, which is why the docs say to pass it)."""
    import control as ct

    p = paper_a("none")
    op = L.linearise_details(p, friction="none").op
    sys = cmc_nlsys(p)
    lin = ct.linearize(sys, op.x, op.u, copy_names=True)
    assert lin.input_labels == sys.input_labels and lin.output_labels == sys.output_labels
    assert "wob" in lin.output_labels and "heave" in lin.input_labels
