"""Issue 13.7: reports people want to read — units in tables, figure defects fixed, modes sorted and named."""

import re
from types import SimpleNamespace

import numpy as np
import pytest

from _cli import run as run_cli  # in this process: these tests check what the command writes


def md_tables(text: str) -> list[list[str]]:
    """Header cells of every Markdown table in ``text``."""
    out = []
    lines = text.splitlines()
    for i, ln in enumerate(lines[:-1]):
        if ln.startswith("|") and re.match(r"^\|(-+\|)+$", lines[i + 1].replace(" ", "")):
            out.append([c.strip() for c in ln.strip("|").split("|")])
    return out


def assert_tables_have_units(text: str):
    tables = md_tables(text)
    assert tables
    for head in tables:
        has_unit_col = any(h.lower() == "unit" for h in head)
        for h in head[1:]:
            assert has_unit_col or "[" in h or h.lower() in ("parameters", "value", "effect", "verdict"), \
                f"column {h!r} of table {head} has no unit"


def test_analysis_report_tables_have_units_and_sorted_named_modes(paper_a_toml, tmp_path):
    r = run_cli("analyse", str(paper_a_toml), "--out", str(tmp_path),
                "--points", "40")
    assert r.returncode == 0, r.stderr
    text = (tmp_path / "report.md").read_text()
    assert_tables_have_units(text)
    assert "mode 1: top mass on the gas spring" in text and "mode 2: lower mass" in text
    assert "mode 1: top mass on the gas spring" in r.stdout


def test_mode_rows_sorted_and_named():
    from heavecomp.report.analysis import mode_rows

    rows = mode_rows([11.0, 2.7], [0.02, 0.03])
    assert [r[1] for r in rows] == [2.7, 11.0]
    assert rows[0][0].startswith("mode 1") and rows[0][4] == 0.03  # damping follows its mode
    assert rows[0][3] == pytest.approx(2 * np.pi / 2.7)


def test_diagnosis_eigenfrequencies_sorted_and_named():
    from heavecomp.diagnosis.where import eigenfrequencies
    from heavecomp.params import paper_a
    from heavecomp.report.diagnosis import named_modes

    f = eigenfrequencies(paper_a())
    text = named_modes(f)
    vals = [float(x) for x in re.findall(r"([0-9.]+) Hz", text)]
    assert vals == sorted(vals) and len(vals) == 3
    # the stuck mode (lower mass on k_ds + k_F alone) lies between the two sliding modes here
    assert re.search(r"Hz \(stuck cylinder", text)
    order = [m.group(1) for m in re.finditer(r"Hz \((sliding, low|sliding, high|stuck)", text)]
    assert set(order) == {"sliding, low", "sliding, high", "stuck"}


def _fig_extent(fig, artist):
    fig.canvas.draw()
    return artist.get_window_extent(fig.canvas.get_renderer())


def test_influence_axes_on_the_data_and_legend_beside_the_arrows():
    from heavecomp.report.rigs import plot_influence

    zc = np.geomspace(1e-3, 3.0, 200)
    Dc = 1.0 / zc ** 2  # a critical curve that runs to 1e6 at small zeta*
    inf = {f"var{i}": {"zeta": list(np.geomspace(0.1, 0.6, 5) * (1 + 0.2 * i)), "D": list(np.geomspace(0.5, 8, 5))}
           for i in range(6)}
    fig = plot_influence(inf, zc, Dc)
    ax = fig.axes[0]
    lo, hi = ax.get_ylim()
    assert hi <= 8 * 2.01 and lo >= 0.5 / 2.01  # not 1e6
    leg = _fig_extent(fig, ax.get_legend())
    box = ax.get_window_extent(fig.canvas.get_renderer())
    assert leg.x0 >= box.x1 - 1  # beside the axes, so over no arrow


def test_where_figure_is_binned_not_overplotted():
    from heavecomp.report.diagnosis import fig_where

    n = 40_000
    rng = np.random.default_rng(0)
    t = np.arange(n) * 0.05
    v = 0.2 * np.sin(0.5 * t) + 0.01 * rng.standard_normal(n)
    wob = rng.standard_normal(n) * 1e3
    diag = SimpleNamespace(traces_={"t": t, "stroke_velocity": v, "nominal": {"wob": wob}, "measured": {"wob": 0 * wob}},
                           split_={"settle": 10.0},
                           where_={"regimes": {"stuck": 0.2, "breakaway": 0.8}, "bands": {"wave": 1.0}})
    fig = fig_where(diag)
    ax = fig.axes[0]
    marks = sum(len(c.get_offsets()) if hasattr(c, "get_offsets") else 0 for c in ax.collections)
    assert 0 < marks < n / 10, marks  # a few hundred bins, not one dot per sample


def test_channel_effect_parameters_in_their_channels_unit():
    """A sensor offset on the pressure reads in Pa and Pa/s, on the stroke in m and m/s (not "unit of
    the channel (N, m or Pa)"); without a channel the effect's own generic unit stays."""
    from heavecomp.report.diagnosis import _effect_units, _with_unit

    u = _effect_units("sensor_offset", {"channel": "pressure", "offset": 101325.0, "drift": 0.0})
    assert u == {"offset": "Pa", "drift": "Pa/s"}
    assert _with_unit("offset", -0.0328, units=_effect_units("sensor_offset", {"channel": "stroke"})) == "offset = -0.0328 m"
    assert "unit of the channel" in _effect_units("sensor_offset")["offset"]
