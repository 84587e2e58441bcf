"""Paper B's pneumatic meter-out cylinder (Fujita et al.): its own wing of the package.

Layers inside the wing follow the package's (nothing imports upward):

- physics: :mod:`~heavecomp.pneumatic.plant` (parameters, chamber and orifice
  equations) and :mod:`~heavecomp.pneumatic.friction` (three lubrication regimes);
- stepper: :mod:`~heavecomp.pneumatic.stepper` (exact stick-slip, numba);
- analysis: :mod:`~heavecomp.pneumatic.linear` (omega_n, zeta*, D*, ``StateSpace``),
  :mod:`~heavecomp.pneumatic.stickslip` (critical curve, maps, minimum velocity),
  :mod:`~heavecomp.pneumatic.measurement` (paper B's friction measurement).

Figures are drawn by :mod:`heavecomp.report.rigs`, the command is
:mod:`heavecomp.commands.stickslip`.
"""
