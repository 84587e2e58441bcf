"""Issue 21.3: results whole or absent.

Every command that writes ``--out DIR`` writes into ``.DIR.partial`` beside it and moves it into place
when it has finished (:mod:`heavecomp.report.output`); a second process on the same ``DIR`` is refused;
a full disk gives one line and leaves nothing torn; a killed run never leaves a folder that reads as
complete, nor a mix of two runs.
"""

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from heavecomp.report.output import MARKER, Staged, lock_path, staging_path, write_text_atomic

LINUX = sys.platform.startswith("linux")


def _cli(*args, cwd=None, **kw):
    return subprocess.run([sys.executable, "-m", "heavecomp", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, **kw)


def _one_line(r, code=2):
    assert r.returncode == code, (r.returncode, r.stdout, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in r.stderr, r.stderr
    return lines[0]


@contextlib.contextmanager
def _lock_held_elsewhere(out):
    """Another process that holds the lock of ``out`` until the block ends (then it is killed)."""
    holder = subprocess.Popen([sys.executable, "-c", "import time\nfrom heavecomp.report.output import Staged\n"
                               f"Staged({str(out)!r}).acquire()\nprint('locked', flush=True)\ntime.sleep(60)"],
                              stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        yield holder.pid
    finally:
        holder.kill()
        holder.wait()
        holder.stdout.close()


def _kill_simulate_when(params, out, ready):
    """SIGKILL a day-long ``simulate PARAMS --out OUT`` as soon as ``ready()`` (it must still be running)."""
    proc = subprocess.Popen([sys.executable, "-m", "heavecomp", "simulate", str(params), "--duration", "86400", "-q",
                             "--out", str(out)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 240
        while time.monotonic() < deadline and proc.poll() is None and not ready():
            time.sleep(0.02)
        assert proc.poll() is None, "the run finished (or failed) before it could be killed"
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def _siblings(folder: Path) -> list[str]:
    """What lies beside ``folder`` besides the inputs of a test: staging folders, locks, temporaries."""
    return sorted(p.name for p in folder.parent.iterdir() if p.name.startswith("."))


# -- the mechanism, in process -------------------------------------------------------------------------

def test_commit_moves_the_folder_into_place_and_replaces_an_old_result_whole(tmp_path):
    out = tmp_path / "run"
    with Staged(out) as work:
        assert work == staging_path(out) and work.parent == tmp_path
        (work / "metrics.json").write_text('{"a": 1}')
        (work / "old_only.csv").write_text("x")
        assert not out.exists()  # nothing at --out while the run works
    assert json.loads((out / "metrics.json").read_text()) == {"a": 1}
    with Staged(out) as work:
        (work / "metrics.json").write_text('{"a": 2}')
        assert (out / "metrics.json").read_text() == '{"a": 1}'  # the old result stays readable meanwhile
    assert sorted(p.name for p in out.iterdir()) == [MARKER, "metrics.json"]  # replaced whole: no file of the old run
    assert json.loads((out / "metrics.json").read_text()) == {"a": 2}
    assert _siblings(out) == []  # no lock, no staging folder left


def test_a_failed_run_leaves_the_old_result_untouched(tmp_path):
    out = tmp_path / "run"
    with Staged(out) as work:
        (work / "metrics.json").write_text("old")
    with pytest.raises(RuntimeError):
        with Staged(out) as work:
            (work / "metrics.json").write_text("new, half")
            raise RuntimeError("killed")
    assert (out / "metrics.json").read_text() == "old"
    assert _siblings(out) == []


def test_a_run_that_writes_nothing_leaves_out_as_it_was(tmp_path):
    out = tmp_path / "a" / "b"
    with Staged(out):
        pass
    assert not (tmp_path / "a").exists()  # the folders made for the lock are removed again


def test_a_folder_of_other_files_is_never_replaced_but_gets_the_results_file_by_file(tmp_path):
    mine = tmp_path / "documents"
    mine.mkdir()
    (mine / "thesis.tex").write_text("years of work")
    (mine / "metrics.json").write_text("an older result")
    with Staged(mine) as work:
        (work / "metrics.json").write_text("new")
        (work / "wob.png").write_bytes(b"png")
    assert (mine / "thesis.tex").read_text() == "years of work"
    assert (mine / "metrics.json").read_text() == "new" and (mine / "wob.png").read_bytes() == b"png"
    assert not (mine / MARKER).exists()  # still not a folder a re-run may replace whole
    assert _siblings(mine) == []


def test_out_whose_parent_takes_no_files_is_staged_inside(tmp_path, monkeypatch):
    here = tmp_path / "cwd"
    here.mkdir()
    (here / "notes.txt").write_text("mine")
    real = os.access
    monkeypatch.setattr(os, "access", lambda p, mode, **kw: False if Path(p) == tmp_path else real(p, mode, **kw))
    with Staged(here) as work:
        assert work.parent == here and lock_path(here).parent == here
        (work / "metrics.json").write_text("{}")
    assert sorted(p.name for p in here.iterdir()) == ["metrics.json", "notes.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cwd"]


def test_lock_refuses_a_second_owner_and_a_dead_owners_lock_is_taken_over(tmp_path):
    from heavecomp.report.output import OutputBusy

    out = tmp_path / "run"
    with _lock_held_elsewhere(out) as pid:
        with pytest.raises(OutputBusy, match=rf"another heavecomp process \(pid {pid}\)"):
            Staged(out).acquire()
    # the holder died: its lock file (still naming its pid) is stale and taken over
    assert lock_path(out).read_text().strip() == str(pid)
    with Staged(out) as work:
        assert lock_path(out).read_text().strip() == str(os.getpid())
        (work / "metrics.json").write_text("{}")
    assert not lock_path(out).exists()


def test_atomic_file_write_keeps_the_old_file_on_failure(tmp_path, monkeypatch):
    f = tmp_path / "p.toml"
    write_text_atomic(f, "old")
    assert f.read_text() == "old"

    class Full(OSError):
        pass

    real = os.fsync

    def fsync(fd):
        raise Full(28, "No space left on device")

    monkeypatch.setattr(os, "fsync", fsync)
    with pytest.raises(Full):
        write_text_atomic(f, "new")
    monkeypatch.setattr(os, "fsync", real)
    assert f.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.toml"]  # no temporary left


# -- the commands --------------------------------------------------------------------------------------

def test_second_process_on_the_same_out_is_refused_in_one_line(paper_a_toml, tmp_path):
    out = tmp_path / "same"
    with _lock_held_elsewhere(out) as pid:
        for cmd in (["analyse", paper_a_toml], ["simulate", paper_a_toml, "--duration", "5"]):
            line = _one_line(_cli(*cmd, "--out", out))
            assert f"--out {out}: another heavecomp process (pid {pid}) is writing this folder" in line
        assert not out.exists()


@pytest.mark.parametrize("ending", ["interrupted", "failed"])
def test_interrupted_or_failed_command_leaves_nothing(paper_a_toml, tmp_path, monkeypatch, capsys, ending):
    """Ctrl-C (exit 130) or a command returning non-zero: the half-written staging folder is dropped."""
    from heavecomp import cli
    from heavecomp.commands import analyse

    def run(args):
        (Path(args.out) / "analysis.json").write_text("{half")
        if ending == "interrupted":
            raise KeyboardInterrupt
        return 1

    monkeypatch.setattr(analyse, "run", run)
    out = tmp_path / "a"
    code = cli.main(["analyse", str(paper_a_toml), "--out", str(out)])
    assert code == (130 if ending == "interrupted" else 1)
    assert not out.exists() and _siblings(out) == []


def test_params_output_is_written_whole(tmp_path):
    f = tmp_path / "p.toml"
    r = _cli("params", "paper_a", "-o", f)
    assert r.returncode == 0, r.stderr
    assert "[compensator]" in f.read_text() and sorted(p.name for p in tmp_path.iterdir()) == ["p.toml"]
    assert f.stat().st_mode & 0o044  # readable like a file opened normally, not mkstemp's 0600


@pytest.mark.slow
@pytest.mark.skipif(not LINUX, reason="SIGKILL semantics checked on Linux")
def test_killed_rerun_keeps_the_old_result_and_leaves_no_mix(paper_a_toml, tmp_path):
    """R3: a finished run, re-run with other parameters and SIGKILLed while writing timeseries.csv."""
    out = tmp_path / "stale"
    r = _cli("simulate", paper_a_toml, "--duration", "120", "-q", "--out", out)
    assert r.returncode == 0, r.stderr
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    sine = tmp_path / "sine.toml"
    sine.write_text(paper_a_toml.read_text().replace("amplitude = 1.0", "amplitude = 0.5"))
    staged_csv = staging_path(out) / "timeseries.csv"
    _kill_simulate_when(sine, out, lambda: staged_csv.is_file() and staged_csv.stat().st_size > 1_000_000)
    # the folder at --out is the first run, byte for byte: no new CSV beside old metrics
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    # the next run takes over the dead run's lock, drops its half-written staging folder and replaces whole
    r = _cli("simulate", sine, "--duration", "30", "-q", "--out", out)
    assert r.returncode == 0, r.stderr
    m = json.loads((out / "metrics.json").read_text())
    assert m["provenance"]["command"].endswith(f"--out {out}") and str(sine) in m["provenance"]["command"]
    rows = (out / "timeseries.csv").read_text().count("\n") - 1
    assert rows == 30 * 20 + 1  # the new run's own CSV, whole
    assert _siblings(out) == []


@pytest.mark.skipif(not LINUX, reason="SIGKILL semantics checked on Linux")
def test_killed_first_run_leaves_nothing_that_reads_as_a_result(paper_a_toml, tmp_path):
    out = tmp_path / "run"
    _kill_simulate_when(paper_a_toml, out, staging_path(out).exists)
    assert not out.exists()
    assert set(_siblings(out)) <= {".run.lock", ".run.partial"}  # hidden, and named as unfinished


# -- disk full -----------------------------------------------------------------------------------------

@pytest.fixture
def small_disk(tmp_path):
    """A 64 kB tmpfs (needs root and mount permission; skipped with the reason otherwise)."""
    d = tmp_path / "full"
    d.mkdir()
    if not LINUX or os.geteuid() != 0:
        pytest.skip("a small tmpfs needs root on Linux")
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(d)], capture_output=True, text=True)
    if r.returncode != 0:
        pytest.skip(f"mount -t tmpfs not permitted here: {r.stderr.strip()}")
    try:
        yield d
    finally:
        subprocess.run(["umount", str(d)], check=False)


def test_disk_too_small_for_the_time_series_is_refused_before_the_run(paper_a_toml, small_disk):
    line = _one_line(_cli("simulate", paper_a_toml, "--duration", "3600", "--out", small_disk / "s"))
    assert f"--out {small_disk / 's'}: about" in line and "free on its file system" in line
    assert list(small_disk.iterdir()) == []


def test_disk_that_fills_during_the_run_gives_one_line_and_nothing_torn(paper_a_toml, small_disk):
    # analyse writes ~400 kB (CSV, figure, HTML): more than the 64 kB disk; no estimate catches it before
    line = _one_line(_cli("analyse", paper_a_toml, "--out", small_disk / "a"), code=3)
    assert f"--out {small_disk / 'a'}: No space left on device" in line and "nothing was written" in line
    assert list(small_disk.iterdir()) == []


def test_full_disk_params_output_leaves_no_torn_file(small_disk):
    fd = os.open(small_disk / "fill", os.O_WRONLY | os.O_CREAT)  # fill the disk to the last block
    try:
        while True:
            os.write(fd, b"\0" * 1024)
    except OSError:
        pass
    finally:
        os.close(fd)
    line = _one_line(_cli("params", "paper_a", "-o", small_disk / "p.toml"), code=3)
    assert f"-o {small_disk / 'p.toml'}: No space left on device" in line
    assert sorted(p.name for p in small_disk.iterdir()) == ["fill"]
