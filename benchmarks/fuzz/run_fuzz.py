"""Fuzz run of issue 21's "Done when": parameter files and logs through the CLI, in subprocesses.

Every input is generated freshly from ``--seed`` (not the reproducers alone) and run as a user would:
``heavecomp params FILE`` (and ``heavecomp simulate FILE --duration 10`` for a sample of the accepted
ones), ``heavecomp diagnose LOG --params P --candidates sensor_gain`` for the logs, each in its own
process under a wall-clock limit.  Each outcome is classified:

- ``ok``: exit 0 with a sane result (an accepted file; a clean log's verdict not a confident named
  effect and without a data-quality warning; a corrupted log read with confidence ``low`` and a
  warning naming the corrupted column; a torn last row dropped with a warning naming it);
- ``refused``: exit 2 with one line (for a corrupted log: naming the corrupted column);
- bad: ``traceback``, ``hang``, ``multi_line`` (exit 2 with more than one line), ``exit_<n>`` (any
  other exit code), ``accepted_bad`` (a parameter file built to be wrong -- a unit slip by 1000, a sea
  beyond the stroke, a broken ``heave.path`` -- accepted), ``confident_on_corrupted``,
  ``confident_wrong`` (a clean log given a named effect with medium/high confidence),
  ``false_alarm`` (a clean log refused or warned about), ``wrong_column`` (a refusal or warning that
  does not name the corrupted column), ``not_finite`` (simulate's metrics not finite).

Usage (from the repository root; PYTHONPATH pointing at it)::

    python benchmarks/fuzz/run_fuzz.py --params 500 --simulate 40 --logs 0 --seed 21 --out benchmarks/fuzz/results_params.json
    python benchmarks/fuzz/run_fuzz.py --params 0 --logs 84 --seed 21 --out benchmarks/fuzz/results_logs.json

``--quick`` is the small version the test suite runs (``tests/test_fuzz_cli.py``).
"""

from __future__ import annotations

import argparse
import concurrent.futures as cf
import json
import math
import os
import random
import re
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

import numpy as np

PARAMS_TIMEOUT = 60.0  #: s for ``heavecomp params`` (a hang beyond it)
SIM_TIMEOUT = 300.0  #: s for a 10 s ``simulate``
DIAG_TIMEOUT = 900.0  #: s for a 60-120 s log's ``diagnose`` (2 shared cores, several at once)
NOISE = {"heave": 5e-3, "stroke": 1e-3, "pressure": 5e3, "wob": 500.0}  #: sensor noise (the closed loop's defaults)
BAD = ("traceback", "hang", "multi_line", "accepted_bad", "confident_on_corrupted", "confident_wrong",
       "false_alarm", "wrong_column", "not_finite")


def cli(args, timeout, cwd=None):
    """(exit code or 'hang', stdout, stderr, wall s) of ``python -m heavecomp ARGS``."""
    t0 = time.perf_counter()
    try:
        r = subprocess.run([sys.executable, "-m", "heavecomp", *args], capture_output=True, text=True,
                           timeout=timeout, cwd=cwd, env=dict(os.environ, PYTHONWARNINGS="default"))
        return r.returncode, r.stdout, r.stderr, time.perf_counter() - t0
    except subprocess.TimeoutExpired:
        return "hang", "", "", time.perf_counter() - t0


def base_class(rc, err):
    """traceback / hang / multi_line / refused / exit_<n> / None (exit 0)."""
    if rc == "hang":
        return "hang"
    if "Traceback" in err:
        return "traceback"
    if rc == 2:
        return "refused" if len([ln for ln in err.splitlines() if ln.strip()]) == 1 else "multi_line"
    return None if rc == 0 else f"exit_{rc}"


# ------------------------------------------------------------------------------------------ parameter files


def base_texts():
    from heavecomp.params import FRICTION_MODELS, SETS, dumps

    out = []
    for factory in SETS.values():
        for model in FRICTION_MODELS:
            out.append(dumps(factory(model)))
        out.append(dumps(factory("rotating_eq7")) + "\n[active]\nu_max = 60000.0\nrate_max = 300000.0\ncontrol_rate = 20.0\n")
        out.append(dumps(factory("stribeck")).replace('kind = "sine"\namplitude = 1.0\nperiod = 12.0\n',
                                                      'kind = "jonswap"\nhs = 2.0\ntp = 12.0\nseed = 5\n'))
    return out


