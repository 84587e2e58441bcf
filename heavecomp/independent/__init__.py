"""An independent truth generator for scoring the gap diagnosis (issue 30, item 5).

Written clean-room from the project's spec (``cmc-reference.md``, ``physics.md``, the
measured-run and diagnosis contracts) and the literature cited in each law's docstring, by a
session that did not read the diagnosis' candidate effects nor the existing benchmark's truth
laws. It must not import ``heavecomp.effects``, ``heavecomp.diagnosis``, ``heavecomp.benchmark``,
``heavecomp.plants``, ``heavecomp.friction`` or ``heavecomp.simulate``
(``tests/test_independent.py`` checks it): its plant, its laws and its integrator are its own;
it reads only the nominal parameter file (:mod:`heavecomp.params`).

- :mod:`~heavecomp.independent.laws`: the truth laws (LuGre, dwell-time stiction, Bouc-Wen, thermal
  accumulator, lumped line, formation hardening, MRU filter, quantisers, mains hum, sensor faults);
- :mod:`~heavecomp.independent.plant`: the CMC with those laws at its seal, gas bank, line, string
  and formation, integrated by scipy (LSODA);
- :mod:`~heavecomp.independent.cases`: :func:`make_case` writes a log, the nominal file, the
  noise-free truth, a second log in another sea and ``truth.json``.

``scenarios/independent_truth.py`` generates a set, runs ``heavecomp diagnose`` on each log and
scores it.
"""

from heavecomp.independent.cases import CLASSES, DISTRIBUTIONS, NOISE, make_case

__all__ = ["CLASSES", "DISTRIBUTIONS", "NOISE", "make_case"]
