"""Friction measured from pressure and displacement (paper B's method), validated twice.

1. **Synthetic**: a run of the pneumatic plant with known three-regime friction
   is "measured" like paper B's rig (encoder quantised to 12.5 um, pressure
   sensor noise), and the friction is recovered with
   :func:`heavecomp.signals.friction_from_motion` — only the equation of motion
   ``M a = A (P_a - P_b) - F_f`` is shared with the generator, not the friction law.
2. **Measured**: TU Delft O-ring seal data (``heavecomp/data/seal-friction``):
   friction = force - p A (the authors' definition) with the velocity from the
   zero-phase twice-differentiated position; sliding friction per direction and
   its growth with pressure (F_C + C_p p).
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np

from heavecomp.errors import DataError

log = logging.getLogger(__name__)

ENCODER_RESOLUTION = 12.5e-6  # m, paper B's optical encoder


def synthetic_validation(p=None, *, duration: float = 3.0, fs: float = 1000.0, cutoff: float = 25.0,
                         pressure_noise: float = 200.0, seed: int = 0) -> dict:
    """Recover the known friction of a simulated Exp.-2 run.

    Parameters
    ----------
    p : PneumaticParams, optional (default cylinder)
    duration : float [s]
    fs : float [Hz]  sampling rate of the synthetic measurement
    cutoff : float [Hz]  FIR cutoff
    pressure_noise : float [Pa]  standard deviation of each pressure sensor

    Returns
    -------
    dict: ``t``, true and measured ``friction`` [N], ``velocity`` [m/s], and
    ``rms_error_N``/``friction_span_N``/``velocity_rms_error`` over the sliding
    samples (excluding 30 ms around each stick/branch event, where the true
    friction jumps and no band-limited method can follow).
    """
    from heavecomp.analysis import pneumatic_sim as PS
    from heavecomp.plants import pneumatic as pn
    from heavecomp.signals import friction_from_motion

    p = p or pn.default()
    r = PS.simulate(p, duration, rate=fs)
    rng = np.random.default_rng(seed)
    x = np.round(r["position"] / ENCODER_RESOLUTION) * ENCODER_RESOLUTION
    Pa = r["pressure_a"] + rng.normal(0.0, pressure_noise, x.size)
    Pb = r["pressure_b"] + rng.normal(0.0, pressure_noise, x.size)
    m = friction_from_motion(r["t"], x, p.area * (Pa - Pb), p.mass, cutoff)
    events = np.flatnonzero(np.diff(r["stuck"]) != 0) + 1
    events = np.concatenate([events, np.flatnonzero(np.diff(r["accelerating"]) != 0) + 1])
    ok = (r["stuck"] < 0.5) & (r["t"] > 0.05) & (r["t"] < duration - 0.05)
    guard = int(0.03 * fs)
    for e in events:
        ok[max(0, e - guard):e + guard] = False
    err = m["friction"] - r["friction"]
    return {"t": r["t"], "friction_true": r["friction"], "friction_measured": m["friction"],
            "velocity_true": r["velocity"], "velocity_measured": m["velocity"], "sliding": ok,
            "rms_error_N": float(np.sqrt(np.mean(err[ok] ** 2))),
            "max_error_N": float(np.max(np.abs(err[ok]))),
            "friction_span_N": float(np.ptp(r["friction"][ok])),
            "velocity_rms_error": float(np.sqrt(np.mean((m["velocity"] - r["velocity"])[ok] ** 2))),
            "cutoff_Hz": cutoff, "fs_Hz": fs, "pressure_noise_Pa": pressure_noise}


SEAL_COLUMNS = ("time_ms", "laser_V", "pressure_V", "force_V", "position_mm", "pressure_bar", "force_N")
SEAL_BORE = 0.025  # m (TU Delft actuator, data README)


def load_seal_file(path) -> dict:
    """Read one O-ring file (7 whitespace-separated columns, no header, see data README)."""
    path = Path(path)
    try:
        d = np.loadtxt(path)
    except OSError as exc:
        raise DataError(f"{path}: cannot read ({exc.strerror})") from None
    except ValueError as exc:
        raise DataError(f"{path}: not a whitespace-separated numeric table ({str(exc).splitlines()[0]})") from None
    if d.ndim != 2 or d.shape[1] != len(SEAL_COLUMNS):
        raise DataError(f"{path}: expected {len(SEAL_COLUMNS)} columns ({', '.join(SEAL_COLUMNS)}), "
                        f"got {d.shape[1] if d.ndim == 2 else 1}")
    return {c: d[:, i] for i, c in enumerate(SEAL_COLUMNS)}


def seal_friction(path, *, fs: float = 100.0, cutoff: float = 2.0, v_min: float = 5e-3, mass: float = 0.0) -> dict:
    """Friction vs velocity of one seal file by paper B's method.

    The file's clock has jitter and gaps, so it is resampled to ``fs`` by linear
    interpolation first.  Velocity and acceleration from the position by
    zero-phase FIR differentiation; friction ``F - p A - m a`` (``mass`` [kg] of
    the moving parts; unknown for this rig, default 0 — at the steady 13 mm/s
    strokes the inertia term is small).

    Returns mean pressure [Pa], velocity [m/s], friction [N] arrays and the mean
    sliding friction for v > v_min and v < -v_min.
    """
    from heavecomp.signals import differentiate, zero_phase_lowpass

    d = load_seal_file(path)
    t = d["time_ms"] / 1e3
    if np.any(np.diff(t) <= 0):
        raise DataError(f"{path}: column time_ms must be strictly increasing")
    tu = np.arange(t[0], t[-1], 1.0 / fs)
    x = np.interp(tu, t, d["position_mm"] / 1e3)
    p = np.interp(tu, t, d["pressure_bar"] * 1e5)
    F = np.interp(tu, t, d["force_N"])
    _, v, a = differentiate(tu, x, cutoff, name="position_mm")
    A = np.pi * SEAL_BORE ** 2 / 4
    Ff = zero_phase_lowpass(F - p * A, fs, cutoff) - mass * a
    pos, neg = v > v_min, v < -v_min
    if pos.sum() < 10 or neg.sum() < 10:
        raise DataError(f"{path}: fewer than 10 samples sliding each way faster than {v_min * 1e3:g} mm/s")
    return {"t": tu, "velocity": v, "friction": Ff, "pressure": float(np.mean(p)),
            "friction_pos": float(np.median(Ff[pos])), "friction_neg": float(np.median(Ff[neg])),
            "speed": float(np.median(np.abs(v[pos | neg]))), "n_sliding": int((pos | neg).sum())}


def seal_summary(folder) -> dict:
    """Run :func:`seal_friction` on every ``O-ring_*bar.csv`` of ``folder``; fit the
    half-difference of the two sliding levels (the direction-symmetric Coulomb part)
    as ``F_C + C_p p`` [N, N/Pa]."""
    folder = Path(folder)
    files = sorted(folder.glob("O-ring_*bar.csv"), key=lambda f: float(f.stem.split("_")[1].rstrip("bar")))
    if not files:
        raise DataError(f"{folder}: no O-ring_*bar.csv files")
    rows = []
    for f in files:
        r = seal_friction(f)
        rows.append({"file": f.name, "pressure_Pa": r["pressure"], "friction_pos_N": r["friction_pos"],
                     "friction_neg_N": r["friction_neg"], "coulomb_N": 0.5 * (r["friction_pos"] - r["friction_neg"]),
                     "offset_N": 0.5 * (r["friction_pos"] + r["friction_neg"]), "speed_m_s": r["speed"]})
    P = np.array([r["pressure_Pa"] for r in rows])
    Fc = np.array([r["coulomb_N"] for r in rows])
    Cp, FC0 = np.polyfit(P, Fc, 1)
    return {"rows": rows, "coulomb_at_zero_N": float(FC0), "pressure_coefficient_N_per_Pa": float(Cp)}
