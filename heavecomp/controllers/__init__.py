"""Controllers for the active cylinder: one loop contract.

Every controller takes the plant parameters and a frozen config at
construction and implements ``reset()`` and ``step(t, measurement, preview=None)
-> u`` [N].  ``measurement`` is what a rig measures (:class:`Measurement`:
stroke, pressure, WOB, heave and the active force it applied).

>>> from heavecomp.controllers import make                       # doctest: +SKIP
>>> ctrl = make("linear-mpc", paper_a())                          # doctest: +SKIP

Names (:data:`CONTROLLERS`): ``passive``, ``pid``, ``linear-mpc``, ``nonlinear-mpc``.
Heavy imports (osqp, casadi, scipy) happen in the sub-modules that need them.
"""

from heavecomp.controllers.base import (CONTROLLERS, ControllerConfig, Measurement, PassiveController,
                                        PIDController, make)

__all__ = ["CONTROLLERS", "ControllerConfig", "Measurement", "PassiveController", "PIDController", "make"]
