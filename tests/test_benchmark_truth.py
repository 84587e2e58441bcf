"""Battery over the benchmark's truth-law registry (:data:`heavecomp.benchmark.truth.LAWS`): each
law's draw stays within its cap, a zero size gives back the nominal run, and no truth law uses a
candidate's equations (no truth file imports a candidate's module, no truth class is or shares a
method with a registered effect).  Also: the diagnosis never imports the benchmark."""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import numpy as np
import pytest

from heavecomp.benchmark import Case, LAWS, parameter_sets
from heavecomp.benchmark.testbed import Testbed
from heavecomp.benchmark.truth import Setting, truth_composition
from heavecomp.effects.registry import library
from heavecomp.errors import ParameterError

from _source import tree as tree_of  # the package's files, parsed once per process

ROOT = Path(__file__).resolve().parents[1]
TRUTH_DIR = ROOT / "heavecomp" / "benchmark" / "truth"
NOMINAL = parameter_sets()["paper_a"]
#: laws whose size is a time constant: a zero size is the singular limit T -> 0 (a division by zero),
#: not a runnable law
SINGULAR_AT_ZERO = {"friction_lag", "sensor_delay"}
#: (law, variant) whose size knob leaves a filter in place at zero size: a misreading channel keeps
#: its 5 Hz sensor bandwidth (about 2 x the WOB floor on its own), an MRU keeps its high-pass; their
#: zero size is not the nominal run, only a smaller gap than the drawn size
FILTER_AT_ZERO = {("sensor_gain", v) for v in (None, "wob", "stroke", "pressure")} | {("heave_reference", "mru"),
                                                                                     ("heave_reference", "mru_drift")}


def _draws(name, n=12):
    law = LAWS[name]
    base = {"wob": np.linspace(9e4, 1.1e5, 500)}
    for variant in (None,) + law.variants:
        for seed in range(n):
            yield variant, law.draw(np.random.default_rng(seed), Setting(NOMINAL, 300.0, variant, base))


def _sized(d):
    """The values the magnitude knob sets."""
    return list(d.parameters.values()) if d.magnitude == "*" else [d.parameters[d.magnitude]]


@pytest.mark.parametrize("name", list(LAWS))
def test_each_draw_is_within_its_cap_and_scales_to_it(name):
    """Every drawn size is below the law's cap (drawn sizes are plausible), and scaling it up stops
    exactly at the cap and says so."""
    knobs = 0
    for variant, d in _draws(name):
        if d.magnitude is None:
            assert d.cap is None
            continue
        knobs += 1
        assert all(abs(x) < d.cap for x in _sized(d)), (variant, d)
        big, capped = d.scaled(1e6)
        assert capped and all(abs(x) == pytest.approx(d.cap) for x in _sized(big))
        assert all(np.sign(x) == np.sign(y) for x, y in zip(_sized(big), _sized(d)))
        small, capped = d.scaled(0.5)
        assert not capped and all(abs(x) == pytest.approx(0.5 * abs(y)) for x, y in zip(_sized(small), _sized(d)))
    assert knobs or name in ("gas_heat_transfer", "wob_saturation")  # only these have no size knob at all


@pytest.fixture(scope="module")
def bed():
    return Testbed(NOMINAL, np.random.default_rng(3), 40.0, 50.0, "jonswap", 1.0)


def _sized_draws(name, bed):
    law = LAWS[name]
    for variant in (None,) + law.variants:
        d = law.draw(np.random.default_rng(0), Setting(NOMINAL, 40.0, variant, bed.base))
        if d.magnitude is not None:
            yield variant, d


@pytest.mark.slow
@pytest.mark.parametrize("name", [n for n in LAWS if n not in SINGULAR_AT_ZERO
                                  and any(d.magnitude for _, d in _draws(n, 1))])
def test_zero_size_gives_back_the_nominal_run(name, bed):
    """At a zero size a law leaves the run as the nominal model makes it (to a millionth of the noise
    floor) while its drawn size shows; where the knob leaves a filter in place
    (:data:`FILTER_AT_ZERO`), the zero size at least shrinks the gap."""
    law = LAWS[name]
    for variant, d in _sized_draws(name, bed):
        zero, _ = d.scaled(0.0)
        assert all(x == 0 for x in _sized(zero))
        at_zero = max(bed.gap([law.part(zero.parameters, NOMINAL)])[0].values())
        drawn = max(bed.gap([law.part(d.parameters, NOMINAL)])[0].values())
        if (name, variant) in FILTER_AT_ZERO:
            assert at_zero < drawn, (variant, at_zero, drawn)
        else:
            assert at_zero < 1e-6 and drawn > 0.1, (variant, at_zero, drawn)


def _imports(path):
    """Every module a file imports from (``from X import a`` -> X and X.a; ``import X`` -> X)."""
    out = set()
    for node in ast.walk(tree_of(path)):
        if isinstance(node, ast.ImportFrom) and node.module:
            out.add(node.module)
            out.update(f"{node.module}.{a.name}" for a in node.names)
        elif isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
    return out


