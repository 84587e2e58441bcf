"""Figures of the controller design study (:mod:`heavecomp.closed_loop.design` computes, this draws)."""

from __future__ import annotations

import numpy as np

from heavecomp.report.figures import REGIME_LABELS, _plt


def plot_wob_controllers(results: dict, window, *, title: str):
    """WOB and active force over time for several controllers (label -> ClosedLoopResult).

    Parameters
    ----------
    results : dict
        Controller label -> :class:`heavecomp.closed_loop.ClosedLoopResult` (the first gives the
        setpoint and the force limit).
    window : (float, float) [s]
        Time span shown.
    title : str
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
    """

    plt = _plt()
    fig, (ax, axu) = plt.subplots(2, 1, figsize=(10, 6.2), sharex=True, gridspec_kw={"height_ratios": [3, 2]})
    colors = {"passive": "tab:red", "pid": "tab:orange", "linear-mpc": "tab:blue", "nonlinear-mpc": "tab:green"}
    for label, res in results.items():
        t = res.t
        m = (t >= window[0]) & (t <= window[1])
        ax.plot(t[m], res["wob"][m] / 1e3, lw=1.2, color=colors.get(label), label=label)
        axu.plot(t[m], res["u_active"][m] / 1e3, lw=1.0, color=colors.get(label), label=label)
    first = next(iter(results.values()))
    u_max = first.control["u_max"]
    for s in (-1, 1):
        axu.axhline(s * u_max / 1e3, color="0.5", ls="--", lw=0.8)
    ax.axhline(first.params.operating_point.wob_setpoint / 1e3, color="0.5", lw=0.8)
    ax.set_ylabel("WOB [kN]")
    axu.set_ylabel("active force u [kN]")
    axu.set_xlabel("time t [s]")
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8, loc="upper right")
    ax.grid(alpha=0.3)
    axu.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def plot_std_table(table: dict, sea: str, *, title: str):
    """Grouped bars: WOB std per friction regime and controller.

    Parameters
    ----------
    table : dict
        ``table[sea][regime][controller]["wob_std"]`` [N].
    sea : str
        The sea whose bars are drawn.
    title : str
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
    """

    plt = _plt()
    fig, ax = plt.subplots(figsize=(9, 4.2))
    regs = list(table[sea])
    ctrls = list(table[sea][regs[0]])
    w = 0.8 / len(ctrls)
    x = np.arange(len(regs))
    for i, c in enumerate(ctrls):
        vals = [table[sea][r][c]["wob_std"] / 1e3 for r in regs]
        bars = ax.bar(x - 0.4 + (i + 0.5) * w, vals, w, label=c)
        ax.bar_label(bars, fmt="%.1f", fontsize=7)
    ax.set_xticks(x, [REGIME_LABELS.get(r, r) for r in regs], fontsize=8)
    ax.set_ylabel("WOB standard deviation [kN]")
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    return fig


def plot_sweeps(sweeps: dict, passive_std: float, *, title: str):
    """One panel per swept option: WOB std (left axis) against the option value.

    Parameters
    ----------
    sweeps : dict
        Option label -> (unit, {controller: [{"value": option value, "wob_std": [N]}, ...]}).
    passive_std : float [N]
        WOB std of the passive compensator (the goal line is 20 % of it).
    title : str
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
    """

    plt = _plt()
    n = len(sweeps)
    fig, axes = plt.subplots(1, n, figsize=(3.3 * n, 3.6), squeeze=False)
    for ax, (label, (unit, rows)) in zip(axes[0], sweeps.items()):
        for ctrl, rr in rows.items():
            ax.plot([r["value"] for r in rr], [r["wob_std"] / 1e3 for r in rr], "o-", label=ctrl)
        ax.axhline(0.2 * passive_std / 1e3, color="k", ls="--", lw=0.8, label="goal: 20 % of passive")
        ax.set_xlabel(f"{label} [{unit}]")
        if "weight" in label:
            ax.set_xscale("log")
        ax.set_ylabel("WOB std [kN]")
        ax.grid(alpha=0.3)
        ax.set_ylim(bottom=0)
    axes[0][0].legend(fontsize=7)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return fig
