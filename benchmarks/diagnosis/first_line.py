"""When the README's example diagnosis prints its first line, and when it ends (issue 32: the first output line
of a diagnosis within 2 s).  The command runs as a user runs it, in a fresh process (the interpreter, the imports
and numba's cache loads included); its output is read line by line as it comes.  Usage::

    python benchmarks/diagnosis/first_line.py [--runs 3]

Prints, per run, the wall time to the first line and to the end, the child's CPU time and the 1-minute load.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
import resource
import subprocess
import sys
import tempfile
import time

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "heavecomp" / "data" / "examples"


def one(out: Path) -> dict:
    cmd = [sys.executable, "-m", "heavecomp", "diagnose", str(EXAMPLE / "rig_log_example.csv.gz"), "--params",
           str(EXAMPLE / "rig_log_example.toml"), "--out", str(out), "--columns",
           "t=Time,heave=MRU_heave,stroke=CMC_pos,pressure=P_main,wob=WOB", "--units",
           "t=ms,pressure=bar,wob=kN,stroke=mm"]
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, bufsize=1, cwd=ROOT)
    first, line = None, ""
    for ln in proc.stdout:
        if first is None:
            first, line = time.perf_counter() - t0, ln.strip()
    proc.wait()
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return {"first_line_s": first, "first_line": line, "wall_s": time.perf_counter() - t0, "exit": proc.returncode,
            "cpu_s": r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime, "load_1min": os.getloadavg()[0]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=3)
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(args.runs):
            r = one(Path(tmp) / f"diag{i}")
            print(f"run {i + 1}: first line after {r['first_line_s']:.2f} s ({r['first_line'][:60]!r}), done in "
                  f"{r['wall_s']:.1f} s, CPU {r['cpu_s']:.1f} s, exit {r['exit']}, load {r['load_1min']:.2f}")
            if r["exit"] != 0:
                return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
