"""The README cannot drift: its Python snippets run, and every number it quotes as a result is
recomputed here from a fresh run (or the README stops quoting it).

``CLAIMS`` lists each quoted result with the code that recomputes it.  Any other number in the
README's prose must be a setting or a citation listed in ``NOT_RESULTS``: a new measured figure
added to the README without a check here fails :func:`test_every_number_is_checked_or_a_setting`.
"""

from __future__ import annotations

import functools
import gzip
import math
import re
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")


def _prose(text: str) -> str:
    """The README without fenced code blocks (commands, parameter files, Python)."""
    return re.sub(r"```.*?```", "", text, flags=re.S)


def _python_blocks(text: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def _k_eff_kn():
    from heavecomp.params import paper_a

    return paper_a("stribeck").k_eff / 1e3


@functools.cache
def _modes():
    from heavecomp.analysis.summary import analyse
    from heavecomp.params import paper_a

    s = analyse(paper_a("stribeck"), n_points=50)["summary"]
    return s["k_eff_dc"] / 1e3, s["natural_frequencies"]


def _eq7_wins_back():
    """Share of the friction's WOB peak-to-peak penalty that eq. 7 wins back (paper-A sine case)."""
    from heavecomp.params import paper_a
    from heavecomp.simulate import simulate

    p2p = {}
    for model in ("none", "stribeck", "rotating_eq7"):
        p = paper_a(model)
        p2p[model] = simulate(p, 240.0, rate=20.0).metrics()["wob_p2p"]
    return (p2p["stribeck"] - p2p["rotating_eq7"]) / (p2p["stribeck"] - p2p["none"])


def _data_mib():
    files = [f for f in (ROOT / "heavecomp" / "data").rglob("*") if f.is_file() and "__pycache__" not in f.parts]
    return sum(f.stat().st_size for f in files) / 2**20


@functools.cache
def _example_log():
    """Duration [min] and rate [Hz] of the shipped example rig log (time column in ms)."""
    from heavecomp.data import EXAMPLE_RUN

    with gzip.open(EXAMPLE_RUN, "rt") as f:
        header = f.readline().strip().split(",")
        t = np.loadtxt(f, delimiter=",", usecols=header.index("Time")) / 1e3
    return (t[-1] - t[0]) / 60.0, 1.0 / np.median(np.diff(t))


@functools.cache
def _exp2():
    from heavecomp.pneumatic import plant as pn
    from heavecomp.pneumatic import stepper as PS

    st = PS.simulate(pn.default(), 3.0, rate=1000.0)["stats"]
    return st["t_first_stick"], st["t_second_breakaway"]


#: quoted result -> a check that recomputes it (each returns True when the README's figure holds)
CLAIMS = {
    "eq. 14: 43.07": lambda: round(_k_eff_kn(), 2) == 43.07,
    "k_eff_dc = 43.07 kN/m, modes 2.76 / 11.03 rad/s": lambda: (
        round(_modes()[0], 2) == 43.07 and [round(w, 2) for w in _modes()[1]] == [2.76, 11.03]),
    "wins back about a third": lambda: 0.28 <= _eq7_wins_back() <= 0.39,
    "(≈ 2.7 MiB)": lambda: round(_data_mib(), 1) == 2.7,
    "10 min at 10 Hz": lambda: (round(_example_log()[0]) == 10 and round(_example_log()[1]) == 10),
    "stick near 1.3 s, restart near 1.7 s": lambda: (
        abs(_exp2()[0] - 1.3) <= 0.1 and abs(_exp2()[1] - 1.7) <= 0.1),
}

#: numbers in the prose that are settings, citations or definitions, not results
NOT_RESULTS = ("WITSML 1.4.1.1", "LAS 2.0", "FMI 3.0", "ICCAS 2012", "eq. 7", "eq. 4", "eq. 14", "eqs. 1-7", "Kagawa 1999", "Python ≥ 3.11",
               "1 m, 12 s heave", "~5 s on 2 cores", "40x40 simulations", "Figs. 7-8", "Fig. 3",
               "exit code 2", "80 t / 30 t masses", "k_ds = 2.08 MN/m", "printed 208 kN/m", "n < 1",
               "mass ≤ 0", "v_S ≤ 0", "--map 40", "two hours", "3600", "600", "--rate 20", "--duration 60",
               "C_p (200 N/bar)", "Exp. 2")


@pytest.mark.parametrize("claim", sorted(CLAIMS))
def test_quoted_number_matches_a_fresh_run(claim):
    assert claim in README, f"README no longer quotes {claim!r}: drop it from CLAIMS"
    assert CLAIMS[claim](), f"README quotes {claim!r}, a fresh run disagrees"


def test_every_number_is_checked_or_a_setting():
    prose = _prose(README)
    for known in sorted((*CLAIMS, *NOT_RESULTS), key=len, reverse=True):
        prose = prose.replace(known, "")
    prose = re.sub(r"\]\([^)]*\)", "]", prose)  # link targets (file names with digits)
    prose = re.sub(r"`[^`]*`", "", prose)        # inline code: names, keys
    left = re.findall(r"(?<![\w.])\d+(?:\.\d+)?(?:\s?(?:x|%|s|ms|Hz|kN|MB|MiB|GB|rad/s|kN/m|N))?(?![\w])", prose)
    assert not left, f"README quotes numbers no test checks: {left}; add each to CLAIMS or NOT_RESULTS"


def test_python_snippets_run():
    blocks = _python_blocks(README)
    assert blocks, "the README has a Python API section"
    ns: dict = {}
    for code in blocks:
        exec(compile(code, "README.md", "exec"), ns)  # noqa: S102 - the README's own code
    res, res_buoy = ns["res"], ns["res_buoy"]
    assert math.isfinite(res.metrics()["wob_std"]) and res.metrics()["wob_std"] > 0
    # measured heave is used: the buoy run's heave is the buoy record's, not the parameter file's sine
    assert not np.allclose(res_buoy["heave"], res["heave"])
