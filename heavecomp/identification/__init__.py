"""Identification from measured data (light package: import the sub-modules you need).

- :mod:`~heavecomp.identification.filtering` — zero-phase low-pass, derivatives,
  parallel decimation (both sides of a regression filtered alike);
- :mod:`~heavecomp.identification.inverse` — inverse-model least squares for a
  1-DOF axis (EMPS benchmark), :class:`InverseModelLS`;
- :mod:`~heavecomp.identification.terms` — candidate friction terms as scalar ``np.*`` functions;
- :mod:`~heavecomp.identification.residual` — where the held-out residual lives and
  which candidate effect shrinks it, :class:`ResidualDiagnoser`;
- :mod:`~heavecomp.identification.seal` — seal friction vs pressure, F_C + C_p dp.
"""
