"""Figures for the stick-slip work (paper B's cylinder, the CMC stick map, paper A's rig).

Each function takes computed results and returns a matplotlib Figure; save with
:func:`heavecomp.report.figures.save`.
"""

from __future__ import annotations

import numpy as np

from heavecomp.pneumatic import linear as PL
from heavecomp.pneumatic.stickslip import critical_D
from heavecomp.report.figures import _plt
from heavecomp.test_rig.plant import QUADRANTS



def plot_exp2(r, p, lin=None):
    """Exp. 2-like response: velocity, pressures, friction vs time.

    Parameters
    ----------
    r : dict
        A run of :func:`heavecomp.pneumatic.stepper.simulate`: ``t`` [s], ``velocity`` [m/s],
        ``pressure_a``, ``pressure_b`` [Pa, absolute], ``friction`` [N], ``stuck``.
    p : heavecomp.pneumatic.plant.PneumaticParams
        The cylinder.
    lin : heavecomp.pneumatic.linear.Linearisation or None
        Its equilibrium velocity ``u0`` [m/s] is drawn (None: not drawn).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    fig, ax = plt.subplots(3, 1, figsize=(9, 7.5), sharex=True)
    t = r["t"]
    ax[0].plot(t, r["velocity"] * 1e3, "C0", lw=1.3, label="piston velocity")
    if lin is not None:
        ax[0].axhline(lin.u0 * 1e3, color="k", ls="--", lw=0.8, label=f"equilibrium u_0 = {lin.u0 * 1e3:.1f} mm/s")
    st = r["stuck"] > 0.5
    ax[0].fill_between(t, 0, 1, where=st, color="0.85", transform=ax[0].get_xaxis_transform(), label="stuck")
    ax[0].set_ylabel("velocity [mm/s]")
    ax[0].legend(fontsize=8, loc="upper right")
    ax[1].plot(t, (r["pressure_a"] - p.atmosphere) / 1e6, "C3", label="charging chamber a")
    ax[1].plot(t, (r["pressure_b"] - p.atmosphere) / 1e6, "C2", label="discharge chamber b")
    ax[1].set_ylabel("pressure [MPa gauge]")
    ax[1].legend(fontsize=8)
    ax[2].plot(t, r["friction"], "C1", label="friction (holding force while stuck)")
    ax[2].axhline(p.start_static_force, color="C1", ls=":", lw=0.8, label="F_0 (first start)")
    ax[2].axhline(p.stick_static_force, color="C4", ls=":", lw=0.8, label="F_s1 (after a stick)")
    ax[2].set_ylabel("friction [N]")
    ax[2].set_xlabel("time t [s]")
    ax[2].legend(fontsize=8)
    for a in ax:
        a.grid(alpha=0.3)
    ax[0].set_title("Paper B Exp. 2 (our parameters): breakaway, one stick, restart at the lower F_s1, steady motion")
    fig.tight_layout()
    return fig


def plot_friction_velocity(v, F_true, F_meas, mask, title):
    """Measured (paper B's method) vs true friction against velocity.

    Parameters
    ----------
    v : numpy.ndarray [m/s]
        Measured piston velocity.
    F_true : numpy.ndarray [N]
        The model's friction.
    F_meas : numpy.ndarray [N]
        Friction as paper B measures it (pressure force minus inertia).
    mask : numpy.ndarray of bool
        The samples drawn.
    title : str
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7.5, 5))
    ax.plot(v[mask] * 1e3, F_true[mask], ".", ms=2, color="0.5", label="true (model) friction")
    ax.plot(v[mask] * 1e3, F_meas[mask], ".", ms=2, color="C3", label="measured: A(P_a - P_b) - M d2x/dt2, zero-phase FIR")
    ax.set_xlabel("velocity [mm/s]")
    ax.set_ylabel("friction force [N]")
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8, markerscale=4)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def plot_critical_map(g, zc, Dc, default_point=None):
    """Grid points in the (zeta*, D*) plane coloured by the nonlinear outcome, with the critical curve.

    Parameters
    ----------
    g : dict
        :func:`heavecomp.pneumatic.stickslip.grid_map`: ``zeta``, ``D`` [-], ``nonlinear`` (stick-slip
        in the simulation), ``agree`` per point, ``agreement`` [-].
    zc : array_like [-]
        Damping ratio zeta* along the critical curve.
    Dc : array_like [-]
        Critical D*_cr at ``zc`` (:func:`heavecomp.pneumatic.stickslip.critical_curve`).
    default_point : (float, float) or None
        (zeta*, D*) [-] of the default cylinder, marked (None: not marked).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    fig, ax = plt.subplots(figsize=(8, 6))
    z, D, nl, ag = g["zeta"].ravel(), g["D"].ravel(), g["nonlinear"].ravel(), g["agree"].ravel()
    ax.scatter(z[nl & ag], D[nl & ag], s=8, c="C3", label="simulation: stick-slip")
    ax.scatter(z[~nl & ag], D[~nl & ag], s=8, c="C0", label="simulation: no stick-slip")
    ax.scatter(z[~ag], D[~ag], s=40, facecolors="none", edgecolors="k", lw=1.2,
               label=f"curve and simulation disagree ({(~ag).sum()} of {ag.size})")
    ax.plot(zc, Dc, "k-", lw=2, label="critical curve (linear analysis)")
    if default_point is not None:
        ax.plot(*default_point, "*", color="gold", mec="k", ms=16, label="default cylinder")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_ylim(D.min() * 0.8, D.max() * 1.2)
    ax.set_xlabel("damping factor zeta* [-]")
    ax.set_ylabel("dimensionless friction drop D* [-]")
    ax.set_title(f"Stick-slip above the critical curve: agreement with {ag.size} nonlinear runs "
                 f"= {100 * g['agreement']:.1f} %", fontsize=10)
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    return fig


def plot_min_velocity(p, zc, Dc, mv):
    """Critical curve mapped to equilibrium velocity for the default cylinder (paper B Fig. 5).

    Parameters
    ----------
    p : heavecomp.pneumatic.plant.PneumaticParams
        The cylinder.
    zc : array_like [-]
        Damping ratio zeta* along the critical curve.
    Dc : array_like [-]
        Critical D*_cr at ``zc`` (:func:`heavecomp.pneumatic.stickslip.critical_curve`).
        Not drawn: the margin D*/D*_cr is recomputed for each exhaust area.
    mv : dict
        :func:`heavecomp.pneumatic.stickslip.minimum_velocity`: ``linear_u0`` and, if simulated,
        ``nonlinear_u0`` [m/s].

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    S = np.geomspace(0.02e-6, 1.0e-6, 40)
    u0, margin = [], []
    for s in S:
        lin = PL.linearise(p.replace(exhaust_area=float(s)))
        u0.append(lin.u0)
        margin.append(lin.D / critical_D(lin.zeta))
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    ax.semilogy(np.array(u0) * 1e3, margin, "C0-", lw=1.5, label="D*/D*_cr (linear analysis)")
    ax.axhline(1.0, color="k", lw=0.8)
    ax.axvline(mv["linear_u0"] * 1e3, color="C0", ls="--", label=f"linear: u_0,min = {mv['linear_u0'] * 1e3:.1f} mm/s")
    if np.isfinite(mv.get("nonlinear_u0", np.nan)):
        ax.axvline(mv["nonlinear_u0"] * 1e3, color="C3", ls="--",
                   label=f"nonlinear simulation: u_0,min = {mv['nonlinear_u0'] * 1e3:.1f} mm/s")
    ax.set_xlabel("equilibrium velocity u_0 [mm/s] (varied through S_e)")
    ax.set_ylabel("D* / D*_cr [-]  (>1: stick-slip)")
    ax.set_title("Minimum equilibrium velocity without stick-slip, default cylinder", fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    return fig


def plot_influence(inf, zc, Dc):
    """Paper B Fig. 6: where (zeta*, D*) moves when each variable is scaled 0.5..2.

    Parameters
    ----------
    inf : dict
        :func:`heavecomp.pneumatic.stickslip.influence`: variable -> {``zeta``, ``D`` [-] per scale
        factor}.
    zc : array_like [-]
        Damping ratio zeta* along the critical curve.
    Dc : array_like [-]
        Critical D*_cr at ``zc`` (:func:`heavecomp.pneumatic.stickslip.critical_curve`).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    fig, ax = plt.subplots(figsize=(10, 6))
    zs = np.concatenate([np.asarray(r["zeta"], float) for r in inf.values()])
    Ds = np.concatenate([np.asarray(r["D"], float) for r in inf.values()])
    # axes on the influence points (the critical curve runs to D* ~ 1e6 at small zeta*: clip it)
    xlim = (zs.min() / 1.5, zs.max() * 1.5)
    ylim = (Ds.min() / 2.0, Ds.max() * 2.0)
    zc, Dc = np.asarray(zc, float), np.asarray(Dc, float)
    ax.plot(zc, Dc, "k-", lw=2, label="critical curve")
    for i, (var, rows) in enumerate(inf.items()):
        z, D = np.array(rows["zeta"]), np.array(rows["D"])
        ax.plot(z, D, "o-", color=f"C{i}", ms=3, lw=1.2, label=f"{var} x0.5 .. x2")
        ax.annotate("", xy=(z[-1], D[-1]), xytext=(z[-2], D[-2]),
                    arrowprops=dict(arrowstyle="->", color=f"C{i}", lw=1.5))
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(*xlim)
    ax.set_ylim(*ylim)
    ax.set_xlabel("damping factor zeta* [-]")
    ax.set_ylabel("dimensionless friction drop D* [-]")
    ax.set_title("Influence of each variable (arrow: increasing it); above the curve = stick-slip", fontsize=10)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)  # beside, not over
    ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    return fig


def plot_cmc_map(m, breakout):
    """CMC main cylinder over heave amplitude x period, one column per friction law:
    fraction of time stuck (top) and mean duration of one stick (bottom).

    Parameters
    ----------
    m : dict
        :func:`heavecomp.pneumatic.stickslip.cmc_stick_map`: ``amplitudes`` [m], ``periods`` [s] and,
        per friction model, ``stick_fraction`` [-] and ``mean_stick_s`` [s] over the grid.
    breakout : dict
        Friction model -> quasi-static breakout heave amplitude [m] per period (dashed line).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    models = [k for k in m if k not in ("amplitudes", "periods")]
    fig, axs = plt.subplots(2, len(models), figsize=(4.6 * len(models), 7.6), sharey=True, sharex=True,
                            squeeze=False)
    A, T = m["amplitudes"], m["periods"]
    vmax_d = max(float(np.max(np.where(m[k]["stick_fraction"] < 0.999, m[k]["mean_stick_s"], 0))) for k in models)
    for c, mod in enumerate(models):
        top, bot = axs[0, c], axs[1, c]
        im = top.pcolormesh(A, T, m[mod]["stick_fraction"], vmin=0, vmax=1, cmap="viridis", shading="nearest")
        dur = np.where(m[mod]["stick_fraction"] < 0.999, m[mod]["mean_stick_s"], np.nan)
        im2 = bot.pcolormesh(A, T, dur, vmin=0, vmax=max(vmax_d, 1e-3), cmap="magma", shading="nearest")
        for ax in (top, bot):
            ax.plot(breakout[mod], T, "w--", lw=1.5, label="breakout estimate (zero stroke to the left)")
            ax.set_xscale("log")
        top.set_title(mod, fontsize=10)
        top.legend(fontsize=7, loc="lower right")
        bot.set_xlabel("heave amplitude [m]")
    axs[0, 0].set_ylabel("heave period [s]")
    axs[1, 0].set_ylabel("heave period [s]")
    fig.colorbar(im, ax=axs[0, :], label="fraction of time stuck [-]")
    fig.colorbar(im2, ax=axs[1, :], label="mean duration of one stick [s] (blank: never slides)")
    fig.suptitle("CMC main cylinder: where it sticks and for how long; rotation (eq. 6, eq. 7) shrinks "
                 "the zero-stroke region", fontsize=11)
    return fig


def plot_rig(r_norot, r_rot, p):
    """Paper A Figs. 7 and 8: friction-velocity loops without and with rotation (eq. 12 readings).

    Parameters
    ----------
    r_norot, r_rot : dict
        Rig runs without and with rotation (:func:`heavecomp.test_rig.plant.run`): ``t`` [s], ``v``
        [m/s], ``friction``, ``friction_eq12`` [N], ``quadrant``.
    p : heavecomp.test_rig.plant.RigParams
        The rig (piston diameter [m], tangential velocity [m/s] in the title).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    fig, axs = plt.subplots(1, 2, figsize=(12, 4.8), sharey=True)
    for ax, r, ttl in ((axs[0], r_norot, "without rotation (Fig. 7): hysteresis, Stribeck when accelerating"),
                       (axs[1], r_rot, "with rotation near v = 0 (Fig. 8): static peak gone, viscous band")):
        for k, qn in enumerate(QUADRANTS):
            m = r["quadrant"] == k
            ax.plot(r["v"][m] * 1e3, r["friction_eq12"][m], ".", ms=2, color=f"C{k}", label=f"eq. 12 reading, {qn}")
        order = np.argsort(r["t"])
        ax.plot(r["v"][order] * 1e3, r["friction"][order], "k-", lw=0.5, alpha=0.6, label="model friction")
        ax.set_xlabel("axial velocity v_a [mm/s]")
        ax.set_title(ttl, fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, markerscale=4)
    axs[0].set_ylabel("friction F_f = A_A p_A - A_B p_B [N]")
    fig.suptitle(f"Paper A test rig, d = {p.piston_diameter * 1e3:.0f} mm, v_t = {p.tangential_velocity * 1e3:.0f} mm/s",
                 fontsize=11)
    fig.tight_layout()
    return fig


def plot_seal(rows_by_file):
    """Seal friction against velocity for each supply pressure (TU Delft O-ring data).

    Parameters
    ----------
    rows_by_file : dict
        File name -> {``velocity`` [m/s], ``friction`` [N], ``pressure`` [Pa]}.

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7.5, 5))
    for i, (name, r) in enumerate(rows_by_file.items()):
        ax.plot(r["velocity"] * 1e3, r["friction"], ".", ms=1.5, color=f"C{i}",
                label=f"{name}: p = {r['pressure'] / 1e5:.1f} bar")
    ax.set_xlabel("velocity from position, zero-phase FIR [mm/s]")
    ax.set_ylabel("friction = force - p A [N]")
    ax.set_title("Measured O-ring friction: sign follows velocity, level grows with pressure", fontsize=10)
    ax.legend(fontsize=8, markerscale=5)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig
