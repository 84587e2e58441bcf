"""Cold start: the first run of each command after ``pip install -e .`` against the second.

From a fresh virtual environment (no cache of the system's python can help):

1. copy the working tree's committed files (``git archive HEAD``) to ``WORK/src``;
2. ``python -m venv WORK/venv`` and ``WORK/venv/bin/pip install -v -e WORK/src`` (timed; the
   install-time compile of the steppers is timed by ``setup.py`` itself and read from its output);
3. in ``WORK/run``, each command twice, first (cold) then again (warm), wall and CPU time
   (user + sys of the process and its children):

   - the README's example diagnosis (``heavecomp diagnose heavecomp/data/examples/...``),
   - ``heavecomp simulate paper_a.toml --duration 600``,
   - ``heavecomp simulate paper_a.toml --duration 600 --controller linear-mpc``,
   - ``heavecomp campaign`` of a small campaign (2 sea states x 2 seeds x 3 regimes, 600 s, ``--workers 1``).

The goal (issue 21): first <= 1.5 x second for each.  Results go to ``results.json`` beside this
file.  Usage::

    python benchmarks/coldstart/bench_coldstart.py [--work /tmp/coldstart] [--keep]
    python benchmarks/coldstart/bench_coldstart.py --after-edit   # then: edit a report module, diagnose again

``--after-edit`` (with the venv of a previous run) appends a comment to the installed sources'
``heavecomp/report/figures.py`` and runs the example diagnosis once more: no compile notice and
the warm time expected (the kernels' cache keys do not cover report modules); it is added to
``results.json`` as ``after_report_edit``.

Takes ~10-20 minutes on 2 cores (the install compiles the steppers; the dependencies install
from the local package index).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import re
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]

CAMPAIGN = """
[campaign]
name = "coldstart"
base = "paper_a"
duration = 600.0
seeds = 2
regimes = ["none", "rotating_eq7", "stribeck"]
chunk_size = 4

[scatter]
hs = [0.5, 1.0]
tp = [10.0, 12.0]
probability = [[0.5, 0.0], [0.0, 0.5]]

[band]
tolerance = 20e3
exposure = 1800.0

