"""Ahead-of-time build of the nominal stepper (numba.pycc), used by ``setup.py``.

The compiled module ``heavecomp.simulate._cmc_aot`` is the same
:func:`heavecomp.simulate._kernel.advance` — the same Python source, the same signature
(:func:`heavecomp.simulate.stepper.canonical_args`: the :class:`~heavecomp.simulate.layout.Plant`
and :class:`~heavecomp.simulate.layout.Drive` tuples), compiled once at install time instead of
at the first call of every process — so a short ``heavecomp simulate`` does not pay numba's
start-up (~0.4 s: numba imports scipy.linalg, initialises LLVM and loads its cache).
It also exports ``source_hash()``, the hash of the source files it was built
from; :func:`heavecomp.simulate.stepper.nominal` uses the module only when that
matches the files on disk, so an edited plant can never run stale code.

``numba.pycc`` is marked for deprecation in numba: the JIT stepper, compiled into numba's cache
at install (:func:`heavecomp.simulate.stepper.compile_all`), is the first-class path; this build
only saves the numba import of a short nominal run, and its absence changes no result.
"""

from __future__ import annotations

from heavecomp.simulate.layout import source_hash
from heavecomp.simulate.stepper import canonical_args


def advance_signature():
    """numba signature of the exported ``advance`` (the JIT stepper's canonical one)."""
    import numba
    from numba import types

    return types.int64(*(numba.typeof(a) for a in canonical_args()))


def build_cc(output_dir=None):
    """The ``numba.pycc.CC`` object for ``heavecomp.simulate._cmc_aot``."""
    from numba.pycc import CC

    from heavecomp.simulate import _kernel

    cc = CC("_cmc_aot")
    if output_dir is not None:
        cc.output_dir = str(output_dir)
    cc.verbose = False
    cc.export("advance", advance_signature())(_kernel.advance.py_func)
    ns: dict = {}
    exec(f"def source_hash():\n    return {source_hash()}\n", ns)  # a constant baked into the module
    cc.export("source_hash", "i8()")(ns["source_hash"])
    return cc


if __name__ == "__main__":  # python -m heavecomp.simulate._aot : build in place (developers)
    from pathlib import Path

    build_cc(Path(__file__).parent).compile()
    print("built heavecomp/simulate/_cmc_aot")
