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
    """matplotlib.pyplot with the non-interactive Agg backend (unless one is already chosen), imported
    on first use; the report package's one pyplot import (also public as :func:`pyplot`)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


pyplot = _plt


def save(fig, path, dpi: int = 110, tight: bool = True) -> Path:
    """Save and close a figure (``tight=False`` skips the extra layout pass of bbox_inches="tight").

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    path : str or os.PathLike
        The image file (its folder is created).
    dpi : int
        Resolution [dots per inch].
    tight : bool
        Crop to the drawn content (``bbox_inches="tight"``).

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=dpi, bbox_inches="tight" if tight else None)
    _plt().close(fig)
    return path


def envelope(t, y, max_points: int = 4000):
    """Min/max envelope of a long series for plotting: at most ``max_points`` points that draw
    exactly the same band as the full series at figure resolution (short series pass through).

    Parameters
    ----------
    t : array_like
        Sample times [s] (or any abscissa).
    y : array_like
        The series [any unit].
    max_points : int
        Largest number of points returned.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        The kept ``t`` and ``y`` (each bin's minimum and maximum, in time order).
    """
    t = np.asarray(t)
    y = np.asarray(y)
    if t.size <= max_points:
        return t, y
    nb = max_points // 2
    edges = np.linspace(0, t.size, nb + 1).astype(int)
    idx_min = np.array([a + np.argmin(y[a:b]) for a, b in zip(edges[:-1], edges[1:])])
    idx_max = np.array([a + np.argmax(y[a:b]) for a, b in zip(edges[:-1], edges[1:])])
    idx = np.sort(np.concatenate([idx_min, idx_max]))
    return t[idx], y[idx]