ODD = ["nan", "inf", "-inf", "0", "-0.0", "-1.0", "1e300", "1e-300", "5e-324", "1e9", "4294967296", '"80 t"', '""',
       "true", "[1.0, 2.0]", "{ a = 1 }", "1979-05-27", "0x10", "1_000", "+5.0", "'raw'", "1" + "0" * 400,
       "1" + "0" * 5000, "0o17", "0b101", "1e400"]


def _sub_heave(text, block):
    return re.sub(r"\[heave\]\n(?:[^\[]*\n)?(?=\[)", "[heave]\n" + block + "\n", text, count=1)


def mutate_params(rng: random.Random, bases, tmp: Path, i: int):
    """(bytes, description, must_refuse) of one fuzzed parameter file."""
    text = rng.choice(bases)
    lines = text.splitlines()
    kind = rng.choice(["value", "value", "magnitude", "key", "table", "syntax", "deep", "heave_path", "sea",
                       "slip", "slip", "encoding"])
    kv = [j for j, ln in enumerate(lines) if re.match(r"^\w+ = ", ln)]
    must = False
    desc = kind
    if kind == "value":
        j = rng.choice(kv)
        k = lines[j].split(" = ")[0]
        new = rng.choice(ODD + [repr(rng.uniform(-1e6, 1e6)), repr(10 ** rng.uniform(-320, 308))])
        lines[j] = f"{k} = {new}"
        desc = f"value {k} = {new[:20]}"
    elif kind == "magnitude":
        j = rng.choice(kv)
        k, _, v = lines[j].partition(" = ")
        try:
            x = float(v)
        except ValueError:
            x = 1.0
        f = rng.choice([-1.0, 0.0, 1e6, 1e-6, 10.0, 0.1, 1e-300, 1e300])
        lines[j] = f"{k} = {x * f!r}"
        desc = f"magnitude {k} x {f:g}"
    elif kind == "key":
        j = rng.choice(kv)
        k, _, v = lines[j].partition(" = ")
        how = rng.choice(["delete", "misspell", "unknown", "duplicate", "case"])
        lines[j] = {"delete": "# deleted", "misspell": f"{k[:-1]} = {v}", "unknown": f"{k}_x = {v}",
                    "duplicate": f"{lines[j]}\n{lines[j]}", "case": f"{k.upper()} = {v}"}[how]
        desc = f"key {how} {k}"
    elif kind == "table":
        heads = [j for j, ln in enumerate(lines) if ln.startswith("[")]
        j = rng.choice(heads)
        how = rng.choice(["rename", "delete", "duplicate", "array"])
        name = lines[j].strip("[]")
        lines[j] = {"rename": f"[{name}s]", "delete": "", "duplicate": f"[{name}]\n[{name}]",
                    "array": f"[[{name}]]"}[how]
        desc = f"table {how} {name}"
    elif kind == "syntax":
        body = "\n".join(lines)
        k = rng.randrange(len(body))
        how = rng.choice(["truncate", "garbage", "quote", "bracket", "decimal_comma"])
        body = {"truncate": body[:k], "garbage": body[:k] + rng.choice("=[]{}\"'\\#\x00\x7f,") + body[k:],
                "quote": body[:k] + '"' + body[k:], "bracket": body[:k] + "[" + body[k:],
                "decimal_comma": re.sub(r"(\d)\.(\d)", r"\1,\2", body, count=1)}[how]
        lines = body.splitlines()
        desc = f"syntax {how}"
    elif kind == "deep":
        n = rng.choice([50, 300, 500, 1000, 3000])
        nest = rng.choice(["inline", "array"])
        deep = ("{a = " * n + "1" + "}" * n) if nest == "inline" else ("[" * n + "1" + "]" * n)
        lines.insert(0, f"deep = {deep}")
        desc = f"deep {nest} {n}"
    elif kind == "heave_path":
        real = tmp / f"heave_{i}.csv"
        t = np.arange(0.0, 60.0, 0.1)
        real.write_text("t,heave\n" + "\n".join(f"{a:.2f},{0.8 * math.sin(a / 1.6):.6f}" for a in t) + "\n")
        (tmp / f"empty_{i}.csv").write_text("")
        path, must = rng.choice([("", True), ("/dev/null", True), (str(tmp), True), ("no_such_heave.csv", True),
                                 (f"empty_{i}.csv", True), (real.name, False), (str(real), False)])
        text2 = _sub_heave("\n".join(lines), f'kind = "file"\npath = "{path}"')
        lines = text2.splitlines()
        desc = f"heave.path = {path!r}"
    elif kind == "sea":
        if rng.random() < 0.5:
            a = rng.uniform(4.0, 15.0)
            block, must = f'kind = "sine"\namplitude = {a!r}\nperiod = 12.0', True
            desc = f"sine amplitude {a:.2f} m"
        else:
            hs = rng.choice([rng.uniform(4.2, 30.0), rng.uniform(0.2, 4.0)])
            block, must = f'kind = "jonswap"\nhs = {hs!r}\ntp = 11.0\nseed = 3', hs * 1.86 > 7.62
            desc = f"jonswap hs {hs:.2f} m"
        lines = _sub_heave("\n".join(lines), block).splitlines()
    elif kind == "slip":
        j = rng.choice([j for j in kv if re.match(r"^\w+ = -?[\d.]+(e[-+]?\d+)?$", lines[j])
                        and not lines[j].startswith(("seed", "ramp"))] or kv)
        k, _, v = lines[j].partition(" = ")
        f = rng.choice([1e3, 1e-3])
        try:
            x = float(v)
        except ValueError:
            x = 0.0
        lines[j] = f"{k} = {x * f!r}"
        must = x != 0.0 and k not in ("polytropic_index",)  # scripts/unit_slips.py: every slip of a shipped set is refused
        desc = f"slip {k} x {f:g}"
    body = "\n".join(lines) + "\n"
    if kind == "encoding":
        how = rng.choice(["bom", "latin1", "utf16", "nul"])
        raw = {"bom": b"\xef\xbb\xbf" + body.encode(), "latin1": ("# r\xe9glage\n" + body).encode("latin-1"),
               "utf16": body.encode("utf-16"), "nul": body.encode()[:50] + b"\x00" + body.encode()[50:]}[how]
        return raw, f"encoding {how}", False
    return body.encode("utf-8"), desc, must


