"""Simulate the CMC for a parameter file with exact stick-slip; write timeseries.csv, metrics.json and a WOB figure."""

from __future__ import annotations

import argparse


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("params", metavar="PARAMS.toml", help="CMC parameter file (cmc-reference.md contract)")
    p.add_argument("--duration", type=float, required=True, metavar="S", help="simulated time [s]")
    p.add_argument("--out", required=True, metavar="DIR", help="output folder")
    p.add_argument("--rate", type=float, default=20.0, metavar="HZ", help="output sample rate [Hz] (default 20)")
    p.add_argument("--dt", type=float, default=None, metavar="S",
                   help="RK4 step [s] (default: from the plant's fastest mode, at most 10 ms)")
    p.add_argument("--friction", default=None, metavar="MODEL",
                   help="override friction.model (none | stribeck | rotating_eq6 | rotating_eq7)")


def run(args) -> int:
    from pathlib import Path

    from heavecomp.commands._progress import Progress
    from heavecomp.params import load
    from heavecomp.simulate import simulate, write_outputs

    params = load(args.params)
    if args.friction:
        params = params.replace(friction={"model": args.friction})
    bar = Progress(f"simulate {args.duration:g} s")
    res = simulate(params, args.duration, dt=args.dt, rate=args.rate, progress=bar)
    m = write_outputs(res, args.out, title=f"WOB — {Path(args.params).name}, friction: {params.friction.model}")
    print(f"WOB mean {m['wob_mean'] / 1e3:.2f} kN, std {m['wob_std'] / 1e3:.2f} kN, "
          f"peak-to-peak {m['wob_p2p'] / 1e3:.2f} kN, stuck {100 * m['stick_fraction']:.1f} % of the time "
          f"-> {args.out}")
    return 0
