"""Tidy pandas tables of a campaign's ``runs.csv`` (pandas imported only here).

``runs.csv`` is the campaign's resumable store: one row per run, scalar results followed by
the two histograms as wide ``dev_*`` / ``peak_*`` count columns.  For analysis it is split into

- :func:`runs_frame`: one row per run, scalar columns with proper dtypes (counts and seeds as
  integers, regime and variant as categories), units in ``df.attrs["units"]``;
- :func:`histograms_frame`: the histograms in long form, one row per (run, histogram, bin) with
  the bin's edges in N and an integer count.

``outputs.format = "parquet"`` writes both (``runs.parquet``, ``histograms.parquet``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from heavecomp.campaign.execute import TABLE, read_table
from heavecomp.errors import ParameterError
from heavecomp.io.arrays import campaign_dataset

#: columns holding whole numbers (stored as float64 by the CSV reader)
INT_COLUMNS = ("sea_state", "seed", "n_samples", "n_band_exits", "n_cycles", "n_stick", "n_breakaway", "n_reversal")
CATEGORY_COLUMNS = ("regime", "variant")
#: units of the scalar columns of runs.csv
UNITS = {"run_id": "", "sea_state": "-", "hs": "m", "tp": "s", "probability": "-", "regime": "", "variant": "",
         "seed": "-", "duration": "s", "dt": "s", "stats_start": "s", "n_samples": "count", "wob_setpoint": "N",
         "band_half_width": "N", "wob_mean": "N", "wob_std": "N", "wob_min": "N", "wob_max": "N",
         "stick_fraction": "-", "stroke_max": "m", "pressure_min": "Pa", "pressure_max": "Pa",
         "frac_outside_band": "-", "n_band_exits": "count", "liftoff_fraction": "-", "n_cycles": "count",
         "heave_hs": "m", "n_stick": "count", "n_breakaway": "count", "n_reversal": "count", "batch_wall_s": "s"}


def _is_hist(name: str) -> bool:
    return name.startswith("dev_") or name.startswith("peak_")


def _table(table) -> dict:
    """``table`` as read by :func:`heavecomp.campaign.execute.read_table`: a dict of columns passes
    through; a campaign folder or its ``runs.csv`` is read."""
    if isinstance(table, dict):
        return table
    if isinstance(table, (str, Path)):
        p = Path(table)
        return read_table(p / TABLE if p.is_dir() or not p.suffix else p)
    raise ParameterError(f"campaign table: expected a campaign folder, its runs.csv or read_table()'s dict, "
                         f"got {type(table).__name__}")


def runs_frame(table):
    """One row per run (scalar columns only), integers as ``int64``, regime/variant as categories.

    ``table``: a campaign folder (``"camp/"``), its ``runs.csv``, or the dict of
    :func:`heavecomp.campaign.execute.read_table`.

    Parameters
    ----------
    table : str or os.PathLike or dict
        A campaign folder, its ``runs.csv``, or the columns of
        :func:`heavecomp.campaign.execute.read_table`.

    Returns
    -------
    pandas.DataFrame
        ``df.attrs["units"]``: column -> unit.

    Raises
    ------
    ValueError
        An integer column holds a value that is not a whole number.
    """
    import pandas as pd

    table = _table(table)
    data = {}
    for k, v in table.items():
        if _is_hist(k):
            continue
        if k in INT_COLUMNS:
            arr = np.asarray(v, dtype=float)
            if not np.all(np.isfinite(arr) & (arr == np.round(arr))):
                raise ValueError(f"runs.csv column '{k}': not whole numbers")
            data[k] = arr.astype(np.int64)
        elif k in CATEGORY_COLUMNS:
            data[k] = pd.Categorical(list(v))
        elif np.asarray(v).dtype == object:
            data[k] = pd.array(list(v), dtype="string")
        else:
            data[k] = np.asarray(v, dtype=float)
    df = pd.DataFrame(data)
    df.attrs["units"] = {k: UNITS.get(k, "") for k in df.columns}
    return df


def to_xarray(table, *, name: str | None = None):
    """The runs as an ``xarray.Dataset`` (:func:`heavecomp.io.arrays.campaign_dataset`): dimensions
    ``sea_state`` (coordinates ``hs``, ``tp``, ``probability``), ``regime`` (friction regime), ``variant``,
    ``seed``; one variable per scalar column of :func:`runs_frame`, its unit in ``attrs["units"]``.

    Parameters
    ----------
    table : str or os.PathLike or dict
        As :func:`runs_frame`'s.
    name : str, optional
        The campaign's name (``attrs["campaign"]``).
    """
    return campaign_dataset(runs_frame(table), UNITS, {"campaign": name} if name else None)


def histograms_frame(table: dict, deviation_max: float, bins: int):
    """The dW and cycle-peak histograms in long form.

    Columns: ``run_id``; ``histogram`` (``"deviation"``: WOB - W_0, ``"cycle_peak"``: max |WOB - W_0|
    between zero up-crossings); ``bin`` (int, -1 = underflow); ``lower_N``, ``upper_N`` (bin edges [N],
    +-inf for the overflow bins); ``count`` (int64).  ``table`` as for :func:`runs_frame`.

    Parameters
    ----------
    table : str or os.PathLike or dict
        As for :func:`runs_frame`.
    deviation_max : float [N]
        Largest |WOB - W_0| the histograms cover (``outputs.deviation_max``).
    bins : int
        Bins of the deviation histogram (``outputs.bins``).

    Returns
    -------
    pandas.DataFrame

    Raises
    ------
    ValueError
        A histogram column for ``bins`` is missing.
    """
    import pandas as pd

    table = _table(table)
    from heavecomp.campaign.batch import hist_columns

    dev_cols, pk_cols = hist_columns(bins)
    w = 2.0 * deviation_max / bins
    dev_lo = np.concatenate([[-np.inf], -deviation_max + w * np.arange(bins), [deviation_max]])
    dev_hi = np.concatenate([[-deviation_max], -deviation_max + w * np.arange(1, bins + 1), [np.inf]])
    nbp = bins // 2
    wp = deviation_max / nbp
    pk_lo = np.concatenate([wp * np.arange(nbp), [deviation_max]])
    pk_hi = np.concatenate([wp * np.arange(1, nbp + 1), [np.inf]])
    run_id = np.asarray(table["run_id"], dtype=object)
    parts = []
    for kind, cols, lo, hi, first in (("deviation", dev_cols, dev_lo, dev_hi, -1), ("cycle_peak", pk_cols, pk_lo, pk_hi, 0)):
        missing = [c for c in cols if c not in table]
        if missing:
            raise ValueError(f"runs.csv has no column '{missing[0]}' (bins = {bins}?)")
        counts = np.column_stack([np.asarray(table[c], dtype=float) for c in cols])  # (runs, bins)
        n_run, n_bin = counts.shape
        parts.append(pd.DataFrame({
            "run_id": pd.array(np.repeat(run_id, n_bin), dtype="string"),
            "histogram": kind,
            "bin": np.tile(np.arange(first, first + n_bin), n_run).astype(np.int64),
            "lower_N": np.tile(lo, n_run), "upper_N": np.tile(hi, n_run),
            "count": counts.ravel().astype(np.int64),
        }))
    df = pd.concat(parts, ignore_index=True)
    df["histogram"] = pd.Categorical(df["histogram"], categories=["deviation", "cycle_peak"])
    df.attrs["units"] = {"lower_N": "N", "upper_N": "N", "count": "count", "bin": "-"}
    return df


def check_parquet() -> None:
    """Fail early (one line, exit 2) when pandas/pyarrow are missing for ``outputs.format = "parquet"``."""

    try:
        import pandas  # noqa: F401
        import pyarrow  # noqa: F401
    except ImportError:
        raise ParameterError("outputs.format = \"parquet\": needs pandas and pyarrow "
                             "(pip install heavecomp[pandas]), or use \"csv\"") from None


def export_parquet(table: dict, out_dir, deviation_max: float, bins: int) -> tuple[Path, Path]:
    """Write ``runs.parquet`` and ``histograms.parquet`` (tidy, typed) into ``out_dir``.

    Parameters
    ----------
    table : str or os.PathLike or dict
        As for :func:`runs_frame`.
    out_dir : str or os.PathLike
        Existing folder the two files go into.
    deviation_max : float [N]
        Largest |WOB - W_0| the histograms cover.
    bins : int
        Bins of the deviation histogram.

    Returns
    -------
    (pathlib.Path, pathlib.Path)
        ``runs.parquet`` and ``histograms.parquet``.
    """
    check_parquet()
    out = Path(out_dir)
    runs, hists = runs_frame(table), histograms_frame(table, deviation_max, bins)
    p1, p2 = out / "runs.parquet", out / "histograms.parquet"
    runs.to_parquet(p1, index=False)
    hists.to_parquet(p2, index=False)
    return p1, p2