def run_param_file(job):
    i, raw, desc, must, tmp, simulate = job
    f = Path(tmp) / f"p{i:04d}.toml"
    f.write_bytes(raw)
    rc, out, err, wall = cli(["params", str(f)], PARAMS_TIMEOUT)
    cls = base_class(rc, err)
    if cls is None:
        cls = "accepted_bad" if must else "ok"
    row = {"i": i, "what": desc, "must_refuse": must, "class": cls, "wall_s": round(wall, 2),
           "stderr": err.strip()[-300:]}
    if simulate and cls == "ok":
        o = Path(tmp) / f"sim{i:04d}"
        rc, out, err, wall = cli(["simulate", str(f), "--duration", "10", "--out", str(o), "-q"], SIM_TIMEOUT)
        s = base_class(rc, err)
        if s is None:
            try:
                m = json.loads((o / "metrics.json").read_text())
                finite = all(math.isfinite(v) for v in _numbers(m))
            except (OSError, ValueError):
                finite = False
            s = "ok" if finite else "not_finite"
        row["simulate"] = {"class": s, "wall_s": round(wall, 2), "stderr": err.strip()[-300:]}
    return row


def _numbers(x):
    if isinstance(x, bool):
        return
    if isinstance(x, (int, float)):
        yield float(x)
    elif isinstance(x, dict):
        for v in x.values():
            yield from _numbers(v)
    elif isinstance(x, list):
        for v in x:
            yield from _numbers(v)


# ------------------------------------------------------------------------------------------ logs


