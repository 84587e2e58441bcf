"""Identification from measured data (light package: import the sub-modules you need).

- :mod:`~heavecomp.identification.filtering` — zero-phase low-pass, derivatives,
  parallel decimation (both sides of a regression filtered alike);
- :mod:`~heavecomp.identification.inverse` — inverse-model least squares for a
  1-DOF axis (EMPS benchmark), :class:`InverseModelLS`;
- :mod:`~heavecomp.identification.plants` — the EMPS axis and the O-ring seal rig as plants of
  the equation-error diagnosis (signals, friction residual, nominal base columns);
- :mod:`~heavecomp.identification.residual` — where the held-out residual lives and
  which candidate effect (the effect library's classes) shrinks it, :class:`ResidualDiagnoser`;
- :mod:`~heavecomp.identification.seal` — seal friction vs pressure, F_C + C_p dp.
"""