def plot_wob(results: dict, *, title: str | None = None, static_estimate: bool = True, window=None,
             force: bool = False):
    """WOB over time for several runs (label -> SimulationResult), with heave and
    paper A's static estimate W_0 - k_eff z_h (eqs. 13-14); ``force``: a third panel with each
    closed-loop run's actuator force ``u_active`` [kN] and its limits +-u_max.

    Parameters
    ----------
    results : dict
        Label -> :class:`heavecomp.simulate.SimulationResult` or
        :class:`heavecomp.closed_loop.ClosedLoopResult` (the first gives the heave and the estimate).
    title : str or None
        Title of the WOB panel (None: the default one).
    static_estimate : bool
        Draw the static estimate.
    window : (float, float) [s] or None
        Time span shown (None: the whole run).
    force : bool
        Add the actuator-force panel (closed-loop results only).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    ratios = [3, 1, 1.4] if force else [3, 1]
    fig, axes = plt.subplots(len(ratios), 1, figsize=(10, 6.2 + 2.0 * force), sharex=True,
                             gridspec_kw={"height_ratios": ratios})
    ax, axh = axes[0], axes[1]
    first = next(iter(results.values()))
    for label, res in results.items():
        t = res["t"]
        m = slice(None) if window is None else (t >= window[0]) & (t <= window[1])
        ax.plot(*envelope(t[m], res["wob"][m] / 1e3), color=REGIME_COLORS.get(label), lw=1.3 if t[m].size < 4000 else 0.6,
                label=REGIME_LABELS.get(label, label))
    t = first["t"]
    m = slice(None) if window is None else (t >= window[0]) & (t <= window[1])
    p = first.params
    if static_estimate:
        ax.plot(*envelope(t[m], (p.operating_point.wob_setpoint - p.k_eff * first["heave"][m]) / 1e3), "k--", lw=1,
                label=f"static estimate W0 - k_eff z_h (eq. 13-14, k_eff = {p.k_eff / 1e3:.1f} kN/m)")
    ax.axhline(p.operating_point.wob_setpoint / 1e3, color="0.6", lw=0.8)
    ax.set_ylabel("WOB [kN]")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title(title or "Weight on bit: friction in the main cylinder reaches the bit almost unfiltered")
    ax.grid(alpha=0.3)
    axh.plot(*envelope(t[m], first["heave"][m]), color="tab:blue", lw=1 if t[m].size < 4000 else 0.6)
    axh.set_ylabel("heave z_h [m]")
    axh.grid(alpha=0.3)
    if force:
        axu = axes[2]
        for label, res in results.items():
            t = res["t"]
            m = slice(None) if window is None else (t >= window[0]) & (t <= window[1])
            axu.plot(*envelope(t[m], res["u_active"][m] / 1e3), color=REGIME_COLORS.get(label), lw=1.0,
                     label=REGIME_LABELS.get(label, label))
        u_max = first.control["u_max"] / 1e3
        for sgn in (-1, 1):
            axu.axhline(sgn * u_max, color="0.5", ls="--", lw=0.8)
        axu.set_ylabel("actuator force u [kN]")
        axu.set_title(f"active cylinder: the force the actuator applied (|u| <= u_max = {u_max:g} kN)",
                      fontsize=9)
        axu.grid(alpha=0.3)
    axes[-1].set_xlabel("time t [s]")
    fig.tight_layout()
    return fig


def plot_wob_run(res, *, title: str | None = None, zoom: float | None = None):
    """One run at a glance: the WOB band over the whole run (min/max per bin) and a zoom on
    its last seconds with the static estimate of eqs. 13-14 and the heave.

    Parameters
    ----------
    res : heavecomp.simulate.SimulationResult
        The run.
    title : str or None
        Title of the top panel (None: the default one).
    zoom : float [s] or None
        Length of the zoom (None: 5 heave periods, 12 s for a heave without one; at most the run).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    t, w, z = res["t"], res["wob"] / 1e3, res["heave"]
    p = res.params
    if zoom is None:
        period = (p.heave.period if p.heave is not None and p.heave.kind == "sine" else
                  p.heave.tp if p.heave is not None and p.heave.kind == "jonswap" else 12.0)
        zoom = min(t[-1], 5 * period)
    fig = plt.figure(figsize=(9.5, 7))
    gs = fig.add_gridspec(3, 1, height_ratios=[2, 2.4, 1])
    ax0 = fig.add_subplot(gs[0])
    nb = min(600, max(1, t.size // 4))
    k = t.size // nb
    tb = t[: nb * k].reshape(nb, k)
    wb = w[: nb * k].reshape(nb, k)
    ax0.fill_between(tb.mean(1), wb.min(1), wb.max(1), color="tab:red", alpha=0.35, lw=0, label="WOB min-max")
    ax0.plot(tb.mean(1), wb.mean(1), color="tab:red", lw=0.8, label="WOB mean")
    ax0.axhline(p.operating_point.wob_setpoint / 1e3, color="0.4", lw=0.8, ls=":", label="set-point W0")
    ax0.axvspan(t[-1] - zoom, t[-1], color="0.85", zorder=0)
    ax0.set_xlabel("time t [s]")
    ax0.set_ylabel("WOB [kN]")
    ax0.legend(loc="upper right", fontsize=8, ncol=3)
    ax0.grid(alpha=0.3)
    ax0.set_title(title or "Weight on bit over the run (band) and its last wave periods (zoom, shaded)")
    m = t >= t[-1] - zoom
    ax1 = fig.add_subplot(gs[1])
    ax1.plot(t[m], w[m], color="tab:red", lw=1.2, label=f"WOB, friction {p.friction.model}")
    ax1.plot(t[m], (p.operating_point.wob_setpoint - p.k_eff * z[m]) / 1e3, "k--", lw=1,
             label=f"static estimate W0 - k_eff z_h (eqs. 13-14, k_eff = {p.k_eff / 1e3:.1f} kN/m)")
    st = res["stuck"][m] > 0.5
    if st.any():
        ax1.fill_between(t[m], w[m].min(), w[m].max(), where=st, color="tab:blue", alpha=0.12, lw=0,
                         label="cylinder stuck")
    ax1.set_ylabel("WOB [kN]")
    ax1.legend(loc="upper right", fontsize=8)
    ax1.grid(alpha=0.3)
    ax2 = fig.add_subplot(gs[2], sharex=ax1)
    ax2.plot(t[m], z[m], color="tab:blue", lw=1)
    ax2.set_ylabel("heave z_h [m]")
    ax2.set_xlabel("time t [s]")
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def plot_friction_laws(curves: dict, *, title: str | None = None, pneumatic: dict | None = None):
    """Friction force vs axial velocity for several laws (label -> (v, F, style)); an optional
    second panel for paper B's pneumatic seal (label -> (v, F, style), in N).

    Parameters
    ----------
    curves : dict
        Label -> (v [m/s], F [N], matplotlib style).
    title : str or None
        Figure title (None: the default one).
    pneumatic : dict or None
        Label -> (v [m/s], F [N], style) for the second panel (None: no second panel).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    if pneumatic:
        fig, (ax, axb) = plt.subplots(1, 2, figsize=(13, 5), gridspec_kw={"width_ratios": [1.3, 1]})
        for label, (v, F, style) in pneumatic.items():
            axb.plot(v * 1e3, F, style, lw=1.5, label=label)
        axb.axhline(0, color="0.5", lw=0.6)
        axb.axvline(0, color="0.5", lw=0.6)
        axb.set_xlabel("piston velocity v [mm/s]")
        axb.set_ylabel("friction force F_f [N]")
        axb.set_title("Paper B: three lubrication regimes (pneumatic seal)", fontsize=10)
        axb.legend(fontsize=8)
        axb.grid(alpha=0.3)
    else:
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
    """Grouped bars of metrics per label (label -> metrics dict).

    Parameters
    ----------
    rows : dict
        Label -> metrics dict.
    keys : sequence of str
        The metrics drawn, one bar each per label.
    title : str
        Figure title.
    unit_scale : float
        Factor from the metrics' unit to ``unit`` (1e-3: N -> kN).
    unit : str
        Unit of the axis.

    Returns
    -------
    matplotlib.figure.Figure
    """
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
