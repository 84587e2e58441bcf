"""casadi import with numpy support switched on, for tracing the np.* physics functions."""

from __future__ import annotations


def casadi():
    """Import casadi with its numpy-aware mode (``np.exp(SX)`` -> ``casadi.exp``).

    The plant and friction functions are written with ``np.*`` calls so numba
    can compile them; casadi's numpy mode 1 makes the same calls build
    symbolic expressions.
    """
    import casadi as ca

    try:
        ca.GlobalOptions.setNumpyMode(1)
    except AttributeError:  # casadi < 3.7 has no switch and follows the input type
        pass
    return ca
