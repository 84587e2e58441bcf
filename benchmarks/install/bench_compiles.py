"""CPU and wall time of each install-time compile of ``setup.py`` alone, in a fresh cache.

Each compile of ``setup.py``'s ``WARM`` table (and the ahead-of-time build, ``"ahead-of-time build"``) runs in
a process of its own, one after the other, with ``HEAVECOMP_CACHE_DIR`` a fresh temporary folder (so every
step compiles from nothing, as in a fresh clone); the child reports its own CPU (``time.process_time``) and
wall time; the load average is recorded beside each (the machine is shared).  ``--after NAME`` runs a step
in a cache that step ``NAME`` has filled first (e.g. the campaign batch once the nominal stepper is
compiled: what it adds).  Run from the repository root::

    nice -n 5 python benchmarks/install/bench_compiles.py [--steps NAME ...] [--after NAME] [--label L]
"""

from __future__ import annotations

import argparse
import ast
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
AOT = "ahead-of-time build"
CHILD = """
import json, time
w0, c0 = time.perf_counter(), time.process_time()
{code}
print(json.dumps(dict(wall_s=time.perf_counter() - w0, cpu_s=time.process_time() - c0)))
"""
AOT_CODE = ("import tempfile; from heavecomp.simulate._aot import build_cc; "
            "d = tempfile.mkdtemp(); cc = build_cc(d); cc.compile()")
#: the JIT nominal stepper alone (no step of setup.py's since the campaign batch compiles it: measure
#: ``--after "campaign batch" --steps "nominal stepper"`` to see what it adds then)
NOMINAL = "from heavecomp.simulate import stepper; stepper.install_steps()['nominal stepper']()"


def warm_table() -> dict:
    """setup.py's ``WARM`` {name: python source}, read from its source (setup.py is not imported: it
    runs ``setup()``)."""
    tree = ast.parse((ROOT / "setup.py").read_text())
    keep = [n for n in tree.body if isinstance(n, ast.Assign)
            and any(isinstance(t, ast.Name) and t.id in ("_LOG", "WARM") for t in n.targets)]
    ns: dict = {}
    exec(compile(ast.Module(body=keep, type_ignores=[]), "setup.py", "exec"), ns)
    return {"nominal stepper": NOMINAL, **ns["WARM"], AOT: AOT_CODE}


def run(name: str, table: dict, cache: str) -> dict:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "HEAVECOMP_CACHE_DIR": cache}
    env.pop("NUMBA_CACHE_DIR", None)
    load0 = os.getloadavg()[0]
    t0 = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", CHILD.format(code=table[name])], cwd=ROOT, env=env,
                         capture_output=True, text=True)
    if out.returncode:
        raise SystemExit(f"{name} failed:\n{out.stderr[-3000:]}")
    res = json.loads(out.stdout.strip().splitlines()[-1])
    return dict(step=name, process_wall_s=time.perf_counter() - t0, load_before=load0, load_after=os.getloadavg()[0],
                **res)


def main(argv=None):
    table = warm_table()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", nargs="*", help=f"steps to time (default every one: {', '.join(table)})")
    ap.add_argument("--after", default=None, help="fill a fresh cache with this step first (not timed)")
    ap.add_argument("--label", default="steps", help="key of this run in the JSON file")
    ap.add_argument("--out", default=str(Path(__file__).with_name("compiles.json")))
    a = ap.parse_args(argv)
    rows = []
    for name in a.steps or list(table):
        with tempfile.TemporaryDirectory(prefix="hc-compile-") as cache:
            if a.after:
                run(a.after, table, cache)
            r = run(name, table, cache)
        r["after"] = a.after
        rows.append(r)
        print(f"{name}{' after ' + a.after if a.after else ''}: CPU {r['cpu_s']:.1f} s, wall {r['wall_s']:.1f} s "
              f"(load {r['load_before']:.2f} -> {r['load_after']:.2f})", flush=True)
    path = Path(a.out)
    data = json.loads(path.read_text()) if path.exists() else {}
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    data[a.label] = dict(when=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), commit=commit,
                         cpus=os.cpu_count(), python=sys.version.split()[0], steps=rows)
    path.write_text(json.dumps(data, indent=2) + "\n")


if __name__ == "__main__":
    main()
