"""Install-time builds of the compiled stepper (see heavecomp/simulate/stepper.py); metadata in pyproject.toml.

1. Warm numba's cache: the JIT steppers the commands use (the stepper of the library's effect
   composition, the campaign's parallel batch with the nominal stepper it calls, the stick-slip map's
   pneumatic batch, and the benchmark generator's truth stepper the scenarios and the fast tests run) are
   compiled into ``heavecomp/_numba_cache`` beside the sources (:mod:`heavecomp.simulate.cache`), so the first
   ``heavecomp diagnose`` / ``simulate`` / ``campaign`` after ``pip install -e .`` loads machine
   code instead of compiling it (about 45 s of CPU here, once: benchmarks/install/compiles.json).  Each is
   compiled in a process of its own, on every core, while step 2 runs (issue 32); one line says what and how long.  Done for an editable
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

#: the install-time compiles, each in a process of its own (each fills its own cache folder), the longest
#: first: {name: python source}; stepper.install_steps() names the steppers'.  The JIT nominal stepper is not
#: a step of its own: the campaign batch calls it from compiled code, so its compile fills the nominal
#: stepper's cache folder too (and heave_at's); a step of its own compiled the same code twice at once
#: (benchmarks/install/compiles.json)
_LOG = "import logging; logging.basicConfig(level=logging.WARNING, format='%(message)s'); "
WARM = {"library effects stepper": _LOG + "from heavecomp.simulate import stepper; "
                                          "stepper.install_steps()['library effects stepper']()",
        "benchmark truth stepper": _LOG + "from heavecomp.benchmark.truth import truth_composition; "
                                          "from heavecomp.simulate import stepper; stepper.kernel_for(truth_composition())",
        "campaign batch": _LOG + "from heavecomp.campaign import batch; batch.compile_batch()",
        "pneumatic stepper": _LOG + "from heavecomp.pneumatic import stepper; stepper.compile_many()"}


class AOTExtension(Extension):
    """The numba.pycc-compiled stepper; built by OptionalBuildExt, not by distutils."""

    def __init__(self):
        # optional: when the build is skipped (HEAVECOMP_NO_AOT) or fails, setuptools copies no library into
        # the sources instead of failing the install on the missing file
        super().__init__("heavecomp.simulate._cmc_aot", sources=[], optional=True)


class OptionalBuildExt(build_ext):
    def run(self):
        warm = None
        if os.environ.get("HEAVECOMP_NO_WARM"):
            pass
        elif not (getattr(self, "editable_mode", False) or self.inplace):
            print("heavecomp: numba's cache is warmed for editable installs only; "
                  "the first run compiles the stepper (with a notice)", file=sys.stderr)
        else:
            warm = Warming()  # in the background, on every core, while the ahead-of-time build runs here
        try:
            super().run()
        finally:
            if warm is not None:
                warm.wait()

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


class Warming:
    """Compile the JIT steppers into the cache beside the sources: each step of :data:`WARM` in a fresh
    process of its own (numba's cache folder is set when heavecomp's kernels are imported), as many at
    once as the machine has cores, in the background (a thread starts the next as one ends); :meth:`wait`
    reports the time the compiles took."""

    def __init__(self):
        import resource
        import threading

        self.env = dict(os.environ)
        self.env["PYTHONPATH"] = os.pathsep.join([str(HERE)] + [p for p in self.env.get("PYTHONPATH", "").split(os.pathsep)
                                                                 if p])
        self.cores = max(1, min(len(WARM), os.cpu_count() or 1))
        self.failed = []
        self.t0, self.r0 = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
        self.t1 = self.t0
        print(f"heavecomp: compiling the steppers ({', '.join(WARM)}) into numba's cache, {self.cores} at a time, "
              "once: about 45 s of CPU (20-30 s on 2 cores)", file=sys.stderr, flush=True)
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self):
        todo, running = list(WARM), []
        while todo or running:
            while todo and len(running) < self.cores:
                name = todo.pop(0)
                try:
                    running.append((name, subprocess.Popen([sys.executable, "-c", WARM[name]], cwd=str(HERE),
                                                           env=self.env)))
                except OSError as exc:  # the first run compiles instead
                    self.failed.append(f"{name} ({exc})")
            done = [(n, p) for n, p in running if p.poll() is not None]
            if not done:
                time.sleep(0.2)
            for name, proc in done:
                running.remove((name, proc))
                if proc.returncode != 0:
                    self.failed.append(f"{name} (exit {proc.returncode})")
        self.t1 = time.perf_counter()

    def wait(self):
        import resource

        self.thread.join()
        r = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = r.ru_utime - self.r0.ru_utime + r.ru_stime - self.r0.ru_stime
        if self.failed:
            print(f"heavecomp: numba's cache not warmed for {', '.join(self.failed)}; the first run compiles it "
                  "(with a notice)", file=sys.stderr)
        print(f"heavecomp: numba's cache warmed in {self.t1 - self.t0:.0f} s ({cpu:.0f} s of CPU) on {self.cores} "
              f"cores; with the ahead-of-time build beside it, {time.perf_counter() - self.t0:.0f} s", file=sys.stderr)


def warm_cache():
    """Compile the JIT steppers into the cache beside the sources (:class:`Warming`) and wait."""
    Warming().wait()


setup(ext_modules=[AOTExtension()], cmdclass={"build_ext": OptionalBuildExt})
