"""The numba cache of each stepper is keyed to what it is compiled from, and nothing else;
every caller uses the stepper's one compiled signature (so the install-time compile serves all)."""

from __future__ import annotations

import logging
import shutil
import time
from pathlib import Path

import numpy as np
import pytest

from heavecomp.effects.compose import library_composition
from heavecomp.simulate import cache

ROOT = Path(cache.__file__).resolve().parents[1]


def _keys(comp):
    return {"nominal": cache.source_key(), "batch": cache.source_key(("campaign/batch.py",)),
            "effects": cache.composition_key(comp)}


@pytest.fixture
def package_copy(tmp_path, monkeypatch):
    """A copy of the package's sources, which the keys are computed from."""
    root = tmp_path / "heavecomp"
    shutil.copytree(ROOT, root, ignore=shutil.ignore_patterns("_numba_cache", "__pycache__", "*.so", "data"))
    monkeypatch.setattr(cache, "ROOT", root)
    return root


def _append(path: Path, text: str) -> None:
    path.write_text(path.read_text() + text)


def test_an_edit_outside_the_compiled_sources_changes_no_key(package_copy):
    comp = library_composition()
    before = _keys(comp)
    for rel in ("report/figures.py", "commands/diagnose.py", "diagnosis/stepper.py", "simulate/stepper.py",
                "simulate/core.py", "closed_loop/loop.py", "params/budget.py"):
        _append(package_copy / rel, "\n# a comment\n")
    assert _keys(comp) == before


@pytest.mark.parametrize("rel", ["friction/laws.py", "plants/cmc.py", "effects/compose.py", "simulate/_kernel.py",
                                 "simulate/layout.py", "params/cmc.py"])
def test_an_edit_of_the_kernel_sources_changes_every_key(package_copy, rel):
    comp = library_composition()
    before = _keys(comp)
    _append(package_copy / rel, "\n# a comment\n")
    after = _keys(comp)
    assert all(after[k] != before[k] for k in before)


def test_the_campaign_batch_is_keyed_to_its_own_file_too(package_copy):
    comp = library_composition()
    before = _keys(comp)
    _append(package_copy / "campaign/batch.py", "\n# a comment\n")
    after = _keys(comp)
    assert after["batch"] != before["batch"]
    assert after["nominal"] == before["nominal"] and after["effects"] == before["effects"]


def test_an_effect_hook_edit_changes_its_composition_key_only(monkeypatch):
    from heavecomp.effects.dwell_stiction import DwellStiction

    comp = library_composition()
    before = _keys(comp)
    # the diagnosis metadata of an effect is not compiled: no key changes
    monkeypatch.setattr(DwellStiction, "candidate", not getattr(DwellStiction, "candidate", False), raising=False)
    monkeypatch.setattr(DwellStiction, "limits", {"gain": (0.0, 1.0)}, raising=False)
    assert _keys(comp) == before

    def static(code, p, lim, tau, s, d, x, FP, gain, exponent):  # the dwell law, edited
        return lim + 2.0 * gain * np.maximum(tau, 1e-12) ** exponent

    monkeypatch.setattr(DwellStiction, "static", staticmethod(static))
    after = _keys(comp)
    assert after["effects"] != before["effects"]
    assert after["nominal"] == before["nominal"] and after["batch"] == before["batch"]


def test_cache_dir_is_set_while_decorating_only(tmp_path, monkeypatch):
    import numba
    from numba.core import config

    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setenv("HEAVECOMP_CACHE_DIR", str(tmp_path))
    cache.base_dir.cache_clear()
    try:
        old = config.CACHE_DIR
        with cache.keyed("abc"):
            assert config.CACHE_DIR == str(tmp_path / "numba-abc")
            f = numba.njit(cache=True)(lambda x: x + 1)
        assert config.CACHE_DIR == old
        assert f._cache.cache_path.startswith(str(tmp_path / "numba-abc"))
    finally:
        cache.base_dir.cache_clear()


def test_compile_notice_is_one_line_then_a_heartbeat(caplog):
    from heavecomp.simulate.stepper import compiling

    with caplog.at_level(logging.WARNING, logger="heavecomp.simulate.stepper"):
        with compiling("a test kernel", notice_after=0.05, every=0.1):
            time.sleep(0.38)
        with compiling("a cached kernel", notice_after=0.5):
            pass  # loaded in no time: nothing said
    lines = [r.getMessage() for r in caplog.records]
    assert lines[0].startswith("heavecomp: compiling a test kernel once")
    assert 2 <= len(lines) <= 5 and all("still compiling a test kernel" in m for m in lines[1:])
    assert not any("cached kernel" in m for m in lines)


