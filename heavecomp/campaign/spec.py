"""Campaign definition: a TOML file -> :class:`Campaign` -> the list of runs.

A campaign is every sea state of a scatter diagram (platform-heave H_s x T_p
with occurrence probabilities) x friction regimes x parameter variants x seeds.
The file is parsed strictly (unknown key, missing key, wrong type, bad value ->
:class:`~heavecomp.errors.ParameterError` naming the key).  See
``docs/campaign.md`` for the format and ``default_campaign.toml`` beside this
module for an example.

The JONSWAP parameters describe the **platform heave** spectrum directly
(``cmc-reference.md``), so the scatter diagram is in platform-heave terms, not
sea-surface terms.
"""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

from heavecomp.errors import ParameterError, did_you_mean
from heavecomp.params.core import choice, from_table, q, read_text, text
from heavecomp.params import dumps, from_dict, SETS
from heavecomp.params import load as load_params
from heavecomp.params.cmc import TABLES
from heavecomp.effects.spec import plant_effects

DEFAULT_FILE = Path(__file__).with_name("default_campaign.toml")
REGIMES = ("none", "stribeck", "rotating_eq6", "rotating_eq7")
TABLE_NAMES = ("campaign", "scatter", "band", "outputs", "variations")


@dataclass(frozen=True, kw_only=True)
class Settings:
    """``[campaign]``: what every run shares."""

    name: str = text("campaign", doc="label used in reports")
    base: str = text("paper_a", doc="named parameter set (paper_a) or a CMC parameter TOML (relative to this file)")
    duration: float = q(unit="s", bounds=(1.0, 1e6), doc="simulated time per run (including the fade-in)")
    seeds: int = q(1, "-", bounds=(1, 100000), integer=True, doc="random-phase realisations per sea state")
    seed_offset: int = q(0, "-", bounds=(0, 2**31), integer=True, doc="first JONSWAP seed")
    gamma: float = q(3.3, "-", bounds=(1.0, 10.0), symbol="gamma", doc="JONSWAP peak enhancement")
    ramp_periods: float = q(2.0, "-", bounds=(0.0, 100.0), doc="fade-in length in peak periods (excluded from statistics)")
    rate: float = q(20.0, "Hz", bounds=(0.1, 1000.0), open_low=True, doc="statistics sampling rate (WOB samples)")
    chunk_size: int = q(8, "-", bounds=(1, 10000), integer=True, doc="runs per task (one task = one batch call)")


@dataclass(frozen=True, kw_only=True)
class Band:
    """``[band]``: WOB tolerance band around the set-point W_0."""

    tolerance: float = q(None, "N", bounds=(0.0, 1e8), open_low=True, doc="half width +-dW [N]")
    relative: float = q(None, "-", bounds=(0.0, 10.0), open_low=True, doc="half width as a fraction of W_0")
    exposure: float = q(3600.0, "s", bounds=(1.0, 1e9), doc="exposure time for P(leave the band within it)")

    def __post_init__(self):
        if (self.tolerance is None) == (self.relative is None):
            raise ParameterError("band.tolerance: give exactly one of band.tolerance [N] or band.relative [-]")

    def half_width(self, wob_setpoint: float) -> float:
        """Half width of the band [N] for a set-point W_0 [N]."""
        return self.tolerance if self.tolerance is not None else self.relative * wob_setpoint


@dataclass(frozen=True, kw_only=True)
class Outputs:
    """``[outputs]``: per-run histograms and the table format."""

    deviation_max: float = q(150e3, "N", bounds=(0.0, 1e8), open_low=True,
                             doc="histogram range of WOB - W_0: [-deviation_max, +deviation_max]")
    bins: int = q(120, "-", bounds=(2, 10000), integer=True, doc="histogram bins over that range (even)")
    format: str = choice(("csv", "parquet"), "csv", doc="table format of the final export (runs.csv always kept)")
    figures: bool = dataclasses.field(default=True, metadata=dict(kind="bool"))

    def __post_init__(self):
        if self.bins % 2:
            raise ParameterError(f"outputs.bins: must be even (bins of |WOB - W_0| use half of them), got {self.bins}")


