"""``[measurement]`` (optional): how a measured series maps to the contract columns.

.. code-block:: toml

    [measurement]
    columns = { t = "Time", heave = "MRU_heave", stroke = "CMC_pos", pressure = "P_main", wob = "WOB" }
    units = { t = "ms", pressure = "bar", wob = "kN", stroke = "mm" }

Read by every command that reads a measured series (``diagnose``, a heave file of
``[heave] kind = "file"``); ``--columns`` / ``--units`` override it key by key.
Contract: ``docs/contracts/measured-run.md``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from heavecomp.errors import ParameterError, did_you_mean
from heavecomp.io.series import check_spec
from heavecomp.errors import InputError

KEYS = ("columns", "units")


@dataclass(frozen=True)
class Measurement:
    """Column mapping (contract name -> source header) and declared units (contract name -> unit)."""

    columns: dict = field(default_factory=dict)
    units: dict = field(default_factory=dict)


def from_table(table) -> Measurement:
    """Validate a ``[measurement]`` table; one-line ParameterError naming the key.

    Parameters
    ----------
    table : Mapping[str, Any]
        The parsed ``[measurement]`` table: ``columns`` and ``units`` inline tables.
    """

    for k in table:
        if k not in KEYS:
            raise ParameterError(f"measurement.{k}: unknown key{did_you_mean(k, KEYS)}; known keys: {', '.join(KEYS)}")
    for k in KEYS:
        if k in table and not isinstance(table[k], dict):
            raise ParameterError(f"measurement.{k}: expected an inline table like {{ t = \"Time\" }}, "
                                 f"got {type(table[k]).__name__}")
    try:
        cols, units = check_spec(table.get("columns"), table.get("units"), "measurement")
    except InputError as exc:
        raise ParameterError(str(exc)) from None
    return Measurement(columns=cols, units=units)


def to_table(m: Measurement) -> dict:
    """The TOML table of ``m`` (only non-empty keys).

    Parameters
    ----------
    m : Measurement
        The validated table.
    """
    return {k: dict(getattr(m, k)) for k in KEYS if getattr(m, k)}