@pytest.mark.slow
def test_every_caller_uses_the_one_compiled_signature(monkeypatch):
    """simulate (with and without effects), the closed loop, the diagnosis' replay and the
    campaign's batch call the steppers with the canonical argument types: the signature
    compiled at install (``stepper.compile_all``) is the only one."""
    from heavecomp.campaign import batch
    from heavecomp.campaign import spec
    from heavecomp.closed_loop import simulate_closed_loop
    from heavecomp.diagnosis import stepper as DS
    from heavecomp.params import paper_a
    from heavecomp.simulate import _kernel as K
    from heavecomp.simulate import simulate
    from heavecomp.simulate import stepper as S

    monkeypatch.setenv("HEAVECOMP_JIT", "1")
    monkeypatch.setattr(S, "_NOMINAL", None)
    p = paper_a("stribeck")
    simulate(p, 20.0)
    simulate(p, 20.0, effects=["flow_loss", "heave_reference"])
    simulate_closed_loop(p, "pid", 5.0)
    DS.simulate_fx(p, 10.0, ["dwell_stiction"])
    camp = spec.loads("""
[campaign]
name = "t"
duration = 20.0
seeds = 1
regimes = ["stribeck"]
[scatter]
hs = [1.0]
tp = [10.0]
probability = [[1.0]]
[band]
tolerance = 20e3
exposure = 1800.0
[outputs]
deviation_max = 100e3
bins = 10
figures = false
""", source="t.toml")
    batch.simulate_batch(camp, camp.runs(), threads=1)
    comp = library_composition()
    assert set(K.advance.overloads) == {S._signature()}
    assert set(K.kernel_for(comp).overloads) == {S._signature(comp)}
    assert len(batch._batch.overloads) == 1
    assert len(K.heave_at.overloads) == 1


_HOOK_COMPILES = """
import collections, json
from numba.core import event
compiled = collections.Counter()
class Count(event.Listener):
    def on_start(self, ev):
        pass
    def on_end(self, ev):
        compiled[ev.data["dispatcher"].py_func.__qualname__] += 1
event.register("numba:compile", Count())
import numpy as np
from heavecomp.effects.compose import GENERATED, composition
from heavecomp.effects.registry import library
from heavecomp.params import paper_a
from heavecomp.plants import cmc
from heavecomp.simulate import _kernel as K
comp = composition((library()["charge_drift"],))
plant = cmc.plant_vectors(paper_a("stribeck"))
EP = comp.ep([library()["charge_drift"](charge_error=0.1)])
p = K.compiled_hooks(comp)["cylinder_pressure_fx"](0.2, 0.01, (0.2, 0.01, 0.0, 0.0), plant.PP, EP)
print(json.dumps([float(p), sum(n for f, n in compiled.items() if f in GENERATED)]))
"""


def test_generated_hook_functions_compile_once_per_cache(tmp_path):
    """The hook functions a composition generates are kept in numba's disk cache like the stepper (their
    source is a file in the composition's cache folder): a second process calling them compiles none of
    them (the pins and the conformance battery call them from Python; they compiled in every process)."""
    import json
    import os
    import subprocess
    import sys

    env = {**os.environ, "HEAVECOMP_CACHE_DIR": str(tmp_path), "PYTHONPATH": str(ROOT.parent)}
    env.pop("NUMBA_CACHE_DIR", None)
    runs = [json.loads(subprocess.run([sys.executable, "-c", _HOOK_COMPILES], env=env, capture_output=True,
                                      text=True, check=True).stdout.splitlines()[-1]) for _ in range(2)]
    (p1, first), (p2, second) = runs
    assert first >= 1 and second == 0
    assert p1 == p2
    assert list(tmp_path.glob("numba-*/hooks_*.py"))


_HOLDER = """
import json, sys, time
from heavecomp.simulate import cache
with cache.one_compiler("stepper-test"):
    t0 = time.time()
    time.sleep(0.4)
    print(json.dumps([t0, time.time()]))
"""


def test_two_processes_compiling_the_same_stepper_take_turns(tmp_path):
    """The cache's compile lock (:func:`heavecomp.simulate.cache.one_compiler`, held around a stepper's first
    compile): two processes that need the same kernel at once hold it one after the other, so the second
    loads what the first compiled instead of compiling it again (pytest's workers, a fleet's processes)."""
    import json
    import os
    import subprocess
    import sys

    env = dict(os.environ, HEAVECOMP_CACHE_DIR=str(tmp_path))
    procs = [subprocess.Popen([sys.executable, "-c", _HOLDER], env=env, stdout=subprocess.PIPE, text=True)
             for _ in range(2)]
    spans = sorted(json.loads(p.communicate(timeout=60)[0]) for p in procs)
    assert all(p.returncode == 0 for p in procs)
    assert spans[1][0] >= spans[0][1], spans  # the second began after the first had let go
    assert (tmp_path / "stepper-test.lock").exists()
