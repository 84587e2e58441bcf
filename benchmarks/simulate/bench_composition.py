"""The superset composition (issue 32): its run-time cost against the fused kernels, and the first use of a
calibrated file's effect mix against the second.

Two measurements, written to ``composition.json`` beside this script (each with ``os.getloadavg()``):

``runtime`` (one process): CPU time (``time.process_time``) of a 600 s run of the stepper
(:func:`heavecomp.diagnosis.stepper.run_fx`, the same heave and step for every variant) of

- (a) ``pressure_friction + line_term + string_term`` (``tests/data/calibrated_hook_terms.toml``) on the
  superset kernel (every other effect off), against (b) the composition of exactly those classes (the
  fused kernel each such file compiled before);
- (c) a library-only set (``pressure_friction + flow_loss + string_damping``) on the superset, against
  (d) the library-only composition (the library stepper before the superset);
- (e) the plain stepper (no effect) for scale.

Repetitions alternate the variants (a change of load hits all alike); the median CPU time is reported
and the ratios a/b and c/d.  The kernels are compiled (or loaded) first, outside the timing.

``first`` (fresh processes): with ``HEAVECOMP_CACHE_DIR`` a fresh folder, the install-time compiles
(``stepper.install_steps()``, as ``setup.py``) and then ``python -m heavecomp simulate CASE --duration 60``
twice, each a fresh process; wall and CPU (user + sys of the child) of each, their ratio.

Run from the repository root::

    python benchmarks/simulate/bench_composition.py runtime [--repeat 3] [--duration 600]
    python benchmarks/simulate/bench_composition.py first
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CASE = ROOT / "tests" / "data" / "calibrated_hook_terms.toml"
OUT = Path(__file__).with_name("composition.json")
LIBRARY_ONLY = (("pressure_friction", {"extra_pressure_coefficient": 2e-3}), ("flow_loss", {"resistance": 3e5}),
                ("string_damping", {"damping": 5e5}))


def _save(key: str, value: dict) -> None:
    data = json.loads(OUT.read_text()) if OUT.exists() else {}
    data[key] = value
    OUT.write_text(json.dumps(data, indent=2) + "\n")


def runtime(duration: float, repeat: int) -> dict:
    sys.path.insert(0, str(ROOT))
    import numpy as np

    from heavecomp.diagnosis.stepper import replay_dt, run_fx
    from heavecomp.effects.compose import composition, hook_order, library_composition
    from heavecomp.effects.registry import library, resolve
    from heavecomp.effects.spec import load, plant_effects
    from heavecomp.plants.cmc import plant_vectors
    from heavecomp.simulate import excitation, stepper

    p = load(CASE)
    fx = plant_effects(p)
    lib_fx = resolve(LIBRARY_ONLY)
    h = replay_dt(p, 50.0)
    n = int(np.ceil(duration / h - 1e-9))
    hs = excitation.make_heave(p.heave, n * h, 0.5 * h, p.base_dir)
    plant = plant_vectors(p)
    superset = library_composition()
    library_only = composition(tuple(c for c in library().values() if c.kind == "plant"))  # before the superset
    variants = {
        "a_file_effects_on_superset": (superset, fx),
        "b_file_effects_own_composition": (composition(hook_order(type(e) for e in fx)), fx),
        "c_library_effects_on_superset": (superset, lib_fx),
        "d_library_effects_on_library_only": (library_only, lib_fx),
        "e_no_effect_plain_stepper": (composition(()), []),
    }
    compile_s = {}
    for name, (comp, _) in variants.items():  # compile or load, outside the timing
        c0, w0 = time.process_time(), time.perf_counter()
        stepper.kernel_for(comp)
        compile_s[name] = dict(cpu_s=time.process_time() - c0, wall_s=time.perf_counter() - w0)
        print(f"{name}: kernel ready ({compile_s[name]['cpu_s']:.1f} s CPU)", flush=True)
    cpu = {k: [] for k in variants}
    wall = {k: [] for k in variants}
    loads = []
    ref = {}
    for _ in range(repeat):
        for name, (comp, eff) in variants.items():
            loads.append(os.getloadavg()[0])
            c0, w0 = time.process_time(), time.perf_counter()
            out = run_fx(plant, comp, comp.ep(eff), hs, h, n, 1)
            cpu[name].append(time.process_time() - c0)
            wall[name].append(time.perf_counter() - w0)
            ref[name] = out
    # the superset and the exact composition integrate the same trajectory
    same_ab = float(np.max(np.abs(ref["a_file_effects_on_superset"] - ref["b_file_effects_own_composition"])))
    same_cd = float(np.max(np.abs(ref["c_library_effects_on_superset"] - ref["d_library_effects_on_library_only"])))
    med = {k: statistics.median(v) for k, v in cpu.items()}
    res = dict(when=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), case=str(CASE.relative_to(ROOT)),
               duration_s=duration, step_s=h, n_steps=n, repeat=repeat, cpu_s=cpu, wall_s=wall,
               median_cpu_s=med, loadavg_1min_each_run=loads, kernel_ready=compile_s,
               ratio_superset_vs_own_composition=med["a_file_effects_on_superset"] / med["b_file_effects_own_composition"],
               ratio_superset_vs_library_only=med["c_library_effects_on_superset"] / med["d_library_effects_on_library_only"],
               ratio_superset_vs_plain=med["a_file_effects_on_superset"] / med["e_no_effect_plain_stepper"],
               max_abs_diff_a_b=same_ab, max_abs_diff_c_d=same_cd)
    for k, v in med.items():
        print(f"{k}: median CPU {v:.3f} s ({n} steps)")
    print(f"superset / own composition: {res['ratio_superset_vs_own_composition']:.3f}; superset / library-only: "
          f"{res['ratio_superset_vs_library_only']:.3f}; load {min(loads):.2f}-{max(loads):.2f}")
    return res


def _timed(cmd, env) -> dict:
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    load = os.getloadavg()
    t0 = time.perf_counter()
    out = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if out.returncode:
        raise SystemExit(f"{' '.join(map(str, cmd))} failed ({out.returncode}):\n{out.stderr}")
    return dict(wall_s=wall, cpu_s=(r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime), loadavg_before=load,
                loadavg_after=os.getloadavg(), stderr=out.stderr.strip().splitlines()[-3:])


def first() -> dict:
    with tempfile.TemporaryDirectory(prefix="hc-first-") as cache, tempfile.TemporaryDirectory() as out:
        env = {**os.environ, "PYTHONPATH": str(ROOT), "HEAVECOMP_CACHE_DIR": cache}
        env.pop("NUMBA_CACHE_DIR", None)
        install = _timed([sys.executable, "-c", "from heavecomp.simulate import stepper\n"
                          "for step in stepper.install_steps().values(): step()"], env)
        print(f"install-time compiles: wall {install['wall_s']:.1f} s, CPU {install['cpu_s']:.1f} s", flush=True)
        runs = []
        for i in range(2):
            runs.append(_timed([sys.executable, "-m", "heavecomp", "simulate", str(CASE), "--duration", "60",
                                "--out", str(Path(out) / f"run{i}")], env))
            print(f"simulate #{i + 1}: wall {runs[-1]['wall_s']:.2f} s, CPU {runs[-1]['cpu_s']:.2f} s "
                  f"(load {runs[-1]['loadavg_before'][0]:.2f})", flush=True)
    res = dict(when=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), case=str(CASE.relative_to(ROOT)),
               command=f"python -m heavecomp simulate {CASE.relative_to(ROOT)} --duration 60 --out DIR",
               install_compiles=install, first=runs[0], second=runs[1],
               ratio_wall_first_second=runs[0]["wall_s"] / runs[1]["wall_s"],
               ratio_cpu_first_second=runs[0]["cpu_s"] / runs[1]["cpu_s"])
    print(f"first / second: wall {res['ratio_wall_first_second']:.2f}, CPU {res['ratio_cpu_first_second']:.2f}")
    return res


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("part", choices=("runtime", "first"))
    ap.add_argument("--duration", type=float, default=600.0, help="simulated time of the runtime part [s]")
    ap.add_argument("--repeat", type=int, default=3, help="repetitions of the runtime part")
    ap.add_argument("--label", default="", help="suffix of the JSON key (e.g. _before)")
    a = ap.parse_args(argv)
    if a.part == "runtime":
        _save("runtime" + a.label, runtime(a.duration, a.repeat))
    else:
        _save("first_and_second_simulate" + a.label, first())


if __name__ == "__main__":
    main()
