"""Paper A, section 4: how much does main-cylinder friction spoil the WOB, and how much does the
rotating piston (eq. 7) win back compared with removing friction altogether?

Paper-A load case (1 m, 12 s sine heave; short string, hard formation), three friction regimes:
no friction, reduced static friction (rotating piston, eq. 7), full static friction (eq. 4).
"""

from __future__ import annotations

import sys

from heavecomp.params import paper_a
from heavecomp.report import figures as fig
from heavecomp.report.scenario import md_table, parse_args, run, write_metrics, write_report
from heavecomp.simulate import simulate

REGIMES = ("none", "rotating_eq7", "stribeck")


def build(duration: float = 240.0) -> dict:
    """Simulate the three regimes; return {regime: SimulationResult}."""
    return {m: simulate(paper_a(m), duration, rate=50.0) for m in REGIMES}


def verdict(metrics: dict, key: str = "wob_p2p") -> dict:
    """Paper A's conclusion as numbers: gain of eq. 7 relative to removing friction."""
    full, red, none = (metrics[m][key] for m in ("stribeck", "rotating_eq7", "none"))
    share = (full - red) / (full - none)
    return {"key": key, "gain_eq7": full - red, "gain_no_friction": full - none, "share": share,
            "holds": bool(0.05 < share < 0.5)}


def main(argv=None) -> int:
    args = parse_args(argv, "paper_a_wob", __doc__)
    results = build(60.0 if args.quick else 240.0)
    metrics = {m: r.metrics() for m, r in results.items()}
    v_p2p, v_std = verdict(metrics, "wob_p2p"), verdict(metrics, "wob_std")
    k_eff = results["none"].params.k_eff
    fig.save(fig.plot_wob(results, window=(results["none"].t[-1] - 48, results["none"].t[-1]),
                          title="Paper A load case: WOB for three friction regimes (last 4 wave periods)"),
             args.out / "wob_regimes.png")
    fig.save(fig.bar_metrics(metrics, title="WOB variation per friction regime (after the 24 s fade-in)"),
             args.out / "wob_bars.png")
    write_metrics(args.out, {"regimes": metrics, "verdict_p2p": v_p2p, "verdict_std": v_std,
                             "static_estimate_p2p": 2 * k_eff * 1.0, "k_eff": k_eff})
    rows = [(fig.REGIME_LABELS[m], metrics[m]["wob_p2p"] / 1e3, metrics[m]["wob_std"] / 1e3,
             metrics[m]["wob_min"] / 1e3, metrics[m]["wob_max"] / 1e3, 100 * metrics[m]["stick_fraction"])
            for m in REGIMES]
    holds = "holds" if v_p2p["holds"] and v_std["holds"] else "does NOT hold"
    write_report(args.out, "Paper A load case: WOB for three friction regimes", [
        "Question: how much does main-cylinder friction spoil the weight on bit, and how much does the "
        "rotating piston (eq. 7) win back? Parameters: `heavecomp params paper_a` (assumptions in its docstring).",
        "![WOB](wob_regimes.png)",
        md_table(["regime", "WOB p2p [kN]", "WOB std [kN]", "WOB min [kN]", "WOB max [kN]", "stuck [%]"], rows),
        f"Static estimate (eqs. 13-14): k_eff = {k_eff / 1e3:.2f} kN/m, so 1 m of heave gives "
        f"{2 * k_eff / 1e3:.1f} kN peak-to-peak without friction; the frictionless simulation gives "
        f"{metrics['none']['wob_p2p'] / 1e3:.1f} kN (the eigenfrequency lies above the wave frequency: "
        f"small dynamic amplification).",
        f"Paper A's conclusion {holds}: eq. 7 reduces the WOB peak-to-peak by {v_p2p['gain_eq7'] / 1e3:.1f} kN, "
        f"removing friction by {v_p2p['gain_no_friction'] / 1e3:.1f} kN — eq. 7 wins back "
        f"{100 * v_p2p['share']:.0f} % of what friction costs (std: {100 * v_std['share']:.0f} %): distinct, "
        f"but modest compared with removing friction.",
        "![bars](wob_bars.png)",
    ])
    print(f"wrote {args.out}/report.md")
    return 0


if __name__ == "__main__":
    sys.exit(run(main))
