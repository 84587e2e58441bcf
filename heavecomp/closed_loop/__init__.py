"""Closed loop: the exact stick-slip CMC stepper with a controller in the loop.

This layer sits above both the stepper (:mod:`heavecomp.simulate`) and the
controllers (:mod:`heavecomp.controllers`); neither imports it.

>>> from heavecomp.closed_loop import simulate_closed_loop, Noise     # doctest: +SKIP
>>> res = simulate_closed_loop(paper_a("stribeck"), "linear-mpc", 240.0)  # doctest: +SKIP

- :mod:`~heavecomp.closed_loop.loop` — :func:`simulate_closed_loop`, :class:`Noise`,
  :class:`ClosedLoopResult`;
- :mod:`~heavecomp.closed_loop.design` — the controller-design study (compare, sweeps,
  robustness) used by ``scenarios/controller_design.py``.
"""

from heavecomp.closed_loop.loop import ClosedLoopResult, Noise, simulate_closed_loop

__all__ = ["simulate_closed_loop", "Noise", "ClosedLoopResult"]
