"""Controller registry: a controller is a name or an object with ``step``.

Like ``scipy.integrate.solve_ivp``'s ``method``, ``controller`` is either one of
the names in :data:`CONTROLLERS` or an object of your own that follows the loop
contract (duck-typed, no base class needed; ``docs/control.md``)::

    step(t, measurement, preview=None) -> u     # commanded active force [N]
    reset()                                     # optional: clear memory before a run

This module sits above the controllers it registers, so ``base.py``,
``linear_mpc.py`` and ``nonlinear_mpc.py`` do not import each other in a cycle.
"""

from __future__ import annotations

import dataclasses

from heavecomp.controllers.base import ControllerConfig, PassiveController, PIDController
from heavecomp.controllers.linear_mpc import LinearMPC
from heavecomp.controllers.nonlinear_mpc import NonlinearMPC
from heavecomp.errors import InputError, did_you_mean

#: name -> class(params, config)
CONTROLLERS = {
    "passive": PassiveController,
    "pid": PIDController,
    "linear-mpc": LinearMPC,
    "nonlinear-mpc": NonlinearMPC,
}


def is_controller(obj) -> bool:
    """True if ``obj`` follows the loop contract: it has a callable ``step``."""
    return callable(getattr(obj, "step", None))


def make(name, params, config: ControllerConfig | None = None, **options):
    """Build a controller by name (:data:`CONTROLLERS`) or return a given controller object.

    Parameters
    ----------
    name : str or object
        A registered name, or any object with ``step(t, measurement, preview=None) -> u``
        (returned as it is; ``options`` then do not apply).
    params : CMCParams
    config : ControllerConfig, optional
    options
        :class:`ControllerConfig` overrides (limits default to ``params``' ``[active]`` table).
    """
    if not isinstance(name, str):
        if not is_controller(name):
            raise InputError(f"controller {type(name).__name__!r}: neither a name ({', '.join(CONTROLLERS)}) "
                             "nor an object with a step(t, measurement, preview=None) method")
        if options:
            raise InputError(f"controller options {', '.join(sorted(options))}: only for a named controller; "
                             f"configure your {type(name).__name__} object directly")
        return name
    if name not in CONTROLLERS:
        raise InputError(f"controller {name!r}: not one of {', '.join(CONTROLLERS)}{did_you_mean(name, CONTROLLERS)}",
                         option="controller")
    if config is None:
        config = ControllerConfig.from_params(params, **options)
    elif options:
        config = dataclasses.replace(config, **options)
    return CONTROLLERS[name](params, config)
