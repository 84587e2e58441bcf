"""Issue 14.2: killing ``heavecomp simulate`` leaves no process behind (the forked figure child dies with it)."""

import os
import signal
import subprocess
import sys
import time

import pytest

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc to find the child (Linux)")


def _children(pid: int) -> list[int]:
    kids = []
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            with open(f"/proc/{d}/stat") as fh:
                stat = fh.read()
        except OSError:
            continue
        # field 4 (after the parenthesised command name) is the parent pid
        if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
            kids.append(int(d))
    return kids


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"  # a zombie is dead
    except OSError:
        return False


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGKILL])
def test_killed_simulate_leaves_no_child(paper_a_toml, tmp_path, sig):
    env = {k: v for k, v in os.environ.items() if k != "HEAVECOMP_NO_FORK"}
    # a run long enough (a day of sea, inside the run-size budget) to still be simulating when killed
    proc = subprocess.Popen([sys.executable, "-m", "heavecomp", "simulate", str(paper_a_toml), "--duration", "86400",
                             "--out", str(tmp_path / "run"), "--quiet"], env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    kids = []
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not kids and proc.poll() is None:
            kids = _children(proc.pid)
            time.sleep(0.05)
        assert kids, "simulate forked no figure process (or finished before it could be killed)"
        time.sleep(0.5)  # let the child get into its wait for the job
        assert proc.poll() is None, "simulate finished before it could be killed"
        proc.send_signal(sig)
        proc.wait(timeout=30)
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline and any(_alive(k) for k in kids):
            time.sleep(0.05)
        left = [k for k in kids if _alive(k)]
        assert not left, f"processes {left} outlived the killed simulate"
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        for k in kids:
            if _alive(k):
                os.kill(k, signal.SIGKILL)
