"""A campaign's runs.csv counts every run once, and odd tables are one line, not a traceback
(issue 14 items 4 and 8)."""

from __future__ import annotations

import gzip

import pytest

from heavecomp.campaign import spec
from heavecomp.errors import InputError

from test_campaign import TINY as _BASE  # noqa: E402 - the suite's tiny campaign, made smaller

TINY = (_BASE.replace('name = "tiny"', 'name = "tiny-table"').replace("duration = 90.0", "duration = 60.0")
        .replace("seeds = 2", "seeds = 1").replace('regimes = ["none", "rotating_eq7", "stribeck"]',
                                                   'regimes = ["none", "stribeck"]').replace("bins = 80", "bins = 40"))


@pytest.fixture(scope="module")
def done(tmp_path_factory):
    from heavecomp.campaign.execute import run_campaign

    camp = spec.loads(TINY, source="tiny.toml")
    out = tmp_path_factory.mktemp("camp")
    info = run_campaign(camp, out, workers=1)
    assert info.complete
    return camp, info.table_path


def _stats(camp, path):
    from heavecomp.campaign.execute import read_table
    from heavecomp.campaign.stats import statistics

    return statistics(camp, read_table(path, camp))


def _copy(src, dst, extra_lines=(), transform=None):
    lines = src.read_text(encoding="utf-8").splitlines()
    lines = (transform(lines) if transform else lines) + list(extra_lines)
    dst.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return dst


def test_duplicated_row_counts_once(done, tmp_path):
    camp, table = done
    ref = _stats(camp, table)
    lines = table.read_text(encoding="utf-8").splitlines()
    dup = _copy(table, tmp_path / "runs.csv", extra_lines=[lines[1], lines[2]])
    got = _stats(camp, dup)
    for g in ref["groups"]:
        a, b = ref["groups"][g], got["groups"][g]
        for key, val in a.items():
            if isinstance(val, float):
                assert b[key] == val, (g, key)
    from heavecomp.campaign.execute import read_table

    assert len(read_table(dup, camp)["run_id"]) == len(lines) - 1


def test_foreign_run_id_is_refused(done, tmp_path):
    camp, table = done
    lines = table.read_text(encoding="utf-8").splitlines()
    k = lines[0].split(",").index("run_id")
    cells = lines[1].split(",")
    cells[k] = "other-campaign-0042"
    bad = _copy(table, tmp_path / "runs.csv", extra_lines=[",".join(cells)])
    with pytest.raises(InputError, match=r"row \d+: run_id 'other-campaign-0042' is not a run of this campaign"):
        _stats(camp, bad)


def test_same_run_id_different_results_is_refused(done, tmp_path):
    camp, table = done
    lines = table.read_text(encoding="utf-8").splitlines()
    header = lines[0].split(",")
    cells = lines[1].split(",")
    j = header.index("wob_std") if "wob_std" in header else len(cells) - 1
    cells[j] = str(float(cells[j]) * 2 + 1)
    bad = _copy(table, tmp_path / "runs.csv", extra_lines=[",".join(cells)])
    with pytest.raises(InputError, match="appears twice with different results"):
        _stats(camp, bad)


def test_ragged_row_is_refused(done, tmp_path):
    camp, table = done
    bad = _copy(table, tmp_path / "runs.csv", transform=lambda ls: ls[:2] + [ls[2] + ",1.0"] + ls[3:])
    with pytest.raises(InputError, match=r"row 3 has \d+ fields, the header has"):
        _stats(camp, bad)


@pytest.mark.parametrize("kind", ["gzip", "latin1"])
def test_odd_runs_csv_is_one_line_exit_2(done, tmp_path, capsys, kind):
    """`heavecomp campaign` resuming into a folder whose runs.csv is gzip or not UTF-8: exit 2, one line."""
    from heavecomp.cli import main

    camp, table = done
    (tmp_path / "c.toml").write_text(TINY)
    out = tmp_path / "out"
    out.mkdir()
    raw = table.read_bytes()
    if kind == "gzip":
        (out / "runs.csv").write_bytes(gzip.compress(raw))
    else:
        (out / "runs.csv").write_bytes(raw.replace(b"run_id", "run_id\u00e9".encode("latin-1"), 1))
    rc = main(["campaign", str(tmp_path / "c.toml"), "--out", str(out), "--workers", "1"])
    err = capsys.readouterr().err.strip()
    assert rc == 2, err
    assert len(err.splitlines()) == 1 and "runs.csv" in err
    assert "Traceback" not in err
