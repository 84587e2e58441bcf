"""Paper A's friction test rig with a rotating piston: its own wing of the package.

:mod:`~heavecomp.test_rig.plant` holds the rig model, the friction reading of
eq. 12 and the per-quadrant fit; figures are drawn by :mod:`heavecomp.report.rigs`.
"""
