"""heavecomp — heave compensation of offshore drilling rigs.

A control-oriented toolbox around the crown-block mounted compensator (CMC) of
Ottestad, Nilsen & Hansen (ICCAS 2012, "paper A") with nonlinear main-cylinder
friction and exact stick-slip, plus paper B's pneumatic stick-slip system
(Fujita, Tokashiki & Kagawa 1999).

Sub-packages, in layers: each imports only those listed before it, ``tests/test_layers.py``
checks it; ``import heavecomp`` is cheap:

- :mod:`heavecomp.params`      parameter sets, TOML in/out, validation
- :mod:`heavecomp.friction`    friction laws (paper A eqs. 1-7, paper B)
- :mod:`heavecomp.plants`      plant equations (CMC, ...), written once
- :mod:`heavecomp.simulate`    exact stick-slip time stepping, excitations
- :mod:`heavecomp.controllers` passive, PID, MPC (or any object with ``step``)
- :mod:`heavecomp.closed_loop` the stepper with a controller in the loop
- :mod:`heavecomp.analysis`    linearisation, frequency responses
- :mod:`heavecomp.diagnosis`   sim-to-real gap diagnosis
- :mod:`heavecomp.report`      figures and reports
"""

__version__ = "0.1.0"
