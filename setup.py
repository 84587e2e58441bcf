"""Install-time builds of the compiled stepper (see heavecomp/simulate/stepper.py); metadata in pyproject.toml.

1. Warm numba's cache: the JIT steppers the commands use (the nominal stepper, the stepper of the
   library's effect composition, the campaign's parallel batch) are compiled into
   ``heavecomp/_numba_cache`` beside the sources (:mod:`heavecomp.simulate.cache`), so the first
   ``heavecomp diagnose`` / ``simulate`` / ``campaign`` after ``pip install -e .`` loads machine
   code instead of compiling it (about 2 minutes of CPU here, once).  Done for an editable
   install (or ``build_ext --inplace``), where the runtime imports these very sources; a wheel
   copied elsewhere compiles on first use, with a notice.  HEAVECOMP_NO_WARM=1 skips it.
2. The optional ahead-of-time build of the nominal stepper (numba.pycc; heavecomp/simulate/_aot.py).
   If numba's AOT compiler or a C compiler is not available, the package installs without it and
   the JIT is used (same results, ~0.4 s more per process).  HEAVECOMP_NO_AOT=1 skips it.

Neither step can fail the install: a failure prints why and the JIT compiles on first use.
"""

import os
import subprocess
import sys
import time
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = Path(__file__).resolve().parent

WARM = ("from heavecomp.simulate import stepper; from heavecomp.campaign import batch; "
        "import logging; logging.basicConfig(level=logging.WARNING, format='%(message)s'); "
        "names = stepper.compile_all(progress=lambda n: print('heavecomp: compiling the ' + n, flush=True)); "
        "batch.compile_batch(); print('heavecomp: compiled ' + ', '.join(names) + ', campaign batch')")


class AOTExtension(Extension):
    """The numba.pycc-compiled stepper; built by OptionalBuildExt, not by distutils."""

    def __init__(self):
        super().__init__("heavecomp.simulate._cmc_aot", sources=[])


class OptionalBuildExt(build_ext):
    def run(self):
        super().run()
        if os.environ.get("HEAVECOMP_NO_WARM"):
            return
        if not (getattr(self, "editable_mode", False) or self.inplace):
            print("heavecomp: numba's cache is warmed for editable installs only; "
                  "the first run compiles the stepper (with a notice)", file=sys.stderr)
            return
        warm_cache()

    def build_extension(self, ext):
        if not isinstance(ext, AOTExtension):
            return super().build_extension(ext)
        if os.environ.get("HEAVECOMP_NO_AOT"):
            return
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


def warm_cache():
    """Compile the JIT steppers into the cache beside the sources (a fresh process: numba's cache
    folder is set when heavecomp's kernels are imported)."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(HERE)] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p])
    import resource

    t0, r0 = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
    try:
        subprocess.run([sys.executable, "-c", WARM], cwd=str(HERE), env=env, check=True)
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime
        print(f"heavecomp: numba's cache warmed in {time.perf_counter() - t0:.0f} s ({cpu:.0f} s of CPU)",
              file=sys.stderr)
    except Exception as exc:  # noqa: BLE001 - the first run compiles instead
        print(f"heavecomp: numba's cache not warmed ({type(exc).__name__}: {exc}); "
              "the first run compiles the stepper", file=sys.stderr)


setup(ext_modules=[AOTExtension()], cmdclass={"build_ext": OptionalBuildExt})
