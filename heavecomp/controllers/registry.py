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
import inspect

from heavecomp.controllers.base import ControllerConfig, PassiveController, PIDController
from heavecomp.controllers.linear_mpc import LinearMPC
from heavecomp.controllers.nonlinear_mpc import NonlinearMPC
from heavecomp.errors import InputError, ParameterError, did_you_mean

#: name -> class(params, config)
CONTROLLERS = {
    "passive": PassiveController,
    "pid": PIDController,
    "linear-mpc": LinearMPC,
    "nonlinear-mpc": NonlinearMPC,
}


def is_controller(obj) -> bool:
    """True if ``obj`` follows the loop contract: it has a callable ``step``.

    Parameters
    ----------
    obj : object
        Any object.
    """
    return callable(getattr(obj, "step", None))


def takes_effects(name) -> bool:
    """True if the registered controller ``name`` has a model that can hold effects (the MPCs).

    Parameters
    ----------
    name : str or object
        A registered controller name (any other object: False).
    """
    return isinstance(name, str) and name in CONTROLLERS and "effects" in inspect.signature(CONTROLLERS[name]).parameters


def make(name, params, config: ControllerConfig | None = None, *, effects=None, **options):
    """Build a controller by name (:data:`CONTROLLERS`) or return a given controller object.

    Parameters
    ----------
    name : str or object
        A registered name, or any object with ``step(t, measurement, preview=None) -> u``
        (returned as it is; ``options`` then do not apply).
    params : heavecomp.params.CMCParams
        Parameter set of the plant the controller acts on (its ``[active]`` limits).
    config : ControllerConfig, optional
        Controller settings; None: :meth:`ControllerConfig.from_params` with ``options``.
    effects : sequence, optional
        Effects the controller's model knows (:mod:`heavecomp.effects`: instances, names or
        ``(name, values)``; None: the plant effects of the parameter file's ``[[effects]]``).  Plant
        effects enter its prediction model, a channel effect (``sensor_gain``, ``sensor_offset``) the way it reads its
        measurement.  Only the MPCs have a model; ``passive`` and ``pid`` take none (ParameterError
        for a non-empty ``effects``).
    **options : dict
        :class:`ControllerConfig` overrides (limits default to ``params``' ``[active]`` table).
    """
    if not isinstance(name, str):
        if not is_controller(name):
            raise InputError(f"controller {type(name).__name__!r}: neither a name ({', '.join(CONTROLLERS)}) "
                             "nor an object with a step(t, measurement, preview=None) method")
        if options or effects:
            raise InputError(f"controller options {', '.join(sorted(options) + (['effects'] if effects else []))}: only for a named controller; "
                             f"configure your {type(name).__name__} object directly")
        return name
    if name not in CONTROLLERS:
        raise InputError(f"controller {name!r}: not one of {', '.join(CONTROLLERS)}{did_you_mean(name, CONTROLLERS)}",
                         option="controller")
    if config is None:
        config = ControllerConfig.from_params(params, **options)
    elif options:
        config = dataclasses.replace(config, **options)
    cls = CONTROLLERS[name]
    if takes_effects(name):
        return cls(params, config, effects=effects)
    if effects:
        raise ParameterError(f"controller {name}: has no model to hold effects "
                             f"({', '.join(getattr(e, 'name', str(e)) for e in effects)}); use linear-mpc or nonlinear-mpc")
    return cls(params, config)
