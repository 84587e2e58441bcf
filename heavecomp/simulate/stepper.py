"""The compiled exact stick-slip stepper of the CMC: its public entry points.

:mod:`heavecomp.simulate._kernel` is the implementation (numba, imported on first use);
this module is what the simulator, the closed loop, the campaigns and the diagnosis call.

One call signature serves every stepper::

    out_pos = advance(state, mode_dir, t0, n_steps, h, plant, drive, out, out_every, out_pos, stats)

- ``plant``: :class:`Plant` ``(code, FP, PP, EP, smooth)``, the plant with the effect parameters
  of the stepper's composition (:func:`plant_args`);
- ``drive``: :class:`Drive` ``(u, sp, Z, DZ, DDZ)``, the active force [N] and the heave samples
  (z, dz, ddz) spaced ``sp`` = h/2 [s];
- ``state`` = ``[s, v, y_b, v_b, effect states..., tau]`` and ``mode_dir`` = ``[mode, direction]``
  (updated in place); ``out`` gets a row of :data:`CHANNELS` every ``out_every`` steps from row
  ``out_pos`` on (returned, advanced); ``stats`` accumulates :data:`STATS`.

Entry points: :func:`nominal` (the stepper of the plain CMC: ahead of time when built, else the
JIT), :func:`kernel_for` (the stepper of an effect composition), :func:`plant_stepper` (either,
for a plant and its effects, with its initial state and :class:`Plant`), :func:`heave_at`.
:func:`compile_all` compiles every stepper the commands use (``setup.py`` runs it at install, so
the first run loads machine code instead of compiling it).  Every call with the argument types of
:func:`canonical_args` uses the one compiled signature.
"""

from __future__ import annotations

import contextlib
import logging
import os
import threading
import time

import numpy as np

from heavecomp.effects.compose import composition, composition_for, library_composition
from heavecomp.simulate import cache, layout
from heavecomp.simulate.layout import CHANNELS, NCH, NSTATS, STATS, STUCK, Drive, Plant

__all__ = ["Plant", "Drive", "CHANNELS", "STATS", "NCH", "NSTATS", "plant_args", "nominal", "kernel_for",
           "plant_stepper", "jit_stepper", "heave_at", "compile_all", "compiling"]

log = logging.getLogger(__name__)


def plant_args(plant, EP=None, smooth=None) -> Plant:
    """The stepper's :class:`Plant` of ``plant`` (:func:`heavecomp.plants.cmc.plant_vectors`).

    Parameters
    ----------
    plant : PlantVectors
        The plant (:func:`heavecomp.plants.cmc.plant_vectors`).
    EP : (n_ep,) array or None
        Effect parameters of the stepper's composition [SI, layout of the composition]; None (the
        default): none, the nominal stepper.
    smooth : bool or None
        True when the friction has no part that jumps with sign(v); None (the default): True when
        the friction law has no stiction.
    """
    EP = np.zeros(0) if EP is None else np.ascontiguousarray(EP, dtype=float)
    if smooth is None:
        smooth = not plant.has_stiction
    return Plant(int(plant.code), plant.FP, plant.PP, EP, bool(smooth))


_NOMINAL = None


def nominal():
    """The compiled stepper of the plain CMC (no effect).

    The ahead-of-time build (``heavecomp.simulate._cmc_aot``, compiled from the same source at
    install time, see ``setup.py``) when it exists and was built from the current source files
    (hash check), so a short run does not import numba; otherwise the numba JIT
    (:func:`heavecomp.simulate._kernel.advance`).  ``HEAVECOMP_JIT=1`` forces the JIT.
    """
    global _NOMINAL
    if _NOMINAL is None:
        fn = None
        if not os.environ.get("HEAVECOMP_JIT"):
            try:
                from heavecomp.simulate import _cmc_aot

                if _cmc_aot.source_hash() == layout.source_hash():
                    fn = _cmc_aot.advance
                else:
                    log.info("ahead-of-time stepper is stale (source changed since install); using the JIT")
            except ImportError:
                pass
        if fn is None:
            fn = _jit_kernel(None)
        _NOMINAL = fn
    return _NOMINAL


_READY: set = set()
_COMPILE_LOCK = threading.Lock()