@dataclass(frozen=True)
class Scatter:
    """``[scatter]``: H_s [m] x T_p [s] grid of platform heave with probabilities."""

    hs: tuple
    tp: tuple
    probability: tuple  # rows = hs, columns = tp
    note: str = ""

    def cells(self):
        """Non-zero cells as (index, hs, tp, probability), row-major."""
        k = 0
        for i, h in enumerate(self.hs):
            for j, t in enumerate(self.tp):
                p = self.probability[i][j]
                if p > 0:
                    yield k, h, t, p
                k += 1


@dataclass(frozen=True)
class Variant:
    """One parameter variant: ``{"table.key": value}`` overrides of the base set."""

    name: str
    overrides: tuple  # ((dotted key, value), ...)


@dataclass(frozen=True)
class Run:
    """One simulation of the campaign (a row of the results table)."""

    run_id: str
    sea_state: int
    hs: float
    tp: float
    probability: float
    regime: str
    variant: str
    seed: int


@dataclass(frozen=True)
class Campaign:
    """A validated campaign (picklable: it travels to process/Dask workers)."""

    settings: Settings
    scatter: Scatter
    regimes: tuple
    band: Band
    outputs: Outputs
    variants: tuple
    base_dir: str | None
    source_text: str = ""

    # ---------------------------------------------------------------- runs
    def runs(self) -> list[Run]:
        """Every run, in a fixed order; the JONSWAP seed depends only on the sea
        state and the seed index, so regimes and variants see the *same* heave
        (paired comparison)."""
        s = self.settings
        out = []
        for k, hs, tp, prob in self.scatter.cells():
            for i in range(s.seeds):
                seed = s.seed_offset + k * s.seeds + i
                for var in self.variants:
                    for reg in self.regimes:
                        rid = f"ss{k:04d}-{reg}-{var.name}-s{seed}"
                        out.append(Run(rid, k, float(hs), float(tp), float(prob), reg, var.name, seed))
        return out

    def variant(self, name: str) -> Variant:
        for v in self.variants:
            if v.name == name:
                return v
        raise KeyError(name)

    def fingerprint(self) -> str:
        """Hash of everything that changes a run's numbers (not chunk size/format)."""
        d = {"settings": {k: v for k, v in dataclasses.asdict(self.settings).items() if k not in ("chunk_size", "name")},
             "scatter": dataclasses.asdict(self.scatter) | {"note": ""}, "regimes": self.regimes,
             "band": dataclasses.asdict(self.band), "variants": [dataclasses.asdict(v) for v in self.variants],
             "bins": [self.outputs.deviation_max, self.outputs.bins], "base": self.base_text()}
        return hashlib.sha256(json.dumps(d, sort_keys=True, default=str).encode()).hexdigest()[:16]

    def base_text(self) -> str:
        return dumps(self.base_params())

    # ---------------------------------------------------------------- parameters
    def base_params(self, regime: str | None = None):
        """The base CMC parameter set (named set or file).

        A named set is built for the regime (``paper_a("rotating_eq7")`` carries
        the set's documented v_t); a file must itself hold every key the
        campaign's regimes need (e.g. ``friction.tangential_velocity``).
        """
        b = self.settings.base
        if b in SETS:
            if regime is not None:
                try:
                    return SETS[b](regime)
                except TypeError:
                    pass
            return SETS[b]()
        path = Path(b)
        if not path.is_absolute() and self.base_dir:
            path = Path(self.base_dir) / path
        if not path.is_file():
            raise ParameterError(f"campaign.base: not a named set ({', '.join(SETS)}) nor a file: {b}")
        params = load_params(path)
        if plant_effects(params):  # checked strictly; the batch stepper is the nominal CMC's: refuse, never ignore
            raise ParameterError(f"campaign.base: {path.name} has plant effects in [[effects]] "
                                 f"({', '.join(n for n, _ in params.effects)}); the campaign's batch stepper runs the "
                                 "nominal CMC only: simulate such a model with `simulate`")
        return params

    def params_for(self, run: Run, base=None):
        """CMC parameters of one run: base + variant overrides + regime + JONSWAP heave."""
        if base is None or (self.settings.base in _named_sets()):
            base = self.base_params(run.regime)
        d = base.to_dict()
        for key, value in self.variant(run.variant).overrides:
            t, k = key.split(".")
            d.setdefault(t, {})[k] = value
        d["friction"] = dict(d["friction"], model=run.regime)
        d["heave"] = {"kind": "jonswap", "hs": run.hs, "tp": run.tp, "gamma": self.settings.gamma,
                      "seed": int(run.seed), "ramp": self.settings.ramp_periods * run.tp}
        return from_dict(d, base_dir=base.base_dir)


