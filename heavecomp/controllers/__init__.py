"""Controllers for the active cylinder: one loop contract.

Every controller takes the plant parameters and a frozen config at
construction and implements ``reset()`` and ``step(t, measurement, preview=None)
-> u`` [N].  ``measurement`` is what a rig measures (:class:`Measurement`:
stroke, pressure, WOB, heave and the active force it applied).  The contract is
duck-typed: any object with ``step`` can be put in the loop (``docs/control.md``).

>>> from heavecomp.controllers import make                       # doctest: +SKIP
>>> ctrl = make("linear-mpc", paper_a())                          # doctest: +SKIP

Names (:data:`CONTROLLERS`): ``passive``, ``pid``, ``linear-mpc``, ``nonlinear-mpc``.
Heavy imports (osqp, casadi, scipy) happen in the sub-modules' functions that need them.
"""

from heavecomp.controllers.base import (Controller, ControllerConfig, Measurement, PassiveController,
                                        PIDController)
from heavecomp.controllers.registry import CONTROLLERS, is_controller, make

__all__ = ["CONTROLLERS", "Controller", "ControllerConfig", "Measurement", "PassiveController", "PIDController",
           "is_controller", "make"]
