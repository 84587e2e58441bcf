"""Effects as submodels at the CMC's hooks (one class per file) and the diagnosis' candidates.

``heavecomp.effects.base`` defines the hooks and the :class:`Effect` base class; one module per
effect holds its class; :mod:`heavecomp.effects.registry` lists them; :mod:`heavecomp.effects.compose`
composes the plant's hook functions for a set of effects (numba and casadi use the same source);
:func:`get` resolves a contract name (``friction_lag``, ...) to its candidate class.
"""

from heavecomp.effects.base import Effect
from heavecomp.effects.candidates import CANDIDATES, EFFECT_NAMES, get

__all__ = ["CANDIDATES", "EFFECT_NAMES", "Effect", "get"]
