"""The diagnosis as parts (issue 20 items 1 and 4): one frozen verdict policy whose every field is
documented and evidenced, the verdict decided under it, and effects fitted by
name from their fit spec."""

import ast
import dataclasses
import inspect
from pathlib import Path

import pytest

from heavecomp.diagnosis import GapDiagnoser
from heavecomp.diagnosis.fitting import CandidateFit
from heavecomp.diagnosis.policy import VerdictPolicy
from heavecomp.diagnosis.verdict import Evidence, decide
from heavecomp.effects.registry import library
from heavecomp.errors import ParameterError
from heavecomp.params import paper_a

ROOT = Path(__file__).resolve().parents[1]
CH = ("wob", "stroke", "pressure")


def test_every_policy_field_says_what_it_guards_against_and_has_evidence_in_the_docs():
    """A field without an attribute docstring, or missing from docs/diagnosis.md's evidence table,
    is a threshold nobody can judge."""
    tree = ast.parse(inspect.getsource(VerdictPolicy))
    body = tree.body[0].body
    documented = {node.target.id for node, after in zip(body, body[1:])
                  if isinstance(node, ast.AnnAssign) and isinstance(after, ast.Expr)
                  and isinstance(after.value, ast.Constant) and isinstance(after.value.value, str)}
    fields = {f.name for f in dataclasses.fields(VerdictPolicy)}
    assert fields - documented == set()
    table = (ROOT / "docs" / "diagnosis.md").read_text().split("### The verdict policy", 1)[1].split("\n## ", 1)[0]
    assert {f for f in fields if f"`{f}`" not in table} == set()


def test_the_settings_write_into_the_policy_and_a_policy_changes_the_verdict():
    """GapDiagnoser's threshold settings override the policy's fields; a stricter policy turns the same
    fits from a named effect into inconclusive."""
    d = GapDiagnoser(paper_a("stribeck"), none_ratio=1.5, policy=VerdictPolicy(high_margin=0.3))
    p = d.verdict_policy()
    assert p.none_ratio == 1.5 and p.high_margin == 0.3 and p.penalty == d.penalty
    fits = [_fit("flow_loss", 0.7), _fit("gas_leak", 0.2)]
    ones = {c: 1.0 for c in CH}
    gap = {c: {"rms_validate": 10.0} for c in CH}
    ev = Evidence({c: 0.0 for c in ("friction", "gas_spring", "flow_line", "string_formation", "sensors",
                                    "heave_input")})
    assert decide(fits, gap, ones, ones, VerdictPolicy(), ev).effect == "flow_loss"
    assert decide(fits, gap, ones, ones, VerdictPolicy(min_explained=0.8), ev).effect == "inconclusive"


def _fit(name, explained):
    return CandidateFit(name, {}, {}, {c: {"rms_before": 1.0, "rms_after": 0.5, "shrink": 0.5} for c in CH},
                        explained, explained, explained, 1, explained - 0.03, 0.0, {})


def test_any_registered_effect_is_a_candidate_by_name():
    """``charge_drift`` is registered but no default candidate: it is accepted by name; an unknown
    name is refused in one line naming the known ones."""
    assert "charge_drift" in library() and not library()["charge_drift"].fit.candidate
    assert GapDiagnoser(paper_a("stribeck"), ["charge_drift", "flow_loss"]).candidates == ["charge_drift", "flow_loss"]
    with pytest.raises(ParameterError, match="charge_drift"):
        GapDiagnoser(paper_a("stribeck"), ["charge_drfit"])