def test_no_truth_law_imports_a_candidate_module():
    """The truth files may use the effect machinery (base, compose), never a candidate's module."""
    candidates = {c.__module__ for c in library().values()}
    assert len(candidates) >= 10
    files = sorted(TRUTH_DIR.glob("*.py"))
    assert len(files) >= len(LAWS)
    for f in files:
        effects = {m for m in _imports(f) if m == "heavecomp.effects" or m.startswith("heavecomp.effects.")}
        assert not effects & candidates, (f.name, effects & candidates)
        assert effects <= {"heavecomp.effects.base", "heavecomp.effects.base.Effect", "heavecomp.effects.compose",
                           "heavecomp.effects.compose.composition"}, (f.name, effects)


@pytest.mark.parametrize("name", list(LAWS))
def test_each_law_lives_in_its_own_file(name):
    """The registry's law ``name`` is the ``LAW`` of ``truth/<name>.py``."""
    mod = importlib.import_module(f"heavecomp.benchmark.truth.{name}")
    assert mod.LAW is LAWS[name] and LAWS[name].name == name


@pytest.mark.parametrize("name", [n for n, law in LAWS.items() if law.plant is not None])
def test_plant_truth_classes_are_the_benchmarks_own(name):
    """A plant truth law is its own class: never a registered candidate, no hook method shared
    with the library's effect of that name, and not in the library's composition."""
    cls = LAWS[name].plant
    lib = library()
    assert cls not in lib.values() and cls.__module__.startswith("heavecomp.benchmark.truth.")
    for m in cls.methods():
        assert all(getattr(cls, m) is not getattr(c, m, None) for c in lib.values())
    comp = truth_composition(name)
    assert cls in comp.classes and not set(comp.classes) & set(lib.values())


@pytest.mark.parametrize("name", [None, pytest.param("line_inertance", marks=pytest.mark.slow)])
def test_a_truth_stepper_with_every_law_off_is_the_plain_stepper_bit_for_bit(name, bed):
    """The truth laws live in two steppers (:func:`truth_composition`: the benchmark's six, installed, and every
    other law); a law that is off adds nothing, so with all of them off each runs the plain stepper's run, bit for
    bit (a law's run does not depend on which other laws its stepper holds)."""
    from heavecomp.benchmark.truth import INSTALLED
    from heavecomp.diagnosis.stepper import CHANNELS, run_fx
    from heavecomp.effects.compose import composition
    from heavecomp.plants.cmc import plant_vectors

    comp = truth_composition(name)
    both = set(truth_composition().classes) | set(truth_composition("line_inertance").classes)
    assert both == {law.plant for law in LAWS.values() if law.plant is not None}
    names = {c.name for c in comp.classes}
    if name is None:
        assert names == set(INSTALLED)
    else:
        assert not names & set(INSTALLED)
    runs = [run_fx(plant_vectors(NOMINAL), c, c.ep([]), bed.hs, bed.h, bed.n_steps, bed.out_every)
            for c in (composition(()), comp)]
    n = CHANNELS.index("gas_pressure") + 1  # the plain stepper's channels (a truth stepper's states follow them)
    assert np.array_equal(runs[0][:, :n], runs[1][:, :n])


@pytest.mark.parametrize("name", [n for n, law in LAWS.items() if law.plant is not None
                                  and law.plant.hook == "seal_friction"])
def test_a_seal_truths_static_limit_holds_the_friction_the_motion_starts_against(name):
    """The stepper's ordering (tests/test_conformance.py, for the candidates) holds for the truth laws too, at
    their drawn parameters: at rest the static limit in a direction is at least the sliding friction at v = 0
    in that direction.  The LuGre bristle once scaled its static limit by its share twice (its ``static`` on
    top of its ``jump``): a generated run hit the stepper's event cap (207 steps in 120 s, 83 samples
    F_f v < 0)."""
    from heavecomp.plants.cmc import plant_vectors
    from test_conformance import _memory_states

    cls = LAWS[name].plant
    comp = truth_composition(name)
    fn = comp.functions
    plant = plant_vectors(NOMINAL)
    slots = [k - 4 for k in comp.slots[cls.name]]
    for _, draw in _draws(name, n=4):
        e = cls(**{k: v for k, v in draw.parameters.items() if k in {f.name for f in cls.fields()}})
        EP = comp.ep([e])
        for mem in _memory_states(cls, plant, e.prm):
            x = np.zeros(comp.n_states)
            x[slots] = mem
            for p, s, d in ((0.0, 0.0, 1.0), (2.4e6, 0.5, -1.0), (2.4e6, -0.5, 1.0), (4e6, 0.0, -1.0)):
                X = (s, 0.0, 0.0, 0.0) + tuple(x)
                lim = fn["static_limit_fx"](plant.code, p, s, d, X, 0.0, plant.FP, EP)
                kinetic = fn["sliding_friction_fx"](plant.code, d, 0.0, p, s, X, plant.FP, EP) * d
                assert lim >= kinetic, (draw.parameters, mem, p, s, d, lim, kinetic)


def test_diagnosis_never_imports_the_benchmark():
    """The benchmark checks the diagnosis: the diagnosis does not know it (same layer, one way)."""
    for f in sorted((ROOT / "heavecomp" / "diagnosis").rglob("*.py")):
        assert not {m for m in _imports(f) if m.startswith("heavecomp.benchmark")}, f.name


def test_a_case_refuses_what_no_law_knows():
    with pytest.raises(ParameterError, match="label"):
        Case("friction_drag", 1)
    with pytest.raises(ParameterError, match="variant"):
        Case("sensor_gain", 1, variant="sideways")
    with pytest.raises(ParameterError, match="sea"):
        Case("none", 1, sea="storm")
