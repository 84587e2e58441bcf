"""The ahead-of-time stepper is the JIT stepper (same source, same numbers), is never used
stale, and the CLI's background figure gives the same file with and without fork."""

import os

import numpy as np
import pytest

from heavecomp.params import paper_a
from heavecomp.simulate import simulate
from heavecomp.simulate import stepper as S


@pytest.fixture
def fresh_stepper(monkeypatch):
    monkeypatch.setattr(S, "_NOMINAL", None)
    yield
    S._NOMINAL = None


def _run(model, monkeypatch, jit):
    S._NOMINAL = None
    if jit:
        monkeypatch.setenv("HEAVECOMP_JIT", "1")
    else:
        monkeypatch.delenv("HEAVECOMP_JIT", raising=False)
    res = simulate(paper_a(model), 180.0)
    return res, S.nominal()


def test_aot_was_built_and_is_used(fresh_stepper, monkeypatch):
    # setup.py builds it with numba.pycc (needs a C compiler, present on CI); if this fails the
    # install printed why and every process pays numba's ~0.4 s start-up
    from heavecomp.simulate import _cmc_aot
    from heavecomp.simulate.layout import source_hash

    assert _cmc_aot.source_hash() == source_hash()
    _, fn = _run("stribeck", monkeypatch, jit=False)
    assert fn is _cmc_aot.advance


@pytest.mark.parametrize("model", ["none", "stribeck", "rotating_eq6", "rotating_eq7"])
def test_aot_equals_jit_bit_for_bit(model, fresh_stepper, monkeypatch):
    a, fa = _run(model, monkeypatch, jit=False)
    b, fb = _run(model, monkeypatch, jit=True)
    assert fa is not fb
    np.testing.assert_array_equal(a.data, b.data)
    assert a.stats == b.stats


def test_stale_build_falls_back_to_jit(fresh_stepper, monkeypatch):
    from heavecomp.simulate import _kernel, layout

    monkeypatch.delenv("HEAVECOMP_JIT", raising=False)
    monkeypatch.setattr(layout, "source_hash", lambda: -1)  # as if cmc.py had been edited
    assert S.nominal() is _kernel.advance


@pytest.mark.parametrize("fork", [True, False])
def test_background_figure(tmp_path, monkeypatch, fork):
    from heavecomp.report.background import BackgroundFigure
    from heavecomp.report.figures import plot_wob_run

    if not fork:
        monkeypatch.setenv("HEAVECOMP_NO_FORK", "1")
    fig = BackgroundFigure()
    assert (fig._proc is not None) == (fork and os.name == "posix" and os.uname().sysname == "Linux")
    res = simulate(paper_a(), 60.0)
    fig.draw(plot_wob_run, res, path=tmp_path / "w.png", save_kwargs={"tight": False})
    fig.wait()
    png = (tmp_path / "w.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 20_000


def test_background_figure_job_that_cannot_reach_the_child_is_drawn_inline(tmp_path):
    # a local function cannot be pickled to the child: the figure must still be written
    from heavecomp.report.background import BackgroundFigure

    calls = []

    def bad_then_good(x):
        import matplotlib.pyplot as plt

        assert os.getpid() == parent
        calls.append(x)
        fig, ax = plt.subplots()
        ax.plot([0, 1], [0, x])
        return fig

    parent = os.getpid()
    fig = BackgroundFigure()
    fig.draw(bad_then_good, 2.0, path=tmp_path / "f.png")
    fig.wait()
    assert (tmp_path / "f.png").is_file() and calls == [2.0]


def test_install_without_the_ahead_of_time_build(tmp_path):
    # HEAVECOMP_NO_AOT (setup.py's docstring) must skip the build, not fail the install: an editable
    # install's in-place copy of a library that was never built failed with "can't copy ...
    # _cmc_aot...so" until the extension was marked optional (found timing the install without it)
    import shutil
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    for name in ("setup.py", "pyproject.toml", "README.md"):
        shutil.copy(root / name, tmp_path / name)
    shutil.copytree(root / "heavecomp", tmp_path / "heavecomp",
                    ignore=shutil.ignore_patterns("_numba_cache", "__pycache__", "*.so", "data"))
    env = {**os.environ, "HEAVECOMP_NO_AOT": "1", "HEAVECOMP_NO_WARM": "1"}
    proc = subprocess.run([sys.executable, "setup.py", "-q", "build_ext", "--inplace"], cwd=tmp_path, env=env,
                          capture_output=True, text=True)
    assert proc.returncode == 0 and "can't copy" not in proc.stderr, proc.stderr[-2000:]
    assert not list((tmp_path / "heavecomp" / "simulate").glob("_cmc_aot*"))