def base_runs(rng: np.random.Generator, n_bases, duration, tmp: Path):
    """Clean simulated runs (paper A under JONSWAP seas of different H_s, T_p, seeds) and their parameter files."""
    from heavecomp.params import dumps, paper_a
    from heavecomp.simulate import simulate

    out = []
    for b in range(n_bases):
        hs, tp = float(rng.uniform(1.5, 3.0)), float(rng.uniform(8.0, 13.0))
        p = paper_a().replace(heave={"kind": "jonswap", "hs": hs, "tp": tp, "seed": int(rng.integers(2 ** 31)),
                                     "ramp": 2 * tp, "amplitude": None, "period": None})
        f = tmp / f"base{b}.toml"
        f.write_text(dumps(p))
        r = simulate(p, duration, rate=20.0)
        cols = {c: np.asarray(r[c], dtype=float) for c in ("heave", "stroke", "pressure", "wob")}
        out.append((p, f, np.asarray(r["t"], dtype=float), cols, {"hs": hs, "tp": tp}))
    return out


def write_log(path, t, cols, *, torn_text=False):
    names = ["t", "heave", "stroke", "pressure", "wob"]
    data = np.column_stack([t] + [cols[c] for c in names[1:]])
    lines = [",".join(names)] + [",".join("1e400" if v == math.inf else "-1e400" if v == -math.inf else f"{v:.10g}"
                                          for v in row) for row in data]
    text = "\n".join(lines) + ("" if torn_text else "\n")
    path.write_text(text)
    return path


def make_logs(seed, n_logs, duration, tmp: Path):
    """(path, params file, description) of ``n_logs`` logs: about one in seven clean, the rest one
    corruption class each (heavecomp.benchmark.corruption), classes in turn."""
    from heavecomp.benchmark import corruption as K

    rng = np.random.default_rng(seed)
    bases = base_runs(rng, 4, duration, tmp)
    logs = []
    kinds = ["clean"] + list(K.CLASSES)
    for i in range(n_logs):
        kind = kinds[i % len(kinds)]
        p, pf, t, cols, sea = bases[i % len(bases)]
        noisy = {c: y + NOISE[c] * rng.normal(size=y.size) for c, y in cols.items()}
        if kind == "clean":
            t2, c2, d = t, noisy, {"class": "clean", "column": None, "expect": "clean"}
        else:
            t2, c2, d = K.corrupt(kind, t, noisy, rng, p)
        d = {("corruption" if k == "class" else k): v for k, v in d.items()
             if isinstance(v, (str, int, float, type(None)))} | {"sea": sea}
        f = write_log(tmp / f"log{i:03d}.csv", t2, c2, torn_text=kind == "torn")
        logs.append((i, str(f), str(pf), d))
    return logs


def run_log(job):
    i, log, pf, d, tmp = job
    o = Path(tmp) / f"d{i:03d}"
    rc, out, err, wall = cli(["diagnose", log, "--params", pf, "--out", str(o), "--candidates", "sensor_gain",
                              "--jobs", "1", "--quiet"], DIAG_TIMEOUT)
    cls = base_class(rc, err)
    col = d.get("column")
    named = (lambda s: col is not None and f"column '{col}'" in s)
    row = {"i": i, **d, "wall_s": round(wall, 2), "stderr": err.strip()[-300:]}
    clean = d["expect"] == "clean"
    if cls == "refused":
        cls = "false_alarm" if clean else ("refused" if named(err) else "wrong_column")
    elif cls is None:
        try:
            j = json.loads((o / "diagnosis.json").read_text())
        except (OSError, ValueError):
            return dict(row, **{"class": "exit_0_no_json"})
        v = j["verdict"]
        warns = j.get("warnings", [])
        row.update(effect=v.get("effect"), confidence=v.get("confidence"), data_quality=v.get("data_quality"))
        confident = v.get("confidence") != "low"
        if clean:
            cls = "false_alarm" if v.get("data_quality") or any("torn" in w for w in warns) else \
                ("confident_wrong" if confident and v.get("effect") not in ("none", "inconclusive") else "ok")
        elif d["expect"] == "dropped":
            dropped = any("torn" in w and named(w) for w in warns)
            cls = "wrong_column" if not dropped else \
                ("confident_wrong" if confident and v.get("effect") not in ("none", "inconclusive") else "ok")
        else:
            cls = "confident_on_corrupted" if confident else ("ok" if any(named(w) for w in warns) else "wrong_column")
    row["class"] = cls
    return row