def _jit_kernel(comp):
    """The JIT stepper of ``comp`` (None: the nominal one), compiled for the canonical signature
    (or loaded from numba's cache) on first use, with a notice when that takes a while."""
    from heavecomp.simulate import _kernel

    fn = _kernel.advance if comp is None else _kernel.kernel_for(comp)
    if fn in _READY:
        return fn
    with _COMPILE_LOCK:  # the diagnosis' threads: one compile, one notice
        if fn not in _READY:
            n = 0 if comp is None else len(comp.classes)
            what = "the stick-slip stepper" + (f" with {n} effect{'s' * (n > 1)}" if n else "")
            # loading from the cache can take seconds on a busy machine: no notice then (a late one if
            # the cache turns out not to hold this signature after all)
            cached = _in_cache(fn)
            # not cached: another process compiling the same stepper now is waited for, and its result loaded
            lock = contextlib.nullcontext() if cached else \
                cache.one_compiler(f"stepper-{'nominal' if comp is None else comp.key}")
            with compiling(what, notice_after=20.0 if cached else 1.0,
                           estimate_s=COMPILE_S + COMPILE_S_PER_EFFECT * n), lock:
                _ensure_compiled(fn, comp)
            _READY.add(fn)
    return fn


def kernel_for(comp):
    """The compiled stepper of an effect composition (:class:`heavecomp.effects.compose.Composition`;
    the composition of no effect: the JIT nominal stepper), compiled (or loaded from the cache) now.

    Parameters
    ----------
    comp : Composition
        The effect composition (:func:`heavecomp.effects.compose.composition`).
    """
    return _jit_kernel(comp)


def plant_stepper(plant, effects=()):
    """``(advance, state, plant)`` for ``plant`` (:func:`heavecomp.plants.cmc.plant_vectors`) with
    ``effects`` (instances) at its hooks: the stepper, its initial state at rest at the operating
    point and its :class:`Plant` (effect parameters bound).

    Without effects the nominal stepper (:func:`nominal`), with effects the stepper of their
    composition (:func:`heavecomp.effects.compose.composition_for`: the superset compiled at install
    for registered effects and hook terms).

    Parameters
    ----------
    plant : PlantVectors
        The plant (:func:`heavecomp.plants.cmc.plant_vectors`).
    effects : sequence of Effect
        Effect instances at the plant's hooks (default none: the nominal stepper).
    """
    if not effects:
        return nominal(), composition(()).initial_state(plant.FP, plant.PP, np.zeros(0)), plant_args(plant)
    comp = composition_for(effects)
    EP = comp.ep(effects)
    args = plant_args(plant, EP, not (plant.has_stiction or comp.adds_stiction(EP)))
    return kernel_for(comp), comp.initial_state(plant.FP, plant.PP, EP), args


def jit_stepper():
    """The JIT nominal stepper itself (a numba dispatcher), for compiled drivers that call it from
    their own compiled code (the campaign's batch); Python callers use :func:`nominal`."""
    from heavecomp.simulate import _kernel

    return _kernel.advance


def heave_at(t, sp, Z, DZ, DDZ):
    """(z, dz, ddz) of the heave samples at time ``t`` [s] as the stepper interpolates them (quintic Hermite).

    Parameters
    ----------
    t : float [s]
        Time (from the first sample).
    sp : float [s]
        Spacing of the samples (h/2 of the stepper).
    Z, DZ, DDZ : (n,) array [m], [m/s], [m/s^2]
        Heave displacement, velocity and acceleration samples.
    """
    from heavecomp.simulate import _kernel

    return _kernel.heave_at(t, sp, Z, DZ, DDZ)


# ---------------------------------------------------------------------------- compile once
def canonical_args(n_eff_states: int = 0, n_ep: int = 0, n_cols: int = NCH):
    """Arguments of the canonical types of the stepper's signature (a call of no step).

    Parameters
    ----------
    n_eff_states : int
        Number of effect states in the state vector (0: the nominal stepper).
    n_ep : int
        Number of effect parameters.
    n_cols : int
        Number of output columns (default :data:`NCH`, the channels).
    """
    state = np.zeros(4 + n_eff_states + 1)
    mode_dir = np.array([float(STUCK), 1.0])
    z = np.zeros(8)
    plant = Plant(0, np.zeros(6), np.zeros(6), np.zeros(n_ep), False)
    drive = Drive(0.0, 0.005, z, z.copy(), z.copy())
    return state, mode_dir, 0.0, 0, 0.01, plant, drive, np.zeros((0, n_cols)), 1, 0, np.zeros(NSTATS)


