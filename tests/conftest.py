import gc
import inspect
import os
from pathlib import Path
import subprocess
import sys

import pytest

# The suite runs one process per core (pytest-xdist, -n auto): a BLAS or OpenMP pool of its own in each
# process only oversubscribes the cores. Set before any worker (and any CLI subprocess) starts: the
# workers inherit the controller's environment. A user's own setting wins.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")


ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def data_dir() -> Path:
    """The measured data shipped inside the package (heavecomp/data, see its README)."""
    from heavecomp.data import ROOT as DATA

    return DATA


@pytest.fixture
def paper_a_toml(tmp_path) -> Path:
    from heavecomp.params import dumps, paper_a

    p = tmp_path / "paper_a.toml"
    p.write_text(dumps(paper_a()))
    return p


@pytest.fixture
def diagnose_cli(tmp_path):
    """``heavecomp diagnose CSV --params TOML --out <tmp>/o [extra...]`` in a fresh interpreter (the
    user's command: exit code and stderr as a shell sees them)."""

    def run(csv, params, *extra):
        return subprocess.run([sys.executable, "-m", "heavecomp.cli", "diagnose", str(csv), "--params", str(params),
                               "--out", str(tmp_path / "o"), *extra], capture_output=True, text=True)

    return run


@pytest.fixture(scope="session")
def once():
    """``once(make, *args, **kwargs)``: ``make(*args, **kwargs)``, computed on first use and shared
    by every test of the session that asks for the same call.

    For the planted runs of the diagnosis tests: a maker that generates a run and diagnoses it runs once
    per distinct call (keyed by the maker's qualified name and the ``repr`` of its bound arguments,
    defaults filled in), so tests that check different things about one diagnosed run fit it once.
    The result is shared: a test only reads it.  Under ``pytest -n`` each worker has its own session."""
    done = {}

    def get(make, *args, **kwargs):
        call = inspect.signature(make).bind(*args, **kwargs)
        call.apply_defaults()  # a default written out or left out is the same call
        key = (make.__module__, make.__qualname__, repr(sorted(call.arguments.items())))
        if key not in done:
            done[key] = make(*args, **kwargs)
        return done[key]

    return get


# Garbage collection: a worker's heap grows to ~700k tracked objects (numba dispatchers, casadi, the
# shared fixtures), and each automatic full collection walks all of it (up to 1.5 s each, ~20 per worker in
# the fast tier: 10-14 s of a worker's CPU).  In the workers a full collection runs after 100 collections
# of the middle generation instead of 10 (gc.set_threshold's third value); the young generations keep
# their defaults, so short-lived cycles are freed as before.  (gc.freeze would walk even less, but
# gc.get_referrers no longer sees frozen objects, and Hypothesis relies on it.)
GC_THRESHOLD_FULL = 100


def pytest_configure(config):
    if os.environ.get("PYTEST_XDIST_WORKER"):
        young, middle, _ = gc.get_threshold()
        gc.set_threshold(young, middle, GC_THRESHOLD_FULL)
    # pytest's unraisable-exception check runs gc.collect() five times at the session's end (a constant
    # "determined experimentally by the Trio project"); on a worker's heap each pass takes ~1.2 s.  One
    # pass still collects the cycles whose finalizers would raise (the check itself stays on).
    try:
        from _pytest.unraisableexception import gc_collect_iterations_key
    except ImportError:  # a pytest without the key: its default
        return
    config.stash[gc_collect_iterations_key] = 1