# ------------------------------------------------------------------------------------------ main


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--params", type=int, default=500, help="parameter files")
    ap.add_argument("--simulate", type=int, default=40, help="accepted parameter files also simulated (10 s)")
    ap.add_argument("--logs", type=int, default=84, help="logs diagnosed")
    ap.add_argument("--duration", type=float, default=75.0,
                    help="log length [s] (75: a clock skew's cut ends leave >= 60 s to diagnose)")
    ap.add_argument("--seed", type=int, default=21)
    ap.add_argument("--jobs", type=int, default=3, help="subprocesses at once")
    ap.add_argument("--out", default=None, help="results json")
    ap.add_argument("--quick", action="store_true", help="the test suite's small run (12 files, 4 logs of 75 s)")
    a = ap.parse_args(argv)
    if a.quick:
        a.params, a.simulate, a.logs, a.duration = 12, 0, 4, 75.0
    t0 = time.time()
    rows_p, rows_l = [], []
    with tempfile.TemporaryDirectory(prefix="heavecomp_fuzz_") as tmp:
        tmp = Path(tmp)
        rng = random.Random(a.seed)
        bases = base_texts()
        jobs = []
        n_sim = 0
        for i in range(a.params):
            raw, desc, must = mutate_params(rng, bases, tmp, i)
            jobs.append((i, raw, desc, must, str(tmp), False))
        with cf.ThreadPoolExecutor(a.jobs) as ex:
            rows_p = list(ex.map(run_param_file, jobs))
        accepted = [r["i"] for r in rows_p if r["class"] == "ok"]
        sim_ids = set(random.Random(a.seed + 1).sample(accepted, min(a.simulate, len(accepted))))
        with cf.ThreadPoolExecutor(a.jobs) as ex:
            sims = list(ex.map(run_param_file, [(j[0], j[1], j[2], j[3], j[4], True) for j in jobs if j[0] in sim_ids]))
        for s in sims:
            rows_p[s["i"]] = s
            n_sim += 1
        logs = make_logs(a.seed, a.logs, a.duration, tmp) if a.logs else []
        with cf.ThreadPoolExecutor(a.jobs) as ex:
            rows_l = list(ex.map(run_log, [(*lg, str(tmp)) for lg in logs]))
    pc = Counter(r["class"] for r in rows_p)
    sc = Counter(r["simulate"]["class"] for r in rows_p if "simulate" in r)
    lc = Counter(r["class"] for r in rows_l)
    by_corruption = {}
    for r in rows_l:
        by_corruption.setdefault(r["corruption"], Counter())[r["class"]] += 1
    summary = {
        "seed": a.seed, "duration_s": a.duration, "wall_s": round(time.time() - t0, 1),
        "params": {"files": len(rows_p), "classes": dict(pc), "simulated": n_sim, "simulate_classes": dict(sc)},
        "logs": {"files": len(rows_l), "classes": dict(lc),
                 "by_corruption": {k: dict(v) for k, v in by_corruption.items()}},
        "bad": {"params": sum(pc[b] for b in BAD) + sum(v for k, v in pc.items() if k.startswith("exit_")),
                "simulate": sum(sc[b] for b in BAD) + sum(v for k, v in sc.items() if k.startswith("exit_")),
                "logs": sum(lc[b] for b in BAD) + sum(v for k, v in lc.items() if k.startswith("exit_"))},
        "command": "python benchmarks/fuzz/run_fuzz.py " + " ".join(argv if argv is not None else sys.argv[1:]),
        "uptime": _uptime(),
    }
    result = {"summary": summary, "params": rows_p, "logs": rows_l}
    print(json.dumps(summary, indent=1))
    if a.out:
        Path(a.out).write_text(json.dumps(result, indent=1) + "\n")
    return 1 if any(summary["bad"].values()) else 0


def _uptime():
    try:
        return Path("/proc/loadavg").read_text().split()[:3]
    except OSError:
        return None


if __name__ == "__main__":
    sys.exit(main())
