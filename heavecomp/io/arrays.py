"""Labelled arrays: campaign, fleet and monitor results as ``xarray.Dataset`` (and netCDF files).

The scientific-Python way to hand over an ensemble: N-d arrays with named coordinates and the unit
of every variable in its ``attrs["units"]``.  ``xarray`` is imported only here, when a dataset is
built (``pip install 'heavecomp[arrays]'``); netCDF is written as netCDF 3 by scipy (xarray's
``scipy`` engine: no binary library beyond the project's own dependencies).

- :func:`campaign_dataset`: dimensions ``sea_state`` (coordinates ``hs`` [m], ``tp`` [s],
  ``probability``), ``regime`` (the friction regime), ``variant`` and ``seed``; one variable per scalar
  column of ``runs.csv`` (``wob_std`` [N], ``frac_outside_band`` [-], ...); runs not simulated are NaN.
- :func:`monitor_dataset`: dimensions ``segment`` (``start``, ``end`` [s], the operating point, the
  verdict) with ``component`` (``gap_to_noise`` [noise sigma]) and ``change`` (``t``, ``onset`` [s],
  ``component``, ``size_to_noise``, ``kind``).
- :func:`fleet_dataset`: the monitor's variables over ``log`` x ``segment`` and ``log`` x ``change``
  (padded: NaN / ``""`` where a log has fewer), plus ``status``, ``duration`` per log.

:func:`write` and :func:`open_dataset` write and read them (``.nc``: netCDF 3; text variables are
stored as character arrays and come back as strings, attributes as they were).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from heavecomp.errors import InputError

#: the attribute describing the variables over an empty dimension (netCDF 3 stores none: :func:`write`)
EMPTY = "heavecomp_empty_variables"
#: the dataset formats the commands write (``--format``)
FORMATS = ("netcdf",)


def xarray():
    """The ``xarray`` module, or a one-line InputError naming the extra to install."""
    try:
        import xarray as xr
    except ImportError:
        raise InputError("labelled arrays need xarray: pip install 'heavecomp[arrays]'") from None
    return xr


# ---------------------------------------------------------------- campaign
#: runs.csv columns that index a run (the dataset's dimensions) or describe its sea state (coordinates)
CAMPAIGN_DIMS = ("sea_state", "regime", "variant", "seed")
SEA_STATE_COORDS = ("hs", "tp", "probability")


def campaign_dataset(frame, units: dict, attrs: dict | None = None):
    """A campaign's runs as a Dataset over ``sea_state`` x ``regime`` x ``variant`` x ``seed``.

    Parameters
    ----------
    frame : pandas.DataFrame
        One row per run (:func:`heavecomp.campaign.tables.runs_frame`).
    units : dict
        Column -> unit.
    attrs : dict, optional
        Dataset attributes (e.g. the campaign's name).
    """
    xr = xarray()
    df = frame.copy()
    for c in ("regime", "variant"):
        df[c] = df[c].astype(str)
    keep = [c for c in df.columns if c not in ("run_id",) and (c in CAMPAIGN_DIMS or df[c].dtype.kind in "iufb")]
    ds = xr.Dataset.from_dataframe(df[keep].set_index(list(CAMPAIGN_DIMS)))
    for c in SEA_STATE_COORDS:
        if c in ds:
            per = df.groupby("sea_state")[c].first()
            ds = ds.drop_vars(c).assign_coords({c: ("sea_state", per.reindex(ds["sea_state"].values).to_numpy())})
    for name in list(ds.variables):
        ds[name].attrs["units"] = units.get(str(name), "")
    ds["regime"].attrs["long_name"] = "friction regime"
    ds.attrs.update({"title": "heavecomp campaign runs", **(attrs or {})})
    return ds


# ---------------------------------------------------------------- monitor / fleet
SEGMENT_UNITS = {"start": "s", "end": "s", "wob_setpoint": "N", "static_stroke": "m", "static_pressure": "Pa",
                 "gap_to_noise": "noise sigma", "verdict": "", "confidence": "", "verdict_component": "",
                 "shrink": "-"}
CHANGE_UNITS = {"t": "s", "onset": "s", "component": "", "size_to_noise": "noise sigma", "kind": "",
                "wob_step": "N", "pressure_step": "Pa"}


def _segment_columns(mon: dict, components) -> dict:
    segs = mon.get("segments") or []
    out = {k: [] for k in ("start", "end", "wob_setpoint", "static_stroke", "static_pressure", "verdict",
                           "confidence", "verdict_component", "shrink")}
    gap = np.full((len(segs), len(components)), np.nan)
    for i, s in enumerate(segs):
        op = s.get("operating_point") or {}
        v = s.get("verdict") or {}
        out["start"].append(float(s["start"]))
        out["end"].append(float(s["end"]))
        for k in ("wob_setpoint", "static_stroke", "static_pressure"):
            out[k].append(float(op.get(k, np.nan)))
        out["verdict"].append(str(v.get("effect") or ""))
        out["confidence"].append(str(v.get("confidence") or ""))
        out["verdict_component"].append(str(v.get("component") or ""))
        out["shrink"].append(np.nan if v.get("shrink") is None else float(v["shrink"]))
        for j, c in enumerate(components):
            g = (s.get("gap_to_noise") or {}).get(c)
            gap[i, j] = np.nan if g is None else float(g)
    out["gap_to_noise"] = gap
    return out


def _change_columns(mon: dict) -> dict:
    ch = mon.get("changes") or []
    return {"t": [float(c["t"]) for c in ch], "onset": [float(c.get("onset", np.nan)) for c in ch],
            "component": [str(c.get("component", "")) for c in ch],
            "size_to_noise": [float(c.get("size_to_noise", np.nan)) for c in ch],
            "kind": [str(c.get("kind", "")) for c in ch],
            "wob_step": [np.nan if c.get("wob_step") is None else float(c["wob_step"]) for c in ch],
            "pressure_step": [np.nan if c.get("pressure_step") is None else float(c["pressure_step"]) for c in ch]}


def _components(mons) -> list:
    seen: dict = {}
    for m in mons:
        for s in (m or {}).get("segments") or []:
            for c in s.get("gap_to_noise") or {}:
                seen.setdefault(c, None)
    return list(seen)


def _units(ds, table):
    for name in ds.variables:
        if str(name) in table:
            ds[name].attrs["units"] = table[str(name)]
    return ds


def monitor_dataset(mon: dict, attrs: dict | None = None):
    """A monitor's result (``monitor.json``'s dict) as a Dataset over ``segment`` (x ``component``) and
    ``change``.

    Parameters
    ----------
    mon : dict
        ``MonitorResult.to_json()`` or a ``monitor.json`` read back.
    attrs : dict, optional
        Dataset attributes (e.g. the log's name).
    """
    xr = xarray()
    comps = _components([mon])
    seg = _segment_columns(mon, comps)
    ch = _change_columns(mon)
    data = {k: (("segment", "component") if k == "gap_to_noise" else ("segment",), np.asarray(v))
            for k, v in seg.items()}
    data.update({f"change_{k}": (("change",), np.asarray(v, dtype=float if k not in ("component", "kind") else str))
                 for k, v in ch.items()})
    data["log_gap_to_noise"] = (("component",), np.asarray(
        [float((mon.get("gap_to_noise") or {}).get(c, np.nan)) for c in comps]))  # over the whole log
    ds = xr.Dataset(data, coords={"segment": np.arange(len(seg["start"])), "component": np.asarray(comps, dtype=str),
                                  "change": np.arange(len(ch["t"]))})
    _units(ds, {**SEGMENT_UNITS, **{f"change_{k}": u for k, u in CHANGE_UNITS.items()},
                "log_gap_to_noise": "noise sigma"})
    ds.attrs.update({"title": "heavecomp monitor", "block_s": float(mon.get("block_s", np.nan)),
                     "duration_s": float(mon.get("duration_s", np.nan)), "sensors": " ".join(mon.get("sensors") or []),
                     **(attrs or {})})
    return ds


def fleet_dataset(logs: list, attrs: dict | None = None):
    """A fleet's results as a Dataset over ``log`` x ``segment`` (x ``component``) and ``log`` x ``change``.

    Parameters
    ----------
    logs : list of dict
        One per log: ``log`` (its key), ``status``, ``reason``, ``monitor`` (the ``monitor.json`` dict,
        or None for a failed log), as :func:`heavecomp.report.fleet.collect` gives them.
    attrs : dict, optional
        Dataset attributes.
    """
    xr = xarray()
    mons = [e.get("monitor") for e in logs]
    comps = _components(mons)
    segs = [_segment_columns(m or {}, comps) for m in mons]
    chs = [_change_columns(m or {}) for m in mons]
    ns = max([len(s["start"]) for s in segs] + [0])
    nc = max([len(c["t"]) for c in chs] + [0])

    def pad(rows, key, n, text):
        out = np.full((len(rows), n), "" if text else np.nan, dtype=object if text else float)
        for i, r in enumerate(rows):
            out[i, :len(r[key])] = r[key]
        return out.astype(str) if text else out

    data = {}
    for k in segs[0] if segs else ():
        if k == "gap_to_noise":
            g = np.full((len(segs), ns, len(comps)), np.nan)
            for i, s in enumerate(segs):
                g[i, :s[k].shape[0]] = s[k]
            data[k] = (("log", "segment", "component"), g)
        else:
            data[k] = (("log", "segment"), pad(segs, k, ns, k in ("verdict", "confidence", "verdict_component")))
    for k in chs[0] if chs else ():
        data[f"change_{k}"] = (("log", "change"), pad(chs, k, nc, k in ("component", "kind")))
    data["status"] = (("log",), np.asarray([str(e.get("status", "")) for e in logs], dtype=str))
    data["reason"] = (("log",), np.asarray([str(e.get("reason", "")) for e in logs], dtype=str))
    data["duration"] = (("log",), np.asarray([float((m or {}).get("duration_s", np.nan)) for m in mons]))
    # how far each log is from the model over the whole log (the fleet's ranking key: its largest)
    data["log_gap_to_noise"] = (("log", "component"), np.asarray(
        [[float(((m or {}).get("gap_to_noise") or {}).get(c, np.nan)) for c in comps] for m in mons]).reshape(
            len(mons), len(comps)))
    ds = xr.Dataset(data, coords={"log": np.asarray([str(e["log"]) for e in logs], dtype=str),
                                  "segment": np.arange(ns), "component": np.asarray(comps, dtype=str),
                                  "change": np.arange(nc)})
    _units(ds, {**SEGMENT_UNITS, **{f"change_{k}": u for k, u in CHANGE_UNITS.items()}, "duration": "s",
                "status": "", "reason": "", "log_gap_to_noise": "noise sigma"})
    ds.attrs.update({"title": "heavecomp fleet", **(attrs or {})})
    return ds


# ---------------------------------------------------------------- files
def write(ds, path) -> Path:
    """Write ``ds`` as netCDF 3 (xarray's scipy engine); text variables as character arrays.

    Parameters
    ----------
    ds : xarray.Dataset
        The dataset.
    path : str or Path
        The ``.nc`` file written.
    """
    path = Path(path)
    ds = ds.copy()
    for name in list(ds.variables):  # text of no character at all: one NUL-padded character (netCDF 3 has
        v = ds[name]                 # no dimension of length 0 but the unlimited one)
        if v.dtype.kind == "U" and v.size and max(len(x) for x in v.values.ravel()) == 0:
            ds[name] = v.astype("S1")
    empty = [d for d, n in ds.sizes.items() if n == 0]
    if empty:  # netCDF 3 has no empty dimension but the unlimited one: the variables over one are described
        spec = {}  # in an attribute and made again by open_dataset
        for name in list(ds.variables):
            v = ds[name]
            if any(d in empty for d in v.dims):
                spec[str(name)] = {"dims": [str(d) for d in v.dims], "shape": list(v.shape), "dtype": v.dtype.str,
                                   "attrs": dict(v.attrs), "coord": name in ds.coords}
        ds = ds.drop_vars(list(spec))
        ds.attrs[EMPTY] = json.dumps(spec)
    ds.to_netcdf(path, engine="scipy", format="NETCDF3_64BIT")
    return path


def open_dataset(path):
    """A dataset written by :func:`write`, loaded into memory (text variables as strings).

    Parameters
    ----------
    path : str or Path
        The ``.nc`` file.
    """
    xr = xarray()
    with xr.open_dataset(path, engine="scipy", mmap=False) as ds:
        out = ds.load()
    for name in list(out.variables):
        if out[name].dtype.kind in "SO":
            out[name] = out[name].astype(str)
    spec = json.loads(out.attrs.pop(EMPTY, "{}"))
    for name, v in spec.items():
        var = xr.Variable(v["dims"], np.zeros(v["shape"], dtype=np.dtype(v["dtype"])), v["attrs"])
        out = out.assign_coords({name: var}) if v["coord"] else out.assign({name: var})
    return out
