"""Candidate unmodelled effects of the CMC, one class each (issue 4).

``heavecomp.effects.terms`` holds the equations (scalar ``np.*``);
``heavecomp.effects.candidates`` the classes the diagnosis fits;
:func:`get` resolves a contract name (``friction_lag``, ...) to its class.
"""

from heavecomp.effects.candidates import CANDIDATES, EFFECT_NAMES, get

__all__ = ["CANDIDATES", "EFFECT_NAMES", "get"]
