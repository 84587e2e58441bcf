"""Ahead-of-time build of the stepper (numba.pycc), used by ``setup.py``.

The compiled module ``heavecomp.simulate._cmc_aot`` is the same
:func:`heavecomp.simulate._kernel.advance` — the same Python source,
compiled once at install time instead of at the first call of every
process — so a short ``heavecomp simulate`` does not pay numba's start-up
(~0.4 s: numba imports scipy.linalg, initialises LLVM and loads its cache).
It also exports ``source_hash()``, the hash of the source files it was built
from; :func:`heavecomp.simulate.core.stepper` uses the module only when that
matches the files on disk, so an edited plant can never run stale code.
"""

from __future__ import annotations

from heavecomp.simulate.layout import source_hash

ADVANCE_SIGNATURE = ("i8(f8[::1], f8[::1], f8, i8, f8, i8, f8[::1], f8[::1], b1, f8, f8, "
                     "f8[::1], f8[::1], f8[::1], f8[:,::1], i8, i8, f8[::1])")


def build_cc(output_dir=None):
    """The ``numba.pycc.CC`` object for ``heavecomp.simulate._cmc_aot``."""
    from numba.pycc import CC

    from heavecomp.simulate import _kernel

    cc = CC("_cmc_aot")
    if output_dir is not None:
        cc.output_dir = str(output_dir)
    cc.verbose = False
    cc.export("advance", ADVANCE_SIGNATURE)(_kernel.advance.py_func)
    ns: dict = {}
    exec(f"def source_hash():\n    return {source_hash()}\n", ns)  # a constant baked into the module
    cc.export("source_hash", "i8()")(ns["source_hash"])
    return cc


if __name__ == "__main__":  # python -m heavecomp.simulate._aot : build in place (developers)
    from pathlib import Path

    build_cc(Path(__file__).parent).compile()
    print("built heavecomp/simulate/_cmc_aot")