def _named_sets():
    return SETS


# -------------------------------------------------------------------- parsing
def _number_list(value, key, *, positive=True) -> tuple:
    if not isinstance(value, list) or not value:
        raise ParameterError(f"{key}: expected a non-empty list of numbers")
    out = []
    for x in value:
        if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
            raise ParameterError(f"{key}: expected finite numbers, got {x!r}")
        if positive and x <= 0:
            raise ParameterError(f"{key}: values must be > 0, got {x!r}")
        out.append(float(x))
    return tuple(out)


def _parse_scatter(t: Mapping[str, Any]) -> Scatter:
    for key in t:
        if key not in ("hs", "tp", "probability", "note"):
            raise ParameterError(f"scatter.{key}: unknown key{did_you_mean(key, ['hs', 'tp', 'probability', 'note'])}")
    for key in ("hs", "tp", "probability"):
        if key not in t:
            raise ParameterError(f"scatter.{key}: missing required key")
    hs = _number_list(t["hs"], "scatter.hs")
    tp = _number_list(t["tp"], "scatter.tp")
    if max(hs) > 30:
        raise ParameterError(f"scatter.hs: platform heave H_s over 30 m ({max(hs):g}) — is it in metres?")
    if min(tp) < 1 or max(tp) > 40:
        raise ParameterError("scatter.tp: peak periods must lie in [1, 40] s")
    P = t["probability"]
    if not isinstance(P, list) or len(P) != len(hs):
        raise ParameterError(f"scatter.probability: expected {len(hs)} rows (one per scatter.hs value)")
    rows = []
    for i, row in enumerate(P):
        if not isinstance(row, list) or len(row) != len(tp):
            raise ParameterError(f"scatter.probability: row {i + 1} must have {len(tp)} values (one per scatter.tp value)")
        r = _number_list(row, f"scatter.probability row {i + 1}", positive=False)
        if min(r) < 0:
            raise ParameterError(f"scatter.probability: row {i + 1} has a negative probability")
        rows.append(r)
    total = sum(map(sum, rows))
    if abs(total - 1.0) > 1e-6:
        raise ParameterError(f"scatter.probability: must sum to 1, sums to {total:.6g}")
    note = t.get("note", "")
    if not isinstance(note, str):
        raise ParameterError("scatter.note: expected a string")
    return Scatter(hs, tp, tuple(rows), note)


def _check_override_key(key: str, where: str):
    parts = key.split(".")
    if len(parts) != 2 or parts[0] not in TABLES or parts[0] == "heave":
        raise ParameterError(f"{where}.{key}: expected \"table.key\" of a CMC parameter table "
                             f"({', '.join(t for t in TABLES if t != 'heave')})")
    if key == "friction.model":
        raise ParameterError(f"{where}.{key}: friction regimes are set by campaign regimes, not a variation")


def _parse_variations(t: Mapping[str, Any] | None) -> tuple:
    if not t:
        return (Variant("base", ()),)
    allowed = ("mode", "grid", "sample", "n", "seed")
    for key in t:
        if key not in allowed:
            raise ParameterError(f"variations.{key}: unknown key{did_you_mean(key, allowed)}")
    mode = t.get("mode")
    if mode not in ("grid", "sample"):
        raise ParameterError(f"variations.mode: expected \"grid\" or \"sample\", got {mode!r}")
    if mode == "grid":
        g = t.get("grid")
        if not isinstance(g, Mapping) or not g:
            raise ParameterError("variations.grid: missing table of \"table.key\" = [values]")
        keys = list(g)
        vals = []
        for key in keys:
            _check_override_key(key, "variations.grid")
            vals.append(_number_list(g[key], f"variations.grid.{key}", positive=False))
        combos = list(itertools.product(*vals))
        return tuple(Variant(f"v{i:03d}", tuple(zip(keys, c))) for i, c in enumerate(combos))
    import numpy as np

    smp = t.get("sample")
    if not isinstance(smp, Mapping) or not smp:
        raise ParameterError("variations.sample: missing table of \"table.key\" = [low, high]")
    n = t.get("n")
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise ParameterError(f"variations.n: expected a whole number >= 1, got {n!r}")
    seed = t.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ParameterError(f"variations.seed: expected a whole number >= 0, got {seed!r}")
    keys = list(smp)
    ranges = []
    for key in keys:
        _check_override_key(key, "variations.sample")
        r = _number_list(smp[key], f"variations.sample.{key}", positive=False)
        if len(r) != 2 or not r[0] < r[1]:
            raise ParameterError(f"variations.sample.{key}: expected [low, high] with low < high")
        ranges.append(r)
    rng = np.random.default_rng(seed)
    u = rng.uniform(size=(n, len(keys)))
    return tuple(Variant(f"v{i:03d}", tuple((k, float(lo + (hi - lo) * u[i, j]))
                                            for j, (k, (lo, hi)) in enumerate(zip(keys, ranges))))
                 for i in range(n))


