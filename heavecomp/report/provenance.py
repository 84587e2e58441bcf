"""Self-describing run folders (issue 13.4): provenance stamp, resolved parameters, units, timings.

Every command and scenario finishes its output folder with :func:`finish`:

- ``params.toml``: the parameter set as resolved and used, with a heave file copied in
  beside it (``heave.path`` then names the copy), so the folder re-runs by itself:
  ``heavecomp simulate RUN/params.toml --duration ... --out RUN2``;
- a ``provenance`` block (heavecomp version, command line, parameter file) and a
  ``units`` block (unit of every numeric entry, by key) added to each JSON result;
- ``<table>.units.csv`` beside each CSV table: ``column,unit`` (``pandas.read_csv`` reads it);
- the stamp at the end of ``report.md`` and a self-contained ``report.html`` beside it;
- wall-clock timings moved out of the JSON results into ``timings.json`` (ignored by
  git), so re-running a scenario leaves the tracked reports unchanged.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import math
import re
import shlex
import shutil
import sys
from pathlib import Path
from heavecomp.errors import ParameterError
from heavecomp.report import invocation
from heavecomp.report.html import write_html
from heavecomp.params import dumps
from heavecomp import __version__
from heavecomp.effects import CANDIDATES
from heavecomp.params.cmc import TABLES
from heavecomp.campaign.tables import UNITS as RUNS_CSV_UNITS
from heavecomp.simulate.core import CHANNEL_UNITS

log = logging.getLogger(__name__)

#: keys that hold wall-clock times (machine-dependent: never in a tracked result)
TIMING_KEY = re.compile(r"(^|_)(wall|solve_time|elapsed)(_|$)")

#: units of result keys (SI unless the key says otherwise); "-" = dimensionless
UNITS: dict[str, str] = {
    # time series channels (the CMC's own: CHANNEL_UNITS, merged below)
    "time": "s", "heave_velocity": "m/s", "heave_acceleration": "m/s^2", "velocity": "m/s",
    "pressure_a": "Pa", "pressure_b": "Pa", "accelerating": "-", "gas_pressure": "Pa",
    # simulate / closed loop metrics
    "wob_mean": "N", "wob_std": "N", "wob_min": "N", "wob_max": "N", "wob_p2p": "N", "wob_setpoint": "N",
    "stick_fraction": "-", "stick_fraction_total": "-", "n_stick": "count", "n_breakaway": "count",
    "n_reversal": "count", "event_cap_hits": "count", "event_cap_first_t": "s",
    "friction_power_min": "W", "n_negative_friction_power": "count", "stroke_max": "m", "pressure_min": "Pa",
    "pressure_max": "Pa", "heave_std": "m", "k_eff_eq14": "N/m", "stats_window": "s", "duration": "s", "dt": "s",
    "amplitude": "m", "period": "s", "ramp": "s", "hs": "m", "tp": "s", "gamma": "-", "seed": "-",
    "u_active_max": "N", "u_active_rms": "N", "fallbacks": "count", "violations_u_max": "count",
    "violations_rate": "count", "control_rate": "Hz", "solver_failures": "count", "wob_std_passive": "N",
    "sample_time_missed": "-", "solve_time_share_over_interval": "-",
    # analyse
    "k_eff_dc": "N/m", "dc_gain_heave_to_wob": "N/m", "natural_frequencies": "rad/s", "natural_periods": "s",
    "damping_ratios": "-", "damped_natural_frequencies": "rad/s", "poles": "rad/s", "wave_band_rad_s": "rad/s",
    "peak_k_eff": "N/m", "peak_omega": "rad/s", "transmissibility_at_wave_periods": "-", "frequency_points": "count",
    "x_stroke": "m", "x_stroke_velocity": "m/s", "x_lower_displacement": "m", "x_lower_velocity": "m/s",
    "u_heave": "m", "u_heave_velocity": "m/s", "u_heave_acceleration": "m/s^2", "u_u_active": "N",
    "sliding_velocity": "m/s", "viscous_coefficient": "N s/m", "omega": "rad/s", "frequency": "Hz",
    "k_eff_mag": "N/m", "k_eff_phase_deg": "deg", "transmissibility": "-", "wob_per_heave_mag": "N/m",
    "wob_per_heave_phase_deg": "deg", "stroke_per_heave_mag": "m/m", "stroke_per_heave_phase_deg": "deg",
    "pressure_per_heave_mag": "Pa/m", "pressure_per_heave_phase_deg": "deg", "tension_per_heave_mag": "N/m",
    "tension_per_heave_phase_deg": "deg", "eigenfrequencies_hz": "Hz",
    # stickslip (paper B, pneumatic)
    "D": "-", "T_f": "s", "a": "1/s", "b": "1/s^2", "c": "1/s^3", "critical_D": "-", "g": "m/s^3 per m^2",
    "omega_n": "rad/s", "zeta": "-", "u0": "m/s", "pb_eq": "Pa", "position": "m", "agreement": "-", "n": "count",
    "stick_slip_linear": "count", "stick_slip_nonlinear": "count", "end_of_stroke": "-", "stuck_time": "s",
    "t_final": "s", "t_first_breakaway": "s", "t_first_stick": "s", "t_second_breakaway": "s", "v_max": "m/s",
    "minimum_velocity_exhaust_area_m2": "m^2", "minimum_velocity_linear_m_s": "m/s",
    # diagnose
    "schema": "-", "explained": "-", "explained_joint": "-", "explained_perturbed_heave": "-",
    "explained_replay": "-", "added_explained": "-", "score": "-", "shrink": "-", "shrink_fit": "-", "margin": "-",
    "gap_to_input_envelope": "-", "predicted_shrink": "-", "windows": "s", "gap_to_noise": "-", "margin_input_noise": "-", "component_gap": "-",
    "bic": "-", "delta_bic": "-", "n_terms": "count", "nrmse": "-", "n_params": "count", "settle": "s",
    "fit": "s", "validate": "s", "segments": "s", "above": "-", "below_wave": "-", "wave": "-", "resonance": "-",
    "breakaway": "-", "sliding_accelerating": "-", "sliding_decelerating": "-",
    # campaign
    "band_exits_per_hour": "1/h", "band_half_width": "N", "bin_width": "N", "cycle_rate": "1/s",
    "dev_exceeded_1e-2": "N", "dev_exceeded_1e-3": "N", "dev_max_in_exposure": "N", "exceed_above": "-",
    "exceed_abs": "-", "exceed_peak": "-", "exposure": "s", "frac_outside_band": "-",
    "frac_outside_ratio_to_none": "-", "n_runs": "count", "p_leave_exposure": "-", "p_leave_window_empirical": "-",
    "p_leave_window_poisson": "-", "probability": "-", "probability_covered": "-", "rate": "Hz",
    "runs_resumed": "count", "runs_simulated": "count", "sea_state": "-", "share_won_back_by_eq7": "-",
    "wob_std_rms": "N", "workers": "count", "x_abs": "N", "x_signed": "N", "none": "-", "rotating_eq7": "-",
    "rotating_eq6": "-", "stribeck": "-",
    # identify (EMPS axis, seal friction)
    "C_0": "N/Pa", "C_0_se": "N/Pa", "C_p": "N/Pa", "C_p_boot": "N/Pa", "C_p_ci95": "N/Pa", "C_p_se": "N/Pa",
    "F_0": "N", "F_0_se": "N", "F_C": "N", "F_C_boot": "N", "F_C_se": "N", "trim": "-", "n_boot": "count",
    "n_files": "count", "n_strokes": "count", "strokes_negative": "count", "strokes_positive": "count",
    "ratio_measured_to_scaled": "-", "mass": "kg", "coulomb": "N", "viscous": "N s/m", "offset": "N",
    "base_mass": "kg", "base_coulomb": "N", "base_viscous": "N s/m", "base_offset": "N", "bic_fit": "-",
    "butterworth_order": "-", "decimate": "-", "cutoff": "Hz", "dead_band": "m/s", "max_abs_relative_error": "-",
    "rms_fit": "N", "rms_validate": "N", "samples": "count", "share": "-", "mean": "m/s", "hi": "m/s", "lo": "m/s",
    "theta": "-", "n_parameters": "count", "coulomb_negative": "N", "coulomb_positive": "N",
    "viscous_negative": "N s/m", "viscous_positive": "N s/m", "viscous_asymmetry": "N s/m", "lag_force": "N",
    "presliding_length": "m", "stribeck_excess": "N", "stribeck_velocity": "m/s",
    "v_min": "m/s", "area": "m^2", "change_in_uncertainties": "-", "heave_reference": "m",  # seal study settings, method sensitivity
    # equation-error diagnosis of the axis / seal (identification.plants terms; withheld-term rows)
    "direction_offset": "N", "direction_offset_pressure": "N/Pa", "friction.coulomb_force": "N",
    "friction.viscous_coefficient": "N s/m", "friction.pressure_coefficient": "N/Pa",
    "base_direction_offset": "N", "base_direction_offset_pressure": "N/Pa", "base_friction.coulomb_force": "N",
    "base_friction.viscous_coefficient": "N s/m", "base_friction.pressure_coefficient": "N/Pa",
    "fit_window": "s", "validate_window": "s", "reachable_shrink": "-", "runner_up_shrink": "-",
    "discovered_shrink": "-",
    # closed loop (heavecomp.controllers.ControllerConfig documents these units)
    "u_max": "N", "rate_max": "N/s", "horizon": "count", "q_wob": "1/N^2", "r_u": "1/N^2", "r_du": "1/N^2",
    "friction_eps": "m/s", "friction_scale": "-", "gas_stiffness_scale": "-", "kp": "-", "ki": "1/s", "kd": "s",
    "pid_tf": "s", "observer_sigma_d": "N", "sqp_iterations": "count", "predictor_order": "count",
    "predictor_window": "s", "n_control_steps": "count", "saturated_steps": "count",
    # residual statistics (forces unless under a channel, see _CHANNEL_STATS)
    "rms": "N", "rms_before": "N", "rms_after": "N", "noise_floor": "N",
}

#: key patterns -> unit (Fourier coefficients of a position-dependent force: f_cos1, fc_sin2, ...)
PATTERN_UNITS = [(re.compile(r"^fc?_(cos|sin)\d+$"), "N"),
                 # a campaign's histogram columns: samples (dev_*) or cycle peaks (peak_*) per bin
                 (re.compile(r"^(dev|peak)_(\d+|under|over)$"), "count")]

#: statistics that carry the unit of the channel named among their parents (gap.channels.stroke.rms = m)
_CHANNEL_STATS = ("rms", "rms_before", "rms_after", "rms_validate", "noise_floor")

#: key suffixes that name their unit (``F_C_N``, ``fs_Hz``, ``C_p_N_per_bar``, ...)
SUFFIX_UNITS = [("_N_per_bar", "N/bar"), ("_N_per_Pa", "N/Pa"), ("_mm_s", "mm/s"), ("_m_s", "m/s"),
                ("_rad_s", "rad/s"), ("_m2", "m^2"), ("_Hz", "Hz"), ("_hz", "Hz"), ("_kN", "kN"), ("_N", "N"),
                ("_bar", "bar"), ("_ms", "ms"), ("_s", "s"), ("_m", "m"), ("_pct", "%"), ("_deg", "deg"),
                ("_frac", "-"), ("_ratio", "-")]

#: nested blocks whose entries take the unit of the block's channel (e.g. noise.wob = N)
_CHANNEL_BLOCKS = ("noise", "operating_point", "channels")

#: blocks whose entries are dimensionless shares (diagnosis "where", Fourier weights)
_SHARE_BLOCKS = ("bands", "regimes", "frac_outside", "levels", "components")


def _param_units() -> dict[str, str]:
    """Units of parameter keys from the parameter classes' own metadata (``q(unit=...)``);
    also merges the CMC's channel units into :data:`UNITS` (imported here, not at start-up)."""


    UNITS.update(CHANNEL_UNITS)
    for k, u in RUNS_CSV_UNITS.items():  # the campaign's runs.csv columns (said once, in campaign/tables.py)
        UNITS.setdefault(k, u)
    out: dict[str, str] = {}
    try:

        for tname, cls in TABLES.items():
            for f in dataclasses.fields(cls):
                if f.metadata.get("kind") == "number":
                    out[f"{tname}.{f.name}"] = f.metadata["unit"]
                    out.setdefault(f.name, f.metadata["unit"])
    except Exception as exc:  # noqa: BLE001 - units are documentation: never fail a run over them
        log.debug("parameter units unavailable: %s", exc)
    try:

        for cand in (CANDIDATES.values() if isinstance(CANDIDATES, dict) else CANDIDATES):
            for spec in cand.describe() if hasattr(cand, "describe") else ():
                out.setdefault(spec["name"], spec["unit"])
            for k, u in getattr(cand, "feature_units", {}).items():   # equation-error coefficients
                out.setdefault(k, u)
    except Exception as exc:  # noqa: BLE001
        log.debug("effect parameter units unavailable: %s", exc)
    return out


