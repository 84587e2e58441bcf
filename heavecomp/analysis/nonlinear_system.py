"""The CMC as a python-control nonlinear system (``control.nlsys``) with smooth friction and named signals.

The right-hand side and the outputs are the casadi model of :func:`heavecomp.effects.model.casadi_model`
(the plant equations written once), evaluated numerically: nothing is restated here.  Use it to
simulate with ``control.input_output_response``, to interconnect with your own controller
(``control.interconnect`` by signal name) or to linearise with ``control.linearize``; the latter
agrees with :func:`heavecomp.analysis.linearise` (tested).  ``control.linearize`` names the linear
system's signals generically unless told otherwise: pass ``copy_names=True`` to keep ``heave``,
``wob``, ... (``ct.linearize(sys, x0, u0, copy_names=True)``; tested).

>>> from heavecomp.params import paper_a
>>> from heavecomp.analysis.nonlinear_system import cmc_nlsys
>>> sys = cmc_nlsys(paper_a("none"))
>>> sys.input_labels
['heave', 'heave_velocity', 'heave_acceleration', 'u_active']

Signals (SI units; states are deviations from the operating point, outputs absolute):

- states ``stroke`` s [m], ``stroke_velocity`` v [m/s], ``lower_displacement`` y_b [m],
  ``lower_velocity`` v_b [m/s];
- inputs ``heave`` z_h [m], ``heave_velocity`` [m/s], ``heave_acceleration`` [m/s^2] (the plant
  is driven by the heave and its derivatives: the stroke is measured on the moving platform),
  ``u_active`` [N];
- outputs ``wob`` [N], ``stroke`` [m], ``pressure`` [Pa] (gauge), ``tension`` [N], ``friction`` [N].

The friction is the set's own law with ``sign(v)`` replaced by ``tanh(v/eps)``
(:func:`heavecomp.friction.laws.friction_smooth`): stick-slip is *not* exact here; for exact
stick-slip use :func:`heavecomp.simulate.simulate`.
"""

from __future__ import annotations

import numpy as np

from heavecomp.analysis.linear import RAW_INPUTS, RAW_OUTPUTS, RAW_STATES
from heavecomp.effects.model import casadi_model
from heavecomp.friction.laws import FrictionLaw
from heavecomp.errors import ParameterError

#: units of the signals, by name
SIGNAL_UNITS = {"stroke": "m", "stroke_velocity": "m/s", "lower_displacement": "m", "lower_velocity": "m/s",
                "heave": "m", "heave_velocity": "m/s", "heave_acceleration": "m/s^2", "u_active": "N",
                "wob": "N", "pressure": "Pa", "tension": "N", "friction": "N"}


def cmc_nlsys(params, *, eps: float | None = None, name: str = "cmc"):
    """The CMC as a ``control.NonlinearIOSystem``.

    Parameters
    ----------
    params : CMCParams
        Validated parameter set.
    eps : float [m/s], optional
        Width of the friction's smooth sign ``tanh(v/eps)``; required when the friction law
        has stiction (``stribeck``, ``rotating_eq6``/``eq7``), ignored for ``none``.
    name : str
        System name (for ``control.interconnect``).

    Returns
    -------
    control.NonlinearIOSystem
        States, inputs and outputs named as in the module docstring; ``sys.x0`` (attribute)
        is the operating point's state (zeros) and ``sys.u0`` its input (zeros).
    """
    import control as ct


    law = FrictionLaw.from_params(params.friction)
    if law.has_stiction and not (eps is not None and eps > 0 and np.isfinite(eps)):
        raise ParameterError(f"eps: friction.model = \"{params.friction.model}\" has stiction; give the smooth "
                             "sign's width eps > 0 [m/s] (e.g. 1e-3)")
    f = casadi_model(params, eps=eps)

    def updfcn(t, x, u, p):
        return np.asarray(f(x, u)[0], dtype=float).ravel()

    def outfcn(t, x, u, p):
        return np.asarray(f(x, u)[1], dtype=float).ravel()

    sys = ct.nlsys(updfcn, outfcn, states=list(RAW_STATES), inputs=list(RAW_INPUTS), outputs=list(RAW_OUTPUTS),
                   name=name)
    sys.x0 = np.zeros(len(RAW_STATES))
    sys.u0 = np.zeros(len(RAW_INPUTS))
    return sys


def heave_to_output_response(A, B, C, D, omega, output: int = 0):
    """Frequency response heave -> output of a model driven by (z_h, dz_h, ddz_h, u_active).

    ``G(jw) = C (jwI - A)^-1 (B_0 + jw B_1 - w^2 B_2) + D_0 + jw D_1 - w^2 D_2`` [output unit per m].

    Parameters
    ----------
    A : (n, n) array
        State matrix.
    B : (n, 4) array
        Input matrix, columns (z_h [m], dz_h [m/s], ddz_h [m/s^2], u_active [N]).
    C : (p, n) array
        Output matrix.
    D : (p, 4) array
        Feedthrough, columns as ``B``.
    omega : float or array [rad/s]
        Frequencies.
    output : int
        Row of ``C`` (and ``D``) whose response is returned.
    """
    A, B, C, D = (np.asarray(M, dtype=float) for M in (A, B, C, D))
    out = []
    n = A.shape[0]
    for w in np.atleast_1d(omega):
        s = 1j * w
        b = B[:, 0] + s * B[:, 1] + s * s * B[:, 2]
        d = D[output, 0] + s * D[output, 1] + s * s * D[output, 2]
        out.append(C[output] @ np.linalg.solve(s * np.eye(n) - A, b) + d)
    return np.array(out)
