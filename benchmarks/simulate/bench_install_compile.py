"""CPU and wall time of each install-time compile (``stepper.install_steps()``), in a fresh cache.

Each step runs in a process of its own (as ``setup.py`` runs them), with ``HEAVECOMP_CACHE_DIR`` a fresh
temporary folder, so every step compiles; the child reports its own CPU time (``time.process_time``) and
wall time, and the load average is recorded beside each (the machine is shared).  Issue 32: the library
effects stepper became the superset (the library's plant effects plus the open search's hook terms); this
says what the bigger stepper costs to compile at install.

Run from the repository root (the package of this tree is imported)::

    python benchmarks/simulate/bench_install_compile.py [--out FILE.json] [--label before]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CHILD = """
import json, os, time
w0, c0 = time.perf_counter(), time.process_time()
from heavecomp.simulate import stepper
steps = stepper.install_steps()
w1, c1 = time.perf_counter(), time.process_time()
steps[{name!r}]()
w2, c2 = time.perf_counter(), time.process_time()
print(json.dumps(dict(import_wall_s=w1 - w0, import_cpu_s=c1 - c0, compile_wall_s=w2 - w1, compile_cpu_s=c2 - c1)))
"""


def names() -> list:
    out = subprocess.run([sys.executable, "-c", "from heavecomp.simulate import stepper; "
                          "print('\\n'.join(stepper.install_steps()))"], cwd=ROOT, capture_output=True, text=True,
                         check=True, env={**os.environ, "PYTHONPATH": str(ROOT)})
    return out.stdout.split("\n")[:-1] if out.stdout.endswith("\n") else out.stdout.split("\n")


def run(name: str) -> dict:
    with tempfile.TemporaryDirectory(prefix="hc-install-") as cache:
        env = {**os.environ, "PYTHONPATH": str(ROOT), "HEAVECOMP_CACHE_DIR": cache}
        env.pop("NUMBA_CACHE_DIR", None)
        load0 = os.getloadavg()
        t0 = time.perf_counter()
        out = subprocess.run([sys.executable, "-c", CHILD.format(name=name)], cwd=ROOT, env=env, capture_output=True,
                             text=True, check=True)
        wall = time.perf_counter() - t0
        res = json.loads(out.stdout.strip().splitlines()[-1])
        return dict(step=name, process_wall_s=wall, loadavg_before=load0, loadavg_after=os.getloadavg(), **res)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(Path(__file__).with_name("install_compile.json")))
    ap.add_argument("--label", default="after", help="key of this run in the JSON file (before / after)")
    ap.add_argument("--steps", nargs="*", help="the install steps to time (default: every one)")
    a = ap.parse_args(argv)
    rows = []
    for name in a.steps or names():
        r = run(name)
        rows.append(r)
        print(f"{name}: compile CPU {r['compile_cpu_s']:.1f} s, wall {r['compile_wall_s']:.1f} s "
              f"(load {r['loadavg_before'][0]:.2f} -> {r['loadavg_after'][0]:.2f})", flush=True)
    path = Path(a.out)
    data = json.loads(path.read_text()) if path.exists() else {}
    data[a.label] = dict(when=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), cpus=os.cpu_count(),
                         python=sys.version.split()[0], steps=rows)
    path.write_text(json.dumps(data, indent=2) + "\n")


if __name__ == "__main__":
    main()