def table_units(table: str) -> dict[str, str]:
    """Units of the number keys of the parameter table ``table`` (``"heave"``), from its classes' metadata.

    Parameters
    ----------
    table : str
        A parameter table name (a key of ``TABLES``).

    Returns
    -------
    dict
        Key -> unit.
    """
    cls = TABLES[table]
    return {f.name: f.metadata["unit"] for f in dataclasses.fields(cls) if f.metadata.get("kind") == "number"}


def unit_of(path: tuple[str, ...]) -> str | None:
    """Unit of the entry at ``path`` (keys from the JSON root), or None if unknown.

    Parameters
    ----------
    path : tuple of str
        Keys from the JSON root to the entry (a numeric last key takes its parent's unit).

    Returns
    -------
    str or None
    """
    global _PARAM_UNITS
    if not _PARAM_UNITS:
        _PARAM_UNITS = _param_units()
    key = str(path[-1])
    if len(path) > 1 and re.fullmatch(r"[-+0-9.eE]+", key):  # e.g. transmissibility_at_wave_periods.12
        return unit_of(path[:-1])
    parents = [str(p) for p in path[:-1]]
    if key in _CHANNEL_STATS:
        for p in reversed(parents):
            if p in ("wob", "stroke", "pressure", "heave"):
                return UNITS[p]
    for pat, unit in PATTERN_UNITS:
        if pat.match(key):
            return unit
    for block in _SHARE_BLOCKS:
        if parents and parents[-1] == block:
            return "-"
    if parents and parents[-1] == "where" and key in ("offset", "trend"):  # shares of the squared residual
        return "-"
    if len(parents) >= 1:
        dotted = f"{parents[-1]}.{key}"
        if dotted in _PARAM_UNITS:
            return _PARAM_UNITS[dotted]
    if key in UNITS:
        return UNITS[key]
    if "." in key and key in _PARAM_UNITS:
        return _PARAM_UNITS[key]
    for suffix, unit in SUFFIX_UNITS:
        if key.endswith(suffix):
            return unit
    if key in _PARAM_UNITS:
        return _PARAM_UNITS[key]
    for block in _CHANNEL_BLOCKS:  # e.g. noise.wob -> unit of the wob channel
        if block in parents:
            return UNITS.get(key)
    return None