def _signature(comp=None):
    import numba

    args = canonical_args() if comp is None else canonical_args(comp.n_states, comp.n_ep)
    return tuple(numba.typeof(a) for a in args)


def _in_cache(fn) -> bool:
    """True when numba's cache holds a fresh entry of ``fn`` (same numba, same source; read from
    numba's cache index: a private interface, so any surprise answers False)."""
    try:
        return bool(fn._cache._cache_file._load_index())  # noqa: SLF001
    except Exception:  # noqa: BLE001
        return False


def _ensure_compiled(fn, comp=None) -> None:
    """Compile (or load from numba's cache) ``fn`` for the canonical argument types."""
    sig = _signature(comp)
    if sig not in fn.overloads:
        fn.compile(sig)


#: CPU seconds to compile the nominal stepper, and more per effect of a composition (measured, numba 0.68,
#: with rk4 one loop compiled for one signature: 6.4 s, and 17.0 s for the superset's 16 classes,
#: benchmarks/install/compiles.json; before issue 32's cut, 23-35 s and 90-105 s; the notice quotes their sum)
COMPILE_S = 6
COMPILE_S_PER_EFFECT = 1


class compiling:
    """Context manager: when what it wraps runs longer than ``notice_after`` seconds (a compile,
    not a load from the cache), log one line saying so, then a heartbeat every ``every`` seconds.

    Logged at WARNING on ``heavecomp.simulate.stepper`` (the CLI prints it to stderr).

    Parameters
    ----------
    what : str
        What is being compiled, for the message (``"the stick-slip stepper"``).
    notice_after : float [s]
        Wall time after which the first line is logged.
    every : float [s]
        Wall time between heartbeat lines.
    estimate_s : float [s]
        CPU time the message quotes for the compile.
    """

    def __init__(self, what: str, notice_after: float = 1.0, every: float = 15.0, estimate_s: float = 60.0):
        self.what, self.notice_after, self.every, self.estimate_s = what, notice_after, every, estimate_s
        self._done = threading.Event()
        self._thread = None

    def _watch(self):
        t0 = time.monotonic()
        if self._done.wait(self.notice_after):
            return
        log.warning("heavecomp: compiling %s once (about %d s of CPU; kept in %s for the next runs)", self.what,
                    self.estimate_s, cache.where())
        while not self._done.wait(self.every):
            log.warning("heavecomp: ... still compiling %s (%.0f s)", self.what, time.monotonic() - t0)

    def __enter__(self):
        self._thread = threading.Thread(target=self._watch, name="heavecomp-compile-notice", daemon=True)
        self._thread.start()
        return self

    def __exit__(self, *exc):
        self._done.set()
        self._thread.join()
        return False


def compile_all(progress=None) -> list[str]:
    """Compile the steppers the commands use into numba's cache (``setup.py`` runs it at install,
    with the campaign's batch: :func:`heavecomp.campaign.batch.compile_batch`).

    The nominal stepper (simulate, closed loop), :func:`heave_at` and the stepper of the superset
    composition (:func:`heavecomp.effects.compose.library_composition`: every registered plant effect
    and the open search's hook terms; ``simulate(effects=...)``, a calibrated file, the diagnosis).
    Returns the names compiled.

    Parameters
    ----------
    progress : callable or None
        Called as ``progress(name)`` before each compile (None: not called).
    """
    steps = install_steps()
    for name, step in steps.items():
        if progress is not None:
            progress(name)
        step()
    return list(steps)


def install_steps() -> dict:
    """The install-time compiles of :func:`compile_all`, by name: each fills its own cache folder, so
    ``setup.py`` runs each in a process of its own, on every core.  ``"library effects stepper"`` is the
    superset composition's (:func:`heavecomp.effects.compose.library_composition`), which serves every
    set of registered effects and hook terms: a calibrated file's new mix of them compiles nothing."""
    from heavecomp.simulate import _kernel

    def nominal():
        _jit_kernel(None)
        _kernel.heave_at(0.0, 0.005, np.zeros(8), np.zeros(8), np.zeros(8))  # the heave interpolation

    return {"nominal stepper": nominal, "library effects stepper": lambda: _jit_kernel(library_composition())}

