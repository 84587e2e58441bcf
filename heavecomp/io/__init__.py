"""Reading measured series (runs, heave files, identification data) in any reasonable shape.

Low in the layer order (needs only :mod:`heavecomp.errors`), so params, simulate, diagnosis
and identification can all use it.  See :mod:`heavecomp.io.series`.
"""