_PARAM_UNITS: dict[str, str] = {}


def _effect_units(name: str):
    """``(feature_units, shape unit)`` of the effect ``name``'s equation-error fit, or None."""
    cls = CANDIDATES.get(name) if isinstance(CANDIDATES, dict) else None
    if cls is None:
        return None
    shape = getattr(cls, "feature_shape", None)
    return dict(getattr(cls, "feature_units", {})), (shape[1] if shape else None)


#: key of the block a producer puts into a result dict beside its values: ``{entry: unit}``
#: (``"-"`` dimensionless, ``"count"``); see :func:`declare_units`
UNITS_KEY = "_units"


def declare_units(block: dict, units) -> dict:
    """Attach the units of ``block``'s entries where the values are made; returns ``block``.

    ``units`` maps an entry's key to its unit.  The unit of a number entry is its own; of a list,
    every number in it; of a nested dict, every number inside that declares nothing itself.  The
    declaration wins over any unit guessed from a key's name (:func:`unit_of`), so a result cannot
    be given a wrong unit by a name it shares with another quantity (a stroke ``offset`` in m
    beside a force ``offset`` in N).  :func:`annotate_json` turns the declarations into the
    ``units`` block and removes them from the written JSON.

    Parameters
    ----------
    block : dict
        A result block, changed in place (its :data:`UNITS_KEY` entry is added or extended).
    units : dict or iterable of (str, str) pairs
        Entry key -> unit.
    """
    block.setdefault(UNITS_KEY, {}).update({str(k): str(u) for k, u in dict(units).items()})
    return block


