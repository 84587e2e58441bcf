"""`heavecomp identify`: results on the real files, one-line errors with exit code 2."""

from __future__ import annotations

import json

import pytest

from heavecomp.cli import main


def test_identify_seal_writes_cp(data_dir, tmp_path, capsys):
    files = [str(data_dir / "seal-friction" / f"O-ring_{p}bar.csv") for p in (1, 7)]
    assert main(["identify", "seal", *files, "--out", str(tmp_path), "--n-boot", "50"]) == 0
    m = json.loads((tmp_path / "metrics.json").read_text())
    assert m["C_p_N_per_bar"] > 0 and m["settings"]["n_boot"] == 50
    assert "N/bar" in capsys.readouterr().out


@pytest.mark.parametrize("extra, message", [
    (["--cutoff", "600"], "cutoff must be in (0, fs/2) = (0, 500.008) Hz, got 600"),
    (["--split", "30"], "--split must lie inside the record (1 .. 23.84 s), got 30"),
    (["--decimate", "0"], "decimate must be a positive integer, got 0"),
])
def test_identify_emps_bad_settings_exit_2(data_dir, tmp_path, capsys, extra, message):
    data = str(data_dir / "emps" / "DATA_EMPS.mat")
    assert main(["identify", "emps", data, "--out", str(tmp_path), *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"heavecomp identify: error: {message}"


def test_identify_seal_bad_input_exit_2(data_dir, tmp_path, capsys):
    one = str(data_dir / "seal-friction" / "O-ring_3bar.csv")
    assert main(["identify", "seal", one, "--out", str(tmp_path)]) == 2
    assert capsys.readouterr().err.strip() == ("heavecomp identify: error: seal friction fit needs files "
                                                "at two or more pressures")
    bad = tmp_path / "bad.csv"
    bad.write_text("1 2 3\n")
    assert main(["identify", "seal", one, str(bad), "--out", str(tmp_path)]) == 2
    assert capsys.readouterr().err.strip().endswith("bad.csv: row 1 has 3 columns, expected 7 "
                                                    "(time [ms], laser [V], pressure [V], force [V], "
                                                    "position [mm], pressure [bar], force [N])")
