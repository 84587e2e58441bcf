"""Issue 13.3 (output side): output paths are checked before any work; one line naming the flag, exit 2."""


import pytest

from _cli import run as run_cli


_run = run_cli  # in this process (tests/_cli.py): what the command writes or refuses


def _one_line(r, *fragments):
    assert r.returncode == 2, (r.stdout, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in r.stderr, r.stderr
    for f in fragments:
        assert f in lines[0], lines[0]


@pytest.mark.parametrize("cmd", [
    ["simulate", "P", "--duration", "1e7"],
    ["analyse", "P"],
    ["diagnose", "run.csv", "--params", "P"],
    ["campaign", "default"],
    ["stickslip", "default", "--duration", "5"],
    ["identify", "seal", "f.csv"],
])
def test_out_pointing_at_a_file_fails_before_the_work(cmd, tmp_path, paper_a_toml):
    f = tmp_path / "taken"
    f.write_text("x")
    argv = [str(paper_a_toml) if a == "P" else a for a in cmd]
    # inputs that do not exist: the output error comes first, so it was checked before any reading or work
    _one_line(_run(*argv, "--out", str(f)), "--out", "is an existing file")
    _one_line(_run(*argv, "--out", str(f / "sub")), "--out", "is a file, not a folder")
    assert f.read_text() == "x"


def test_out_in_an_unwritable_place(paper_a_toml):
    # /proc takes no new files even for root (chmod does not stop root, a pseudo file system does)
    _one_line(_run("simulate", str(paper_a_toml), "--duration", "1", "--out", "/proc/heavecomp-out"),
              "--out /proc/heavecomp-out", "not writable")


def test_params_output_checked(tmp_path):
    _one_line(_run("params", "paper_a", "-o", "/nonexistent/dir/x.toml"), "-o /nonexistent/dir/x.toml",
              "does not exist")
    _one_line(_run("params", "paper_a", "-o", str(tmp_path)), "is a folder")
    r = _run("params", "paper_a", "-o", str(tmp_path / "ok.toml"))
    assert r.returncode == 0 and "[compensator]" in (tmp_path / "ok.toml").read_text()


def test_out_that_does_not_exist_yet_is_fine_and_not_created_by_the_check(tmp_path):
    from heavecomp.report.paths import out_dir

    target = tmp_path / "a" / "b"
    assert out_dir(target) == target
    assert not (tmp_path / "a").exists()