def strip_declared(obj):
    """Copy of a result without its :data:`UNITS_KEY` blocks.

    Parameters
    ----------
    obj : dict, list or scalar
        A JSON-like result.

    Returns
    -------
    dict, list or scalar
    """
    if isinstance(obj, dict):
        return {k: strip_declared(v) for k, v in obj.items() if k != UNITS_KEY}
    if isinstance(obj, list):
        return [strip_declared(v) for v in obj]
    return obj


def undeclared(obj, path: tuple = ()) -> list[str]:
    """Dotted paths of the numbers of a result whose unit no producer declared (:func:`declare_units`).

    Parameters
    ----------
    obj : dict, list or scalar
        A JSON-like result.
    path : tuple of str
        Keys of ``obj`` from the root (the prefix of the paths returned).

    Returns
    -------
    list of str
        Sorted, without repeats.
    """
    out: list[str] = []

    def walk(x, p, has):
        if isinstance(x, dict):
            decl = x.get(UNITS_KEY) if isinstance(x.get(UNITS_KEY), dict) else {}
            for k, v in x.items():
                if k not in (UNITS_KEY, "units", "provenance"):
                    walk(v, p + (str(k),), has or str(k) in decl)
        elif isinstance(x, (list, tuple)):
            for v in x:
                walk(v, p, has)
        elif isinstance(x, (int, float)) and not isinstance(x, bool) and not has:
            out.append(".".join(p))

    walk(obj, tuple(path), False)
    return sorted(set(out))