def _parse_outputs(t):
    t = dict(t or {})
    figs = t.pop("figures", True)
    if not isinstance(figs, bool):
        raise ParameterError("outputs.figures: expected true or false")
    o = from_table(Outputs, t, "outputs")
    return dataclasses.replace(o, figures=figs)


def loads(text_: str, *, base_dir=None, source: str = "<string>") -> Campaign:
    """Parse campaign TOML text (see module docstring); raises ParameterError.

    Parameters
    ----------
    text_ : str
        The campaign TOML.
    base_dir : str or os.PathLike or None
        Folder that relative paths in the text (the base parameter file) are resolved from.
    source : str
        Name of the text in messages (its file).

    Returns
    -------
    Campaign
    """
    try:
        data = tomllib.loads(text_)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"{source}: not valid TOML: {exc}") from None
    for tname in data:
        if tname not in TABLE_NAMES:
            raise ParameterError(f"[{tname}]: unknown table{did_you_mean(tname, TABLE_NAMES)}; "
                                 f"known tables: {', '.join(TABLE_NAMES)}")
    for tname in ("campaign", "scatter", "band"):
        if tname not in data:
            raise ParameterError(f"[{tname}]: missing required table")
    ct = dict(data["campaign"])
    regimes = ct.pop("regimes", None)
    if regimes is None:
        raise ParameterError("campaign.regimes: missing required key (list of friction models)")
    if not isinstance(regimes, list) or not regimes:
        raise ParameterError("campaign.regimes: expected a non-empty list of friction models")
    for r in regimes:
        if r not in REGIMES:
            raise ParameterError(f"campaign.regimes: unknown friction model {r!r}{did_you_mean(r, REGIMES)}; "
                                 f"known: {', '.join(REGIMES)}")
    if len(set(regimes)) != len(regimes):
        raise ParameterError("campaign.regimes: duplicate entries")
    settings = from_table(Settings, ct, "campaign")
    camp = Campaign(settings=settings, scatter=_parse_scatter(data["scatter"]), regimes=tuple(regimes),
                    band=from_table(Band, data["band"], "band"), outputs=_parse_outputs(data.get("outputs")),
                    variants=_parse_variations(data.get("variations")),
                    base_dir=str(base_dir) if base_dir is not None else None, source_text=text_)
    base = camp.base_params()  # fail early on a bad base set, and on bad overrides / regimes
    for v in camp.variants:
        for reg in camp.regimes:
            camp.params_for(Run("check", 0, camp.scatter.hs[0], camp.scatter.tp[0], 1.0, reg, v.name, 0), base=base)
    return camp


def load(path) -> Campaign:
    """Read and validate a campaign TOML file.

    Parameters
    ----------
    path : str or os.PathLike
        The campaign file; relative paths inside it are resolved from its folder.

    Returns
    -------
    Campaign

    Raises
    ------
    heavecomp.errors.ParameterError
        A missing or unreadable file, or an invalid campaign.
    """
    path = Path(path)
    raw = read_text(path, "campaign file")
    return loads(raw, base_dir=path.resolve().parent, source=str(path))


def default() -> Campaign:
    """The illustrative default campaign (``default_campaign.toml``)."""
    return load(DEFAULT_FILE)
