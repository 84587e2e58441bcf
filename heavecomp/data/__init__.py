"""Measured data shipped with the package (sources and licences: ``heavecomp/data/README.md``).

Only files the tests, scenarios and examples use are shipped, so that a plain clone or
a pip install is complete without any folder beside it.
"""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parent

#: The EMPS benchmark estimation set (MATLAB v5).
EMPS = ROOT / "emps" / "DATA_EMPS.mat"
#: Folder of the TU Delft O-ring seal-friction files (1, 3, 5, 7 bar).
SEAL_FRICTION = ROOT / "seal-friction"
#: Two hours (06:00-08:00) of Datawell Waverider buoy heave, 1.28 Hz.
WAVERIDER = ROOT / "waverider" / "waverider_2005-07-01_06h-08h_heave.csv"
#: Example measured run in a rig's shape (ms time, bar, kN, mm; see docs/contracts/measured-run.md).
EXAMPLE_RUN = ROOT / "examples" / "rig_log_example.csv.gz"
#: The nominal parameter file of the example run.
EXAMPLE_PARAMS = ROOT / "examples" / "rig_log_example.toml"


def path(*parts: str) -> Path:
    """Path of a shipped data file, e.g. ``path("emps", "DATA_EMPS.mat")``.

    Parameters
    ----------
    *parts : str
        Path components below the package's data folder (:data:`ROOT`).
    """
    return ROOT.joinpath(*parts)