def units_of(obj, path: tuple = ()) -> tuple[dict[str, str], list[str]]:
    """``({key: unit}, [dotted paths of numbers with no known unit])`` for a JSON-like result.

    A unit declared beside the value (:func:`declare_units`) wins; otherwise it is looked up
    by the key's name and its parents (:func:`unit_of`).

    Parameters
    ----------
    obj : dict, list or scalar
        A JSON-like result.
    path : tuple of str
        Keys of ``obj`` from the root.
    """
    global _PARAM_UNITS
    if not _PARAM_UNITS:
        _PARAM_UNITS = _param_units()
    units: dict[str, str] = {}
    missing: list[str] = []

    def walk(x, p, own=None, coef=None, declared=None):
        if isinstance(x, dict) and (declared is not None or isinstance(x.get(UNITS_KEY), dict)):
            decl = x.get(UNITS_KEY) if isinstance(x.get(UNITS_KEY), dict) else {}
            for k, v in x.items():  # declared beside the value, or by an enclosing block
                if k not in (UNITS_KEY, "units", "provenance"):
                    u = decl.get(str(k), declared)
                    walk(v, p + (str(k),), u, declared=u)
            return
        if isinstance(x, dict):
            # an entry that names its own unit (e.g. a fitted parameter at its bound: value, bound, unit;
            # a component row: rms and noise in its equation's unit)
            own_unit = x.get("unit") if isinstance(x.get("unit"), str) else None
            # an equation-error fit of one effect: its coefficients and shape in the effect's own units
            eff = _effect_units(x.get("effect")) if isinstance(x.get("effect"), str) else None
            for k, v in x.items():
                if k in ("units", "provenance"):
                    continue
                if coef is not None:
                    walk(v, p + (str(k),), coef.get(str(k)))
                elif eff is not None and k == "coefficients" and isinstance(v, dict):
                    walk(v, p + (str(k),), None, eff[0])
                elif eff is not None and k == "shape" and eff[1]:
                    walk(v, p + (str(k),), eff[1])
                else:
                    walk(v, p + (str(k),), own_unit if k in ("value", "bound", "rms", "noise", "stderr") else None)
        elif isinstance(x, (list, tuple)):
            for v in x:
                walk(v, p, own, declared=declared)
        elif isinstance(x, (int, float)) and not isinstance(x, bool) and p:
            u = own or unit_of(p)
            name = p[-1] if not p[-1].isdigit() else ".".join(p[-2:])
            if u is None:
                missing.append(".".join(p))
            elif units.get(name, u) != u:  # same key, different unit in another block
                units[".".join(p[-2:])] = u
            else:
                units[name] = u

    walk(obj, tuple(path))
    return dict(sorted(units.items())), sorted(set(missing))


