"""A rig logger's file, as a user brings it (issue 31's reproducer, made here: the project reads no shared folder).

Semicolons, the time as epoch milliseconds (``TIME_MS``), the stroke in mm, the pressure in bar and the hook load
in tonnes (``HKLD_T``: no WOB column; the WOB is the string weight minus the hook load), from a simulation of the
truth plant with sensor noise (heave 1 mm, stroke 2 mm, pressure 2 kPa, WOB 400 N).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

#: the mapping a user gives for this log (contract name -> the logger's column / unit)
COLUMNS = "t=TIME_MS,heave=MRU_HEAVE_M,stroke=CMC_STROKE_MM,pressure=CMC_P_BAR,hook_load=HKLD_T"
UNITS = "t=ms,stroke=mm,pressure=bar,hook_load=t"
#: the string weight hanging from the hook [N] (the parameter file's ``[measurement] string_weight``)
STRING_WEIGHT = 1.5e6
#: the logger's clock at the first row [ms since 1970]
EPOCH_MS = 1_764_000_000_000
NOISE = {"heave": 1e-3, "stroke": 2e-3, "pressure": 2e3, "wob": 400.0}


def nominal_toml(path, *, seed: int = 7, hs: float = 2.0) -> Path:
    """The nominal file of these logs: paper A with a JONSWAP sea and the string weight declared."""
    from heavecomp.params import dumps, paper_a

    p = paper_a().replace(heave={"kind": "jonswap", "hs": hs, "tp": 10.0, "seed": seed, "ramp": 20.0,
                                 "amplitude": None, "period": None})
    text = dumps(p) + f"\n[measurement]\nstring_weight = {STRING_WEIGHT:g}\n"
    Path(path).write_text(text, encoding="utf-8")
    return Path(path)


def write_logger_log(path, params, *, duration: float, rate: float = 10.0, seed: int = 1) -> Path:
    """Simulate ``params`` (a parameter set: the truth plant and its sea) for ``duration`` s and write the log a
    rig logger would, at ``rate`` Hz, to ``path``."""
    from heavecomp.simulate import simulate

    res = simulate(params, duration, rate=rate)
    rng = np.random.default_rng(seed)
    t = np.asarray(res["t"], float)
    y = {k: np.asarray(res[k], float) + rng.normal(0.0, s, t.size) for k, s in NOISE.items()}
    rows = ["TIME_MS;MRU_HEAVE_M;CMC_STROKE_MM;CMC_P_BAR;HKLD_T"]
    for i in range(t.size):
        rows.append(f"{EPOCH_MS + round(1e3 * t[i])};{y['heave'][i]:.5f};{1e3 * y['stroke'][i]:.2f};"
                    f"{y['pressure'][i] / 1e5:.5f};{(STRING_WEIGHT - y['wob'][i]) / 9810.0:.4f}")
    Path(path).write_text("\n".join(rows) + "\n", encoding="utf-8")
    return Path(path)
