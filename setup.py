"""Optional ahead-of-time build of the compiled stepper (see heavecomp/simulate/_aot.py).

All metadata is in pyproject.toml.  If numba's AOT compiler or a C compiler is
not available, the package installs without the extension and the stepper is
compiled just in time instead (same results, ~0.4 s more per process).
Set HEAVECOMP_NO_AOT=1 to skip the build.
"""

import os
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = Path(__file__).resolve().parent


class AOTExtension(Extension):
    """The numba.pycc-compiled stepper; built by OptionalBuildExt, not by distutils."""

    def __init__(self):
        super().__init__("heavecomp.simulate._cmc_aot", sources=[])


class OptionalBuildExt(build_ext):
    def build_extension(self, ext):
        if not isinstance(ext, AOTExtension):
            return super().build_extension(ext)
        target = Path(self.get_ext_fullpath(ext.name))
        try:
            sys.path.insert(0, str(HERE))
            from heavecomp.simulate._aot import build_cc

            target.parent.mkdir(parents=True, exist_ok=True)
            cc = build_cc(target.parent)
            cc.output_file = target.name
            cc.compile()
            print(f"heavecomp: built the ahead-of-time stepper {target}", file=sys.stderr)
        except Exception as exc:  # noqa: BLE001 - any failure falls back to the JIT
            print(f"heavecomp: ahead-of-time stepper not built ({type(exc).__name__}: {exc}); "
                  "the JIT will be used", file=sys.stderr)


setup(ext_modules=[] if os.environ.get("HEAVECOMP_NO_AOT") else [AOTExtension()],
      cmdclass={"build_ext": OptionalBuildExt})