def split_timings(obj):
    """``(result without wall-clock entries, the timings)`` (nested like the result).

    Parameters
    ----------
    obj : dict, list or scalar
        A JSON-like result; a wall-clock entry is one whose key matches ``TIMING_KEY``.

    Returns
    -------
    (dict, list or scalar; dict, list or None)
    """
    if isinstance(obj, dict):
        keep, times = {}, {}
        for k, v in obj.items():
            if TIMING_KEY.search(str(k)):
                times[k] = v
                continue
            kv, tv = split_timings(v)
            keep[k] = kv
            if tv:
                times[k] = tv
        return keep, times
    if isinstance(obj, list):
        pairs = [split_timings(v) for v in obj]
        times = [t for _, t in pairs]
        return [k for k, _ in pairs], (times if any(times) else None)
    return obj, None


def _clean(x, digits: int | None = None):
    """JSON-ready copy: NaN/inf -> None, numpy scalars -> Python, tuples -> lists, keys -> str;
    the report package's one JSON cleaner.

    Parameters
    ----------
    x : dict, list, tuple or scalar
        A JSON-like value, possibly holding numpy scalars.
    digits : int, optional
        Round every finite float to this many significant digits (none: floats kept exact).

    Returns
    -------
    dict, list or scalar
    """
    if isinstance(x, float):
        if not math.isfinite(x):
            return None
        if digits:
            return float(f"{x:.{digits}g}")
    if isinstance(x, dict):
        return {str(k): _clean(v, digits) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_clean(v, digits) for v in x]
    if hasattr(x, "item") and not isinstance(x, (str, bytes)):
        try:
            return _clean(x.item(), digits)
        except (ValueError, AttributeError):
            pass
    return x


def command_line() -> str:
    """The command being run, as a shell line (``heavecomp simulate p.toml ...``)."""
    argv = invocation.COMMAND if invocation.COMMAND is not None else ["python", *sys.argv]
    return shlex.join(str(a) for a in argv)


def stamp(params_file: str | None = None, **extra) -> dict:
    """The provenance block: heavecomp version, command line, parameter file (no dates or host:
    a re-run writes the same bytes).

    Parameters
    ----------
    params_file : str or None
        The parameter file written into the output folder (its name).
    **extra : dict
        Further entries of the block.

    Returns
    -------
    dict
    """

    s = {"heavecomp_version": __version__, "command": command_line()}
    if params_file:
        s["parameters"] = params_file
    s.update(extra)
    return s