[outputs]
deviation_max = 100e3
bins = 80
figures = false
"""

EXAMPLE = "{src}/heavecomp/data/examples/rig_log_example"
COMMANDS = {
    "diagnose (README example)": ["diagnose", EXAMPLE + ".csv.gz", "--params", EXAMPLE + ".toml", "--out", "{out}",
                                  "--columns", "t=Time,heave=MRU_heave,stroke=CMC_pos,pressure=P_main,wob=WOB",
                                  "--units", "t=ms,pressure=bar,wob=kN,stroke=mm"],
    "simulate --duration 600": ["simulate", "paper_a.toml", "--duration", "600", "--out", "{out}"],
    "simulate --duration 600 --controller linear-mpc": ["simulate", "paper_a.toml", "--duration", "600", "--out",
                                                        "{out}", "--controller", "linear-mpc"],
    "campaign (12 runs of 600 s, --workers 1)": ["campaign", "campaign.toml", "--out", "{out}", "--workers", "1"],
}


def numba_cache_counts(out: str) -> dict:
    """Functions numba compiled (and saved to its cache) and loaded from it in a run (NUMBA_DEBUG_CACHE=1)."""
    return {"numba_compiled": out.count("[cache] data saved to"), "numba_loaded": out.count("[cache] data loaded from")}


def run(cmd, cwd, env=None, log=None):
    """(wall s, cpu s of the children, stdout+stderr) of one command."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if log is not None:
        Path(log).write_text(p.stdout)
    if p.returncode != 0:
        raise SystemExit(f"{' '.join(map(str, cmd))} failed ({p.returncode}):\n{p.stdout[-3000:]}")
    return wall, cpu, p.stdout


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--work", default="/tmp/coldstart")
    ap.add_argument("--keep", action="store_true", help="reuse WORK/venv if it exists (no install timing)")
    ap.add_argument("--after-edit", action="store_true",
                    help="reuse WORK/venv: edit report/figures.py, run the example diagnosis once more")
    args = ap.parse_args()
    if args.after_edit:
        return after_edit(Path(args.work))
    work = Path(args.work)
    src, venv, rundir = work / "src", work / "venv", work / "run"
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "NUMBA_CACHE_DIR", "HEAVECOMP_CACHE_DIR")}
    result = {"machine": {"python": platform.python_version(), "cpus": os.cpu_count(),
                          "load_at_start": os.getloadavg()},
              "commit": subprocess.run(["git", "rev-parse", "HEAD"], cwd=REPO, capture_output=True,
                                       text=True).stdout.strip()}
    if not (args.keep and venv.exists()):
        shutil.rmtree(work / "src", ignore_errors=True)
        shutil.rmtree(venv, ignore_errors=True)
        src.mkdir(parents=True)
        archive = subprocess.run(["git", "archive", "HEAD"], cwd=REPO, capture_output=True, check=True).stdout
        subprocess.run(["tar", "-x", "-C", str(src)], input=archive, check=True)
        run([sys.executable, "-m", "venv", str(venv)], work, env)
        wall, cpu, out = run([str(venv / "bin" / "pip"), "install", "-v", "-e", str(src)], work, env,
                             log=work / "install.log")
        warm = re.search(r"numba's cache warmed in (\d+) s \((\d+) s of CPU\)", out)
        result["install"] = {"command": f"{venv}/bin/pip install -v -e {src}", "wall_s": round(wall, 1),
                             "cpu_s": round(cpu, 1),
                             "of_which_compile_steppers_s": int(warm.group(1)) if warm else None,
                             "of_which_compile_steppers_cpu_s": int(warm.group(2)) if warm else None,
                             "aot_built": "built the ahead-of-time stepper" in out}
    shutil.rmtree(rundir, ignore_errors=True)
    rundir.mkdir(parents=True)
    env = dict(env, NUMBA_DEBUG_CACHE="1")  # numba says what it loads and what it compiles (and saves)
    heavecomp = str(venv / "bin" / "heavecomp")
    run([heavecomp, "params", "paper_a", "-o", "paper_a.toml"], rundir, env)
    (rundir / "campaign.toml").write_text(CAMPAIGN)
    rows = {}
    for name, argv in COMMANDS.items():
        times = []
        for k in ("first", "second"):
            cmd = [heavecomp] + [a.format(src=src, out=f"out_{len(rows)}_{k}") for a in argv]
            wall, cpu, out = run(cmd, rundir, env, log=rundir / f"log_{len(rows)}_{k}.txt")
            compiled = [ln for ln in out.splitlines() if "compiling" in ln]
            times.append({"wall_s": round(wall, 2), "cpu_s": round(cpu, 2), "compile_notices": compiled,
                          **numba_cache_counts(out)})
            print(f"{name:50s} {k:6s} wall {wall:7.2f} s  cpu {cpu:7.2f} s  {len(compiled)} compile notice(s)  "
                  f"{times[-1]['numba_compiled']} compiled by numba", flush=True)
        first, second = times
        rows[name] = {"command": "heavecomp " + " ".join(argv), "first": first, "second": second,
                      "ratio_wall": round(first["wall_s"] / second["wall_s"], 2),
                      "ratio_cpu": round(first["cpu_s"] / second["cpu_s"], 2)}
    result["commands"] = rows
    result["goal"] = "first <= 1.5 x second (wall) for each command"
    result["met"] = all(r["ratio_wall"] <= 1.5 for r in rows.values())
    result["machine"]["load_at_end"] = os.getloadavg()
    (HERE / "results.json").write_text(json.dumps(result, indent=1) + "\n")
    print(json.dumps(result, indent=1))


def after_edit(work: Path) -> None:
    src, venv, rundir = work / "src", work / "venv", work / "run"
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "NUMBA_CACHE_DIR", "HEAVECOMP_CACHE_DIR")}
    env["NUMBA_DEBUG_CACHE"] = "1"
    fig = src / "heavecomp" / "report" / "figures.py"
    fig.write_text(fig.read_text() + "\n# an edit of a report module (benchmarks/coldstart --after-edit)\n")
    name = "diagnose (README example)"
    argv = [str(venv / "bin" / "heavecomp")] + [a.format(src=src, out="out_after_edit") for a in COMMANDS[name]]
    wall, cpu, out = run(argv, rundir, env, log=rundir / "log_after_edit.txt")
    notices = [ln for ln in out.splitlines() if "compiling" in ln]
    counts = numba_cache_counts(out)
    print(f"{name} after editing report/figures.py: wall {wall:.2f} s, cpu {cpu:.2f} s, {len(notices)} compile "
          f"notice(s), {counts['numba_compiled']} compiled by numba")
    path = HERE / "results.json"
    result = json.loads(path.read_text())
    result["after_report_edit"] = {"edit": "a comment appended to heavecomp/report/figures.py", "command": name,
                                   "wall_s": round(wall, 2), "cpu_s": round(cpu, 2), "compile_notices": notices,
                                   **counts,
                                   "load": os.getloadavg()}
    path.write_text(json.dumps(result, indent=1) + "\n")


if __name__ == "__main__":
    main()
