"""Run time of the stepper of this tree against another tree's (e.g. ``git archive`` of main): did a change
that cuts compile work (``compiles.json``) cost run time?

Each tree runs in processes of its own (its own package, its own warm numba cache: ``--cache DIR`` per tree,
default the tree's ``heavecomp/_numba_cache``), the trees alternating ``--rounds`` times, each process timing
``--repeat`` 600 s runs (:func:`heavecomp.diagnosis.stepper.run_fx`, the same heave and step) of
(a) the calibrated file's effects (``tests/data/calibrated_hook_terms.toml``) on the superset stepper and
(e) the paper-A Stribeck plant on the plain JIT stepper (stick-slip: the event paths run); the median CPU
time (``time.process_time``) per variant and tree, and their ratio this / other.  Run from the repository
root::

    python benchmarks/install/bench_kernel_runtime.py --other /tmp/main [--other-cache DIR] [--rounds 2 --repeat 10]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CHILD = """
import json, time
import numpy as np
from heavecomp.diagnosis.stepper import replay_dt, run_fx
from heavecomp.effects.compose import composition, library_composition
from heavecomp.effects.spec import load, plant_effects
from heavecomp.params import paper_a
from heavecomp.plants.cmc import plant_vectors
from heavecomp.simulate import excitation, stepper
p = load({case!r})
fx = plant_effects(p)
h = replay_dt(p, 50.0)
n = int(np.ceil(600.0 / h - 1e-9))
hs = excitation.make_heave(p.heave, n * h, 0.5 * h, p.base_dir)
pa = paper_a("stribeck")
variants = dict(a_file_effects_on_superset=(plant_vectors(p), library_composition(), fx),
                e_paper_a_stribeck_plain=(plant_vectors(pa), composition(()), []))
for name, (plant, comp, eff) in variants.items():
    stepper.kernel_for(comp)
cpu = {{k: [] for k in variants}}
check = {{}}
for _ in range({repeat}):
    for name, (plant, comp, eff) in variants.items():
        c0 = time.process_time()
        out = run_fx(plant, comp, comp.ep(eff), hs, h, n, 1)
        cpu[name].append(time.process_time() - c0)
        check[name] = float(np.sum(out))
print(json.dumps(dict(cpu=cpu, check=check)))
"""


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--other", required=True, help="root of the other tree")
    ap.add_argument("--cache", default=None, help="HEAVECOMP_CACHE_DIR of this tree (default its own)")
    ap.add_argument("--other-cache", default=None, help="HEAVECOMP_CACHE_DIR of the other tree (default its own)")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--repeat", type=int, default=10)
    ap.add_argument("--out", default=str(Path(__file__).with_name("kernel_runtime.json")))
    ap.add_argument("--label", default="landed", help="key of this run in the JSON file")
    a = ap.parse_args(argv)
    trees = {"this": (ROOT, a.cache), "other": (Path(a.other).resolve(), a.other_cache)}
    cpu = {t: {} for t in trees}
    check, loads = {}, []
    for _ in range(a.rounds):
        for t, (root, cache) in trees.items():
            env = {**os.environ, "PYTHONPATH": str(root), "HEAVECOMP_JIT": "1"}
            if cache:
                env["HEAVECOMP_CACHE_DIR"] = cache
            loads.append(os.getloadavg()[0])
            case = str(root / "tests" / "data" / "calibrated_hook_terms.toml")
            out = subprocess.run([sys.executable, "-c", CHILD.format(case=case, repeat=a.repeat)], cwd=root, env=env,
                                 capture_output=True, text=True)
            if out.returncode:
                raise SystemExit(out.stderr[-3000:])
            r = json.loads(out.stdout.strip().splitlines()[-1])
            for k, v in r["cpu"].items():
                cpu[t].setdefault(k, []).extend(v)
            check[t] = r["check"]
    med = {t: {k: statistics.median(v) for k, v in d.items()} for t, d in cpu.items()}
    ratio = {k: med["this"][k] / med["other"][k] for k in med["this"]}
    res = dict(when=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), other=str(trees["other"][0]),
               median_cpu_s=med, ratio_this_over_other=ratio, same_output=check["this"] == check["other"],
               checksums=check, loadavg_1min=loads, cpu_s=cpu)
    for k in ratio:
        print(f"{k}: this {med['this'][k]:.3f} s, other {med['other'][k]:.3f} s CPU median, ratio {ratio[k]:.3f}")
    print(f"same output: {res['same_output']}; load {min(loads):.2f}-{max(loads):.2f}")
    path = Path(a.out)
    data = json.loads(path.read_text()) if path.exists() else {}
    data[a.label] = res
    path.write_text(json.dumps(data, indent=2) + "\n")


if __name__ == "__main__":
    main()