def stamp_markdown(st: dict) -> str:
    """The stamp as one Markdown paragraph for reports.

    Parameters
    ----------
    st : dict
        The stamp (:func:`stamp`).

    Returns
    -------
    str
    """
    parts = [f"heavecomp {st['heavecomp_version']}", f"command `{st['command']}`"]
    if st.get("parameters"):
        parts.append(f"parameters `{st['parameters']}`")
    return "*Provenance: " + "; ".join(parts) + ".*"


def heave_file(params) -> Path | None:
    """The heave file a parameter set names (``heave.kind = "file"``), resolved against its folder.

    Parameters
    ----------
    params : heavecomp.params.CMCParams
        The parameter set.

    Returns
    -------
    pathlib.Path or None
        None when the heave is not read from a file.
    """
    heave = getattr(params, "heave", None)
    if heave is None or getattr(heave, "kind", None) != "file" or not heave.path:
        return None
    src = Path(heave.path)
    if not src.is_absolute() and params.base_dir is not None:
        src = Path(params.base_dir) / src
    return src


def write_params(out_dir, params, name: str = "params.toml", *, heave_used: bool = True) -> Path:
    """Write the resolved parameter set; a heave file is copied in beside it so the folder re-runs
    by itself (``heave.path`` names the copy).

    ``heave_used=False`` (a command that takes no heave from the parameter file, e.g. the diagnosis,
    whose heave is the measured run's): a ``[heave]`` table naming a file is left out -- the file is
    neither copied nor recorded, and need not exist.

    Parameters
    ----------
    out_dir : str or os.PathLike
        Output folder (created if missing).
    params : heavecomp.params.CMCParams
        The parameter set.
    name : str
        File name of the set.
    heave_used : bool
        The command takes its heave from ``params``.

    Returns
    -------
    pathlib.Path
        The parameter file written.

    Raises
    ------
    heavecomp.errors.ParameterError
        The heave file the set names does not exist (``heave_used`` only).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    src = heave_file(params)
    if src is not None and not heave_used:
        params = params.replace(heave=None)
    elif src is not None:
        copy = out / f"heave{src.suffix or '.csv'}"
        if not src.is_file():
            raise ParameterError(f"heave.path: {src} is not a file (the heave input of this run)")
        if src.resolve() != copy.resolve():
            shutil.copyfile(src, copy)
        params = params.replace(heave={"path": copy.name})

    path = out / name
    path.write_text(dumps(params, header="resolved parameter set of this run (heavecomp; re-run from this file)"),
                    encoding="utf-8")
    return path


def write_units_csv(csv_path, columns, units: dict | None = None) -> Path:
    """``<name>.units.csv`` beside a CSV table: one row per column, ``column,unit``.

    Parameters
    ----------
    csv_path : str or os.PathLike
        The CSV table.
    columns : sequence of str
        Its columns, in order.
    units : dict or None
        Column -> unit, winning over the unit looked up by name (:func:`unit_of`).

    Returns
    -------
    pathlib.Path
        The units file written.

    Raises
    ------
    KeyError
        A column whose unit is neither given nor known.
    """
    csv_path = Path(csv_path)
    units = units or {}
    rows = []
    for c in columns:
        u = units.get(c) or unit_of((c,))
        if u is None:
            raise KeyError(f"no unit known for column {c!r} of {csv_path.name}")
        rows.append(f"{c},{u}")
    path = csv_path.with_name(csv_path.stem + ".units.csv")
    path.write_text("column,unit\n" + "\n".join(rows) + "\n")
    return path


#: significant digits kept in JSON results: far below any physical resolution, and above the
#: last-bit noise between machines, BLAS builds or the JIT and ahead-of-time steppers, so a
#: re-run elsewhere writes the same bytes
DIGITS = 12


def round_floats(x, digits: int = DIGITS):
    """Copy of a JSON-like value with every float rounded to ``digits`` significant digits.

    Parameters
    ----------
    x : dict, list or scalar
        A JSON-like value.
    digits : int
        Significant digits.

    Returns
    -------
    dict, list or scalar
    """
    if isinstance(x, float):
        return float(f"{x:.{digits}g}")
    if isinstance(x, dict):
        return {k: round_floats(v, digits) for k, v in x.items()}
    if isinstance(x, list):
        return [round_floats(v, digits) for v in x]
    return x


def annotate_json(path, st: dict, *, indent: int | None = 2) -> dict:
    """Move timings out of a JSON result into ``timings.json``; add ``provenance`` and ``units``;
    round floats to :data:`DIGITS` significant digits.

    Parameters
    ----------
    path : str or os.PathLike
        The JSON result, rewritten in place.
    st : dict
        The provenance stamp (:func:`stamp`).
    indent : int or None
        JSON indentation (None: one line).

    Returns
    -------
    dict or list
        The data as written.
    """

    path = Path(path)
    data = json.loads(path.read_text())
    data, times = split_timings(data)
    if times:
        tpath = path.with_name("timings.json")
        old = json.loads(tpath.read_text()) if tpath.exists() else {}
        old[path.name] = times
        tpath.write_text(json.dumps(_clean(old), indent=2) + "\n")
    if isinstance(data, dict):
        units, missing = units_of(data)
        if missing:
            log.debug("%s: no unit known for %s", path.name, ", ".join(missing))
        data = strip_declared(data)
        data["provenance"] = st
        data["units"] = units
    path.write_text(json.dumps(round_floats(_clean(data)), indent=indent) + "\n")
    return data


def stamp_report(md_path, st: dict) -> Path:
    """End the Markdown report with the stamp (replacing an older one) and write its HTML twin.

    Parameters
    ----------
    md_path : str or os.PathLike
        The Markdown report, rewritten in place.
    st : dict
        The provenance stamp (:func:`stamp`).

    Returns
    -------
    pathlib.Path
        The HTML report written beside it.
    """

    md_path = Path(md_path)
    lines = [ln for ln in md_path.read_text(encoding="utf-8").rstrip("\n").split("\n")
             if not ln.startswith("*Provenance: ")]
    while lines and not lines[-1].strip():
        lines.pop()
    md_path.write_text("\n".join(lines) + "\n\n" + stamp_markdown(st) + "\n", encoding="utf-8")
    return write_html(md_path)


def finish(out_dir, *, params=None, params_name: str = "params.toml", params_file: str | None = None,
           json_files=("metrics.json",), csv_files=(), report: str = "report.md", heave_used: bool = True,
           **extra) -> dict:
    """Make ``out_dir`` self-describing (see the module docstring); returns the stamp.

    ``params`` (a CMC parameter set) is written as ``params_name``; a command that wrote its
    own parameter file (e.g. paper B's pneumatic set) names it with ``params_file``.
    ``heave_used=False``: the command took no heave from ``params`` (see :func:`write_params`).

    Parameters
    ----------
    out_dir : str or os.PathLike
        The output folder.
    params : heavecomp.params.CMCParams or None
        The parameter set to write (None: none).
    params_name : str
        Its file name.
    params_file : str or None
        A parameter file the command wrote itself (used when ``params`` is None).
    json_files : sequence of str
        JSON results to annotate (:func:`annotate_json`), where present.
    csv_files : sequence of str
        CSV tables that get a units file (:func:`write_units_csv`), where present.
    report : str or None
        The Markdown report to stamp, where present.
    heave_used : bool
        The command takes its heave from ``params``.
    **extra : dict
        Further entries of the stamp.

    Returns
    -------
    dict
    """
    out = Path(out_dir)
    if params is not None:
        params_file = write_params(out, params, params_name, heave_used=heave_used).name
    st = stamp(params_file, **extra)
    for name in json_files:
        if (out / name).exists():
            annotate_json(out / name, st, indent=None if name == "statistics.json" else 2)
    for name in csv_files:
        p = out / name
        if p.exists():
            with p.open() as fh:
                header = fh.readline().strip().split(",")
            write_units_csv(p, header)
    if report and (out / report).exists():
        stamp_report(out / report, st)
    return st
