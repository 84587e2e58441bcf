"""Figures: each function takes results, returns a matplotlib Figure (use :func:`save`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

REGIME_LABELS = {
    "none": "no friction",
    "rotating_eq7": "reduced static friction (rotating piston, eq. 7)",
    "rotating_eq6": "rotating piston (eq. 6)",
    "stribeck": "full static friction (eq. 4)",
}
REGIME_COLORS = {"none": "tab:green", "rotating_eq7": "tab:orange", "rotating_eq6": "tab:purple",
                 "stribeck": "tab:red"}


def _plt():
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def save(fig, path, dpi: int = 110) -> Path:
    """Save and close a figure."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=dpi, bbox_inches="tight")
    _plt().close(fig)
    return path


def plot_wob(results: dict, *, title: str | None = None, static_estimate: bool = True, window=None):
    """WOB over time for several runs (label -> SimulationResult), with heave and
    paper A's static estimate W_0 - k_eff z_h (eqs. 13-14)."""
    plt = _plt()
    fig, (ax, axh) = plt.subplots(2, 1, figsize=(10, 6.2), sharex=True, gridspec_kw={"height_ratios": [3, 1]})
    first = next(iter(results.values()))
    for label, res in results.items():
        t = res["t"]
        m = slice(None) if window is None else (t >= window[0]) & (t <= window[1])
        ax.plot(t[m], res["wob"][m] / 1e3, color=REGIME_COLORS.get(label), lw=1.3,
                label=REGIME_LABELS.get(label, label))
    t = first["t"]
    m = slice(None) if window is None else (t >= window[0]) & (t <= window[1])
    p = first.params
    if static_estimate:
        ax.plot(t[m], (p.operating_point.wob_setpoint - p.k_eff * first["heave"][m]) / 1e3, "k--", lw=1,
                label=f"static estimate W0 - k_eff z_h (eq. 13-14, k_eff = {p.k_eff / 1e3:.1f} kN/m)")
    ax.axhline(p.operating_point.wob_setpoint / 1e3, color="0.6", lw=0.8)
    ax.set_ylabel("WOB [kN]")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title(title or "Weight on bit: friction in the main cylinder reaches the bit almost unfiltered")
    ax.grid(alpha=0.3)
    axh.plot(t[m], first["heave"][m], color="tab:blue", lw=1)
    axh.set_ylabel("heave z_h [m]")
    axh.set_xlabel("time t [s]")
    axh.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def plot_friction_laws(curves: dict, *, title: str | None = None):
    """Friction force vs axial velocity for several laws (label -> (v, F))."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(8, 5))
    for label, (v, F, style) in curves.items():
        ax.plot(v * 1e3, F / 1e3, style, lw=1.5, label=label)
    ax.axhline(0, color="0.5", lw=0.6)
    ax.axvline(0, color="0.5", lw=0.6)
    ax.set_xlabel("axial velocity v_a [mm/s]")
    ax.set_ylabel("friction force F_f [kN]")
    ax.set_title(title or "Friction laws (paper A Fig. 3): rotation removes the static peak (eq. 6) "
                 "and the sign jump (eq. 7)", fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def bar_metrics(rows: dict, keys=("wob_p2p", "wob_std"), *, title: str = "", unit_scale=1e-3, unit="kN"):
    """Grouped bars of metrics per label (label -> metrics dict)."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(8, 4))
    labels = list(rows)
    x = np.arange(len(labels))
    w = 0.8 / len(keys)
    for i, k in enumerate(keys):
        vals = [rows[l][k] * unit_scale for l in labels]
        bars = ax.bar(x + i * w - 0.4 + w / 2, vals, w, label=k.replace("_", " "))
        ax.bar_label(bars, fmt="%.1f", fontsize=7)
    ax.set_xticks(x, [REGIME_LABELS.get(l, l) for l in labels], fontsize=8, rotation=10)
    ax.set_ylabel(f"[{unit}]")
    ax.set_title(title)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    return fig
