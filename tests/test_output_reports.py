"""Issue 21.6: every command that writes a folder writes its report -- ``identify`` wrote none and
``stickslip --map`` no figure."""

from __future__ import annotations

import json
import re

from heavecomp.cli import main


def _figures_embedded(folder):
    md = (folder / "report.md").read_text()
    html = (folder / "report.html").read_text()
    figs = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", md)
    assert figs and all((folder / f).is_file() for f in figs), figs
    assert html.count("data:image/png;base64,") == len(figs) and "<p class=\"missing\">" not in html
    assert md.rstrip().splitlines()[-1].startswith("*Provenance: ")
    return md


def test_identify_seal_writes_a_report(data_dir, tmp_path, capsys):
    files = [str(data_dir / "seal-friction" / f"O-ring_{p}bar.csv") for p in (1, 7)]
    out = tmp_path / "seal"
    assert main(["identify", "seal", *files, "--out", str(out), "--n-boot", "50"]) == 0
    md = _figures_embedded(out)
    m = json.loads((out / "metrics.json").read_text())
    assert f"C_p = {m['C_p_N_per_bar']:.3f}" in md  # the report states the result of this run


def test_stickslip_map_writes_its_figure_and_report(tmp_path, capsys):
    out = tmp_path / "ss"
    assert main(["stickslip", "default", "--map", "3", "--out", str(out)]) == 0
    md = _figures_embedded(out)
    m = json.loads((out / "metrics.json").read_text())
    assert "critical_curve.png" in md and f"{100 * m['map']['agreement']:.1f} %" in md
    assert not (out / "simulation.png").exists()  # no --duration: no simulation figure
