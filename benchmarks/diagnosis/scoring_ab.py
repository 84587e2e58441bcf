"""Does this tree score no worse than an older one on the same logs (issue 32: "the scoring sets score no worse")?

The scoring run (``python scenarios/diagnosis_validation.py --set scoring --seed-base N --runs DIR``) keeps every
generated log and its nominal file in DIR and this tree's verdicts in its ``metrics.json``.  This script diagnoses the
very same files with the code of another tree (a ``git worktree`` of the older commit, its own numba cache: the first
run compiles), in worker processes whose ``PYTHONPATH`` is that tree, and judges both sets of verdicts by this tree's
rules (``scenarios/diagnosis_validation.py``'s ``judge``).  One generator, one judge, two diagnoses: the difference
is the diagnosis alone.  Usage::

    git worktree add /tmp/old 39b1208
    python benchmarks/diagnosis/scoring_ab.py --old /tmp/old --runs DIR [--metrics reports/diagnosis_validation/scoring/metrics.json]

writes ``scoring_ab.json`` beside this file and prints the table (categories, right and confident wrong, and every
run whose verdict differs).
"""

from __future__ import annotations

import argparse
import copy
import glob
import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _diagnose_one(csv):
    from heavecomp.diagnosis import GapDiagnoser, load_run
    from heavecomp.params import load

    nominal = load(csv[:-4] + ".toml")
    try:
        d = GapDiagnoser(nominal, n_jobs=1).fit(load_run(csv, nominal))
    except Exception as exc:  # noqa: BLE001 - a refusal or a crash of the older code is its verdict
        return os.path.basename(csv), {"error": f"{type(exc).__name__}: {exc}"}
    v = d.verdict_
    return os.path.basename(csv), {"verdict": v["effect"], "confidence": v["confidence"], "component": v.get("component"),
                                   "shrink": float(v.get("shrink", 0.0)), "group": v.get("group")}


def _diagnose_all(runs, out, jobs):
    """In the older tree's interpreter path: every CSV of ``runs`` diagnosed, {file: verdict} into ``out``."""
    from multiprocessing import Pool

    with Pool(jobs) as p:
        res = dict(p.map(_diagnose_one, sorted(glob.glob(os.path.join(runs, "*.csv"))), chunksize=1))
    Path(out).write_text(json.dumps(res, indent=1))


def _judge():
    spec = importlib.util.spec_from_file_location("dv", ROOT / "scenarios" / "diagnosis_validation.py")
    dv = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(dv)
    return dv.judge


def compare(new_rows, old, judge) -> dict:
    """Both trees' rows judged alike: per category {n, right, confident_wrong} and the runs that differ."""
    pairs = []
    for r in new_rows:
        stem = f"{r['case']['seed']}_{r['case']['label']}"
        o = old.get(f"{stem}_full.csv")
        ro = copy.deepcopy(r)
        if o is None or "error" in o:
            ro["full"].update(verdict="refused", confidence="low", component=None, shrink=0.0, group=None)
        else:
            ro["full"].update({k: o[k] for k in ("verdict", "confidence", "component", "shrink", "group")})
        oc = old.get(f"{stem}_cut.csv")
        if "cut" in r and oc is not None and "error" not in oc:
            ro["cut"] = dict(r["cut"], verdict=oc["verdict"])
        pairs.append((ro, r))
    out = {"old": {}, "new": {}, "differ": []}
    for key, k in (("old", 0), ("new", 1)):
        for p in pairs:
            row = p[k]
            j = judge(row)
            t = out[key].setdefault(row["category"], {"n": 0, "right": 0, "confident_wrong": 0})
            t["n"] += 1
            t["right"] += bool(j["right"])
            t["confident_wrong"] += bool(j["confident_wrong"])
            if "unchanged_when_cut" in j:
                c = out[key].setdefault("unchanged_when_cut", {"n": 0, "right": 0, "confident_wrong": 0})
                c["n"] += 1
                c["right"] += bool(j["unchanged_when_cut"])
    for ro, rn in pairs:
        jo, jn = judge(ro), judge(rn)
        fo, fn = ro["full"], rn["full"]
        if (fo["verdict"], fo["confidence"]) != (fn["verdict"], fn["confidence"]) or jo["right"] != jn["right"]:
            out["differ"].append({"seed": rn["seed"], "category": rn["category"], "label": rn["label"],
                                  "old": [fo["verdict"], fo["confidence"], round(fo["shrink"], 3), bool(jo["right"])],
                                  "new": [fn["verdict"], fn["confidence"], round(fn["shrink"], 3), bool(jn["right"])]})
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--old", required=False, help="the older tree (a git worktree) whose diagnosis is compared")
    ap.add_argument("--runs", required=True, help="the scoring run's --runs folder (CSV logs and nominal files)")
    ap.add_argument("--metrics", default=str(ROOT / "reports" / "diagnosis_validation" / "scoring" / "metrics.json"),
                    help="this tree's scoring metrics.json of those runs")
    ap.add_argument("--jobs", type=int, default=2, help="diagnoses in parallel (default 2)")
    ap.add_argument("--reuse", action="store_true",
                    help="judge the older tree's verdicts already in RUNS/old_verdicts.json again (no diagnosis)")
    ap.add_argument("--diagnose-only", default=None, help=argparse.SUPPRESS)  # the worker side, in the old tree
    args = ap.parse_args(argv)
    if args.diagnose_only:
        _diagnose_all(args.runs, args.diagnose_only, args.jobs)
        return 0
    if not args.old or not (Path(args.old) / "heavecomp").is_dir():
        print(f"--old: no heavecomp tree at {args.old!r} (make one: git worktree add DIR COMMIT)", file=sys.stderr)
        return 2
    metrics = json.loads(Path(args.metrics).read_text())
    old_json = Path(args.runs) / "old_verdicts.json"
    env = dict(os.environ, PYTHONPATH=str(Path(args.old).resolve()))
    head = subprocess.run(["git", "-C", args.old, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    if not (args.reuse and old_json.exists()):
        print(f"diagnosing {args.runs} with {args.old} ({head}) ...", file=sys.stderr, flush=True)
        subprocess.run([sys.executable, str(Path(__file__).resolve()), "--runs", args.runs, "--jobs", str(args.jobs),
                        "--diagnose-only", str(old_json)], cwd=args.old, env=env, check=True)
    res = compare(metrics["runs"], json.loads(old_json.read_text()), _judge())
    here = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    res.update(old_commit=head, new_commit=here, seed_base=metrics["runs"][0]["seed"],
               command="python benchmarks/diagnosis/scoring_ab.py " + " ".join(sys.argv[1:] if argv is None else argv))
    print(f"category: {head} right/n (confident wrong) -> {here}")
    for c in res["new"]:
        o, n = res["old"][c], res["new"][c]
        print(f"  {c}: {o['right']}/{o['n']} ({o['confident_wrong']}) -> {n['right']}/{n['n']} ({n['confident_wrong']})")
    for d in res["differ"]:
        print(f"  {d['seed']} {d['category']} {d['label']}: {d['old']} -> {d['new']}")
    Path(__file__).with_name("scoring_ab.json").write_text(json.dumps(res, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
