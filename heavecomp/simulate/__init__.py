"""Time-domain simulation with exact stick-slip.

>>> from heavecomp.params import paper_a
>>> from heavecomp.simulate import simulate
>>> res = simulate(paper_a("stribeck"), 120.0)        # doctest: +SKIP
>>> res.metrics()["wob_p2p"]                          # doctest: +SKIP
"""

from heavecomp.simulate.core import CHANNELS, SimulationResult, default_dt, simulate

__all__ = ["simulate", "SimulationResult", "CHANNELS", "default_dt"]
