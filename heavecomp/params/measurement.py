"""``[measurement]`` (optional): how a measured series maps to the contract columns.

.. code-block:: toml

    [measurement]
    columns = { t = "Time", heave = "MRU_heave", stroke = "CMC_pos", pressure = "P_main", wob = "WOB" }
    units = { t = "ms", pressure = "bar", wob = "kN", stroke = "mm" }
    string_weight = 1.2e6   # N: a log with a hook load and no WOB reads wob = string_weight - hook_load

Read by every command that reads a measured series (``diagnose``, a heave file of
``[heave] kind = "file"``); ``--columns`` / ``--units`` override it key by key.
Contract: ``docs/contracts/measured-run.md``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from heavecomp.errors import ParameterError, did_you_mean
from heavecomp.io.series import check_spec
from heavecomp.errors import InputError

KEYS = ("columns", "units", "string_weight")
TABLES = ("columns", "units")


@dataclass(frozen=True)
class Measurement:
    """Column mapping (contract name -> source header) and declared units (contract name -> unit)."""

    columns: dict = field(default_factory=dict)
    units: dict = field(default_factory=dict)
    #: string weight [N] the WOB is derived from when a log has a hook load and no WOB (None: not given)
    string_weight: float | None = None


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
    for k in TABLES:
        if k in table and not isinstance(table[k], dict):
            raise ParameterError(f"measurement.{k}: expected an inline table like {{ t = \"Time\" }}, "
                                 f"got {type(table[k]).__name__}")
    try:
        cols, units = check_spec(table.get("columns"), table.get("units"), "measurement")
    except InputError as exc:
        raise ParameterError(str(exc)) from None
    w = table.get("string_weight")
    if w is not None and (isinstance(w, bool) or not isinstance(w, (int, float)) or not w > 0 or w == float("inf")):
        raise ParameterError(f"measurement.string_weight: expected a positive force in N, got {w!r}")
    return Measurement(columns=cols, units=units, string_weight=None if w is None else float(w))


def used(params, columns=None, units=None):
    """``params`` with the ``[measurement]`` a log was read with: its own table with ``columns`` / ``units``
    (e.g. a command's ``--columns``/``--units``) over it key by key, as the readers merge them.  A file
    written from it (``calibrated.toml``) then reads the same log with no flags.

    Parameters
    ----------
    params : CMCParams
        The parameter set.
    columns, units : dict or None
        Contract name -> the log's column / unit.
    """
    import dataclasses

    old = params.extra.get("measurement") or Measurement()
    new = Measurement(columns={**old.columns, **(columns or {})}, units={**old.units, **(units or {})},
                      string_weight=old.string_weight)
    if new == Measurement():
        return params
    return dataclasses.replace(params, extra={**params.extra, "measurement": new})


def to_table(m: Measurement) -> dict:
    """The TOML table of ``m`` (only non-empty keys).

    Parameters
    ----------
    m : Measurement
        The validated table.
    """
    out = {k: dict(getattr(m, k)) for k in TABLES if getattr(m, k)}
    if m.string_weight is not None:
        out["string_weight"] = m.string_weight
    return out
