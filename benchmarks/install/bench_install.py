"""The install against its peer: ``pip install -e .`` of a fresh clone in a fresh venv, against ``pip install``
of the same dependencies alone in another fresh venv (issue 32: <= 2 min and <= 2.5 x the peer, quiet 2-core
machine).  One process runs both, one after the other, and reports the ratio of wall times and of the
children's CPU times, with the 1-minute load average before and after each.

The peer runs first, so the downloads are in pip's cache for both (the ratio is the work pip and the
build do here, not the network).  The clone is fresh (``git clone`` of the repository's committed HEAD):
no numba cache, no ahead-of-time module, as a user's clone.  ``--peer-no-cache`` also times the peer with
``pip install --no-cache-dir`` (every wheel downloaded, as issue 32's 32.5 s likely was), in a venv of its own
between the two, and reports the install against it too.  ``--rounds N`` runs the pair N times (a fresh clone and
fresh venvs each round, peer then install) and reports each round's ratio and their median: one pair's wall times
swing by a third with the machine's load (the peer alone took 19-27 s in one hour here), and the rounds
interleave, so both sides of a ratio see the same load.  Usage::

    python benchmarks/install/bench_install.py [--repo PATH] [--extras test] [--keep DIR] [--peer-no-cache] [--rounds N]
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import tomllib

ROOT = Path(__file__).resolve().parents[2]


def _timed(cmd, cwd=None, env=None) -> dict:
    """Run ``cmd``; wall [s], the children's CPU [s] (user + system) and the load before/after."""
    load0 = os.getloadavg()[0]
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        sys.stderr.write(proc.stdout[-3000:] + proc.stderr[-3000:])
        raise SystemExit(f"failed ({proc.returncode}): {' '.join(map(str, cmd))}")
    return {"wall_s": wall, "cpu_s": (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime),
            "load_before": load0, "load_after": os.getloadavg()[0], "command": " ".join(map(str, cmd))}


def _round(args, work, deps, env) -> dict:
    """One peer/install pair: a fresh clone, a fresh venv for each, the peer first (pip's cache holds the
    downloads for both)."""
    work.mkdir(parents=True, exist_ok=True)
    clone = work / "heavecomp"
    subprocess.run(["git", "clone", "--quiet", args.repo, str(clone)], check=True)
    head = subprocess.run(["git", "-C", str(clone), "rev-parse", "--short", "HEAD"], capture_output=True,
                          text=True, check=True).stdout.strip()
    out = {"commit": head}
    for name in ("peer",) + (("peer_no_cache",) if args.peer_no_cache else ()) + ("install",):
        venv = work / f"venv_{name}"
        subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
        pip = [str(venv / "bin" / "python"), "-m", "pip", "install", "--quiet"]
        if name == "peer":
            print(f"peer: pip install of the {len(deps)} dependencies alone ...", file=sys.stderr, flush=True)
            out["peer"] = _timed(pip + deps, env=env)
        elif name == "peer_no_cache":
            print("peer without pip's cache (--no-cache-dir: downloads) ...", file=sys.stderr, flush=True)
            out[name] = _timed(pip + ["--no-cache-dir"] + deps, env=env)
        else:
            target = "." + (f"[{args.extras}]" if args.extras else "")
            print(f"install: pip install -e {target} of a fresh clone ({head}) ...", file=sys.stderr, flush=True)
            out["install"] = _timed(pip + ["-e", target], cwd=clone, env=env)
        print(f"  {out[name]['wall_s']:.0f} s wall, {out[name]['cpu_s']:.0f} s CPU", file=sys.stderr, flush=True)
    out["ratio_wall"] = out["install"]["wall_s"] / out["peer"]["wall_s"]
    out["ratio_cpu"] = out["install"]["cpu_s"] / out["peer"]["cpu_s"]
    if "peer_no_cache" in out:
        out["ratio_wall_vs_peer_no_cache"] = out["install"]["wall_s"] / out["peer_no_cache"]["wall_s"]
    print(f"  ratio {out['ratio_wall']:.2f} wall", file=sys.stderr, flush=True)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repo", default=str(ROOT), help="the repository cloned (default: this one)")
    ap.add_argument("--extras", default="", help="extras installed by both, e.g. test (default: none)")
    ap.add_argument("--keep", default=None, help="work in this folder and keep it (default: a temporary one)")
    ap.add_argument("--peer-no-cache", action="store_true",
                    help="also time the peer with pip's --no-cache-dir (downloads every wheel; the goal is still "
                         "judged on the cached peer, the stricter one)")
    ap.add_argument("--rounds", type=int, default=1,
                    help="peer/install pairs, interleaved, each on a fresh clone and fresh venvs; the median "
                         "ratio is reported (default: 1)")
    args = ap.parse_args(argv)
    if args.rounds < 1:
        ap.error("--rounds must be at least 1")

    work = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="heavecomp_install_"))
    work.mkdir(parents=True, exist_ok=True)
    try:
        meta = tomllib.loads((Path(args.repo) / "pyproject.toml").read_text())["project"]
        deps = list(meta["dependencies"])
        for e in filter(None, args.extras.split(",")):
            deps += meta["optional-dependencies"][e]
        env = {k: v for k, v in os.environ.items() if not k.startswith("HEAVECOMP_")}
        out = {"extras": args.extras, "cpus": os.cpu_count(), "python": sys.version.split()[0], "rounds": []}
        for k in range(args.rounds):
            out["rounds"].append(_round(args, work / f"round{k}", deps, env))
        first = out["rounds"][0]
        out["commit"] = first["commit"]
        for key in ("peer", "peer_no_cache", "install"):
            if key in first:
                out[key] = first[key]
        for key in ("ratio_wall", "ratio_cpu", "ratio_wall_vs_peer_no_cache"):
            if key in first:
                out[key] = first[key]
                out[f"median_{key}"] = statistics.median(r[key] for r in out["rounds"])
        out["median_install_wall_s"] = statistics.median(r["install"]["wall_s"] for r in out["rounds"])
        out["median_peer_wall_s"] = statistics.median(r["peer"]["wall_s"] for r in out["rounds"])
        out["goal"] = {"install_wall_s": 120.0, "ratio_wall": 2.5}
        text = json.dumps(out, indent=2)
        print(text)
        (Path(__file__).with_name("results.json")).write_text(text + "\n")
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
