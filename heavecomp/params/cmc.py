"""Parameters of the crown-block mounted compensator (CMC) — the TOML contract.

The table and key names are fixed by ``docs/contracts/parameter-file.md``; this
module adds nothing to their meaning.  All quantities SI.

Which keys may be omitted (the documented defaults; everything else is required):

- ``[heave]`` as a whole (``simulate`` then needs ``--heave`` data; diagnosis takes
  heave from the measured run).  ``heave.ramp`` defaults to two periods (sine) or
  two peak periods (jonswap); ``heave.gamma`` to 3.3; ``heave.seed`` to 0.
- ``[friction]`` keys not used by the chosen ``model`` (``none`` needs none;
  ``tangential_velocity`` only for the rotating models).  Keys given but not
  used by the model are validated and kept (so one file can be run in every
  friction regime with ``--friction``), but do not act.
- ``drill_string.damping`` and ``formation.damping`` default to 0 N s/m.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

from heavecomp.errors import ParameterError, did_you_mean
from heavecomp.params.core import G, P_ATM, choice, dump_toml, from_table, q, read_text, text, to_table, toml_error_message
from heavecomp.params import effects as effects_table, measurement, plausibility


FRICTION_MODELS = ("none", "stribeck", "rotating_eq6", "rotating_eq7")
V_T_MIN = 1e-3  #: smallest non-zero friction.tangential_velocity [m/s]
HEAVE_KINDS = ("sine", "jonswap", "file")


@dataclass(frozen=True, kw_only=True)
class Heave:
    """``[heave]``: the platform heave input used by ``simulate``."""

    kind: str = choice(HEAVE_KINDS, doc="sine | jonswap | file")
    amplitude: float = q(None, "m", bounds=(0.0, 15.0), symbol="a", doc="sine amplitude", unit_high="mm",
                         why="platform heave: drilling stops at a few metres, 15 m is a survival storm")
    period: float = q(None, "s", bounds=(0.5, 100.0), symbol="T", doc="sine period", unit_high="ms",
                      why="sea states are 3-25 s; wider for sweeps and slow quasi-static checks")
    ramp: float = q(None, "s", bounds=(0.0, 1e5), symbol="T_r", unit_high="ms",
                    doc="fade-in time; default 2 periods (sine) / 2 peak periods (jonswap)",
                    why="0 (no fade-in) or 0.1-100 periods (checked against the period): a shorter non-zero fade-in "
                        "is a unit slip (e.g. 1e-300 s), a longer one never reaches the sea state")
    hs: float = q(None, "m", bounds=(0.0, 30.0), symbol="H_s", unit_high="mm",
                  doc="significant wave height of the platform heave (jonswap)",
                  why="the highest recorded sea states are ~20 m; platform heave is less")
    tp: float = q(None, "s", bounds=(1.0, 40.0), symbol="T_p", doc="spectral peak period (jonswap)", unit_high="ms",
                  why="wind sea and swell peak between 3 and 25 s")
    gamma: float = q(None, "-", bounds=(1.0, 10.0), symbol="gamma", doc="JONSWAP peak enhancement (default 3.3)",
                     why="1 (Pierson-Moskowitz) to ~7 for very peaked seas (DNV-RP-C205)")
    seed: int = q(None, "-", bounds=(0, 2**32 - 1), integer=True, doc="random seed of the JONSWAP phases (default 0)",
                  why="numpy's seed: a whole number in [0, 2**32 - 1]")
    path: str = text(None, doc="CSV with columns t, heave (relative to the parameter file's folder)")

    _REQUIRED = {"sine": ("amplitude", "period"), "jonswap": ("hs", "tp"), "file": ("path",)}

    def __post_init__(self):
        for key in self._REQUIRED[self.kind]:
            if getattr(self, key) is None:
                raise ParameterError(f"heave.{key}: missing required key for kind = \"{self.kind}\"")
        unused = {"sine": ("hs", "tp", "gamma", "seed", "path"), "jonswap": ("amplitude", "period", "path"),
                  "file": ("amplitude", "period", "hs", "tp", "ramp", "gamma", "seed")}[self.kind]
        for key in unused:
            if getattr(self, key) is not None:
                raise ParameterError(f"heave.{key}: not used by kind = \"{self.kind}\" (remove it or change heave.kind)")
        if self.kind == "jonswap":
            if self.gamma is None:
                object.__setattr__(self, "gamma", 3.3)
            if self.seed is None:
                object.__setattr__(self, "seed", 0)
        if self.ramp is None and self.kind != "file":
            object.__setattr__(self, "ramp", 2.0 * (self.period if self.kind == "sine" else self.tp))


@dataclass(frozen=True, kw_only=True)
class Compensator:
    """``[compensator]``: main cylinder, top mass and gas spring."""

    plunger_diameter: float = q(unit="m", bounds=(0.05, 3.0), symbol="d", unit_high="mm",
                                doc="single-acting plunger diameter; area A = pi d^2/4",
                                why="equivalent single plunger of a 100-1000 t compensator at 50-300 bar: 0.2-1.5 m")
    moving_mass: float = q(unit="kg", bounds=(1e3, 1e6), symbol="M_c", unit_low="t",
                           doc="top mass: crown block, travelling block, top drive, plungers",
                           why="crown block + travelling block + top drive weigh tens of tonnes; < 1 t or "
                               "> 1000 t is no drilling rig")
    gas_stiffness: float = q(unit="N/m", bounds=(1e3, 1e8), symbol="k_gas", unit_low="kN/m",
                             doc="gas spring stiffness linearised at the operating point (after force equalizers)",
                             why="compensators are built soft (tens of kN/m) so heave barely changes the load; "
                                 "the gas volume it implies is checked too")
    polytropic_index: float = q(unit="-", bounds=(1.0, 1.7), symbol="n",
                                doc="polytropic index of the gas (1 isothermal, 1.4 adiabatic N2)",
                                why="between isothermal (1) and adiabatic for any real gas (<= 5/3 monatomic)")


@dataclass(frozen=True, kw_only=True)
class Friction:
    """``[friction]``: main-cylinder friction (paper A eqs. 4, 6, 7)."""

    model: str = choice(FRICTION_MODELS, doc="none | stribeck | rotating_eq6 | rotating_eq7")
    static_force: float = q(None, "N", bounds=(0.0, 5e6), symbol="F_S", doc="static (breakaway) friction",
                            why="seal friction is a few % of the cylinder load (checked against p_0 A)")
    coulomb_force: float = q(None, "N", bounds=(0.0, 5e6), symbol="F_C", doc="Coulomb friction",
                             why="between F_S / 100 and F_S (seals: F_S / F_C ~ 1-3)")
    stribeck_velocity: float = q(None, "m/s", bounds=(1e-4, 1.0), symbol="v_S", unit_high="mm/s",
                                 doc="Stribeck velocity",
                                 why="hydraulic seals: 0.1-50 mm/s; below 0.1 mm/s the friction slope forces "
                                     "a time step too small to simulate")
    viscous_coefficient: float = q(None, "N s/m", bounds=(0.0, 1e8), symbol="C_v", doc="viscous coefficient",
                                   why="viscous friction at 1 m/s must stay below half the cylinder load (checked)")
    pressure_coefficient: float = q(None, "N/Pa", bounds=(0.0, 0.1), symbol="C_p", unit_high="N/bar",
                                    doc="pressure coefficient (200 N/bar = 2e-3 N/Pa)",
                                    why="seal contact area x friction coefficient: ~1e-3 N/Pa for a 0.7 m plunger; "
                                        "C_p p_0 is checked against the load")
    tangential_velocity: float = q(None, "m/s", bounds=(0.0, 2.0), symbol="v_t", unit_high="mm/s",
                                   doc="piston surface speed from rotation, omega d/2 (rotating models)",
                                   why="0 (rotation stopped: eqs. 6-7 are eq. 4) or 1 mm/s - 2 m/s (checked): a "
                                       "rotating piston turns at ~0.1-5 rad/s on a < 1.5 m piston; below 1 mm/s the "
                                       "eq. 7 slope F_S / v_t forces a time step too small to simulate")

    _LAW_KEYS = ("static_force", "coulomb_force", "stribeck_velocity", "viscous_coefficient",
                 "pressure_coefficient")

    def __post_init__(self):
        if self.model == "none":
            return
        needed = self._LAW_KEYS + (("tangential_velocity",) if self.model.startswith("rotating") else ())
        for key in needed:
            if getattr(self, key) is None:
                raise ParameterError(f"friction.{key}: missing required key for model = \"{self.model}\"")
        vt = self.tangential_velocity
        if vt is not None and 0.0 < vt < V_T_MIN:
            raise ParameterError(f"friction.tangential_velocity = {vt:g} m/s: use 0 (rotation stopped) or at least "
                                 f"{V_T_MIN:g} m/s (slower rotation makes the eq. 7 slope F_S / v_t too steep to "
                                 f"simulate); is it in mm/s? (SI: m/s)")
        if self.static_force < self.coulomb_force:
            raise ParameterError(
                f"friction.static_force = {self.static_force:g} N is below friction.coulomb_force = "
                f"{self.coulomb_force:g} N (static friction must be >= Coulomb friction)")


@dataclass(frozen=True, kw_only=True)
class DrillString:
    """``[drill_string]``: the string as a spring-damper to the lumped lower mass."""

    stiffness: float = q(unit="N/m", bounds=(1e4, 1e8), symbol="k_ds", doc="axial stiffness EA/L", unit_low="kN/m",
                         why="steel pipe EA ~ 0.5-2e9 N over 30 m to 10 km")
    damping: float = q(0.0, "N s/m", bounds=(0.0, 1e7), symbol="c_ds", doc="axial damping (default 0)",
                       why="damping ratio of the lower mass <= 10 (checked)")
    lower_mass: float = q(unit="kg", bounds=(1e3, 2e6), symbol="m_b", doc="lumped string + BHA mass", unit_low="t",
                          why="a BHA alone weighs > 1 t; 10 km of heavy pipe with BHA < 2000 t")


@dataclass(frozen=True, kw_only=True)
class Formation:
    """``[formation]``: one-sided bit-rock contact."""

    stiffness: float = q(unit="N/m", bounds=(5e3, 1e8), symbol="k_F", doc="contact stiffness", unit_low="kN/m",
                         why="softer than 5 kN/m is > 2 m of give per 10 t of WOB (mud, not rock); the BHA's "
                             "own compliance caps it near 1e8 N/m")
    damping: float = q(0.0, "N s/m", bounds=(0.0, 1e7), symbol="c_F", doc="contact damping (default 0)",
                       why="damping ratio of the lower mass <= 10 (checked)")


@dataclass(frozen=True, kw_only=True)
class OperatingPoint:
    """``[operating_point]``."""

    wob_setpoint: float = q(unit="N", bounds=(1e3, 2e6), symbol="W_0", doc="WOB set-point", unit_low="kN",
                            why="bits run at 1-50 t; below 1 kN is a unit slip (kN or t), and W_0 must be below the "
                                "lower mass's weight (checked)")


#: contract tables in file order -> class; optional tables registered by other modules
TABLES: dict[str, type] = {
    "heave": Heave,
    "compensator": Compensator,
    "friction": Friction,
    "drill_string": DrillString,
    "formation": Formation,
    "operating_point": OperatingPoint,
}
#: tables a file may leave out entirely
OPTIONAL_TABLES: set[str] = {"heave"}


@dataclass(frozen=True, kw_only=True)
class CMCParams:
    """A complete, validated CMC parameter set (see ``cmc-reference.md``).

    Use :func:`load`, :func:`loads`, :func:`from_dict`, or a named set from
    :mod:`heavecomp.params.sets`; change with :meth:`replace`.
    """

    compensator: Compensator
    friction: Friction
    drill_string: DrillString
    formation: Formation
    operating_point: OperatingPoint
    heave: Heave | None = None
    #: ``[[effects]]``: ``((name, {parameter: value}), ...)``, checked against the effect classes by
    #: :func:`heavecomp.effects.spec.check` (the effects layer; :mod:`heavecomp.params.effects`)
    effects: tuple = dataclasses.field(default=(), hash=False)
    #: folder of the file it was read from (resolves ``heave.path``)
    base_dir: Path | None = dataclasses.field(default=None, compare=False, repr=False)
    #: optional extra tables registered in OPTIONAL_EXTRA (e.g. ``[active]``)
    extra: Mapping[str, Any] = dataclasses.field(default_factory=dict, compare=False)

    def __post_init__(self):
        g_load = (self.compensator.moving_mass + self.drill_string.lower_mass) * G
        if self.operating_point.wob_setpoint >= g_load:
            raise ParameterError(
                f"operating_point.wob_setpoint = {self.operating_point.wob_setpoint:g} N must be below the "
                f"suspended weight (M_c + m_b) g = {g_load:g} N (the cylinder pressure would be <= 0)")

        plausibility.check(self)  # cross-key plausibility: unit slips inside each key's bounds
        if self.heave is not None and self.heave.kind == "file" and not self.heave.path.strip():
            raise ParameterError('heave.path = "": empty; give the heave CSV (columns t, heave), relative to the '
                                 "parameter file's folder")

    # ---- derived quantities (cmc-reference.md) ---------------------------------
    @property
    def area(self) -> float:
        """Plunger area A = pi d^2 / 4 [m^2]."""
        return math.pi * self.compensator.plunger_diameter ** 2 / 4.0

    @property
    def p0(self) -> float:
        """Operating-point gauge pressure: p_0 A = (M_c + m_b) g - W_0 [Pa]."""
        c, ds = self.compensator, self.drill_string
        return ((c.moving_mass + ds.lower_mass) * G - self.operating_point.wob_setpoint) / self.area

    @property
    def gas_volume(self) -> float:
        """V_0 from k_gas = n (p_0 + p_atm) A^2 / V_0 [m^3]."""
        c = self.compensator
        return c.polytropic_index * (self.p0 + P_ATM) * self.area ** 2 / c.gas_stiffness

    @property
    def k_eff(self) -> float:
        """Paper A eq. 14: springs in series, 1/k_eff = 1/k_gas + 1/k_ds + 1/k_F [N/m]."""
        return 1.0 / (1.0 / self.compensator.gas_stiffness + 1.0 / self.drill_string.stiffness
                      + 1.0 / self.formation.stiffness)

    def replace(self, **changes: Mapping[str, Any]) -> "CMCParams":
        """Return a copy with some keys changed, validated like a file.

        ``p.replace(friction={"model": "none"}, drill_string={"stiffness": 208e3})``;
        a value ``None`` removes that key, a table ``None`` removes the table.
        Unknown tables or keys raise :class:`ParameterError`.
        """
        d = self.to_dict()
        for tname, upd in changes.items():
            if tname == "effects":  # the [[effects]] array as a whole: specs or tables
                d["effects"] = effects_table.to_tables(upd if upd and isinstance(upd[0], tuple) else
                                                       effects_table.parse(upd or []))
                continue
            if tname not in TABLES and tname not in OPTIONAL_EXTRA:
                raise ParameterError(f"{tname}: unknown table{did_you_mean(tname, list(TABLES) + list(OPTIONAL_EXTRA))}")
            if upd is None:
                d.pop(tname, None)
                continue
            new = dict(d.get(tname, {}))
            new.update(upd)
            d[tname] = {k: v for k, v in new.items() if v is not None}  # None removes a key
        return from_dict(d, base_dir=self.base_dir)

    def to_dict(self) -> dict[str, dict[str, Any]]:
        out = {}
        for tname in TABLES:
            obj = getattr(self, tname)
            if obj is not None:
                out[tname] = to_table(obj)
        for tname, obj in self.extra.items():
            out[tname] = to_table(obj) if dataclasses.is_dataclass(obj) else dict(obj)
        if self.effects:
            out["effects"] = effects_table.to_tables(self.effects)
        return out


def check_heave_path(heave, base_dir) -> None:
    """``heave.path`` (kind ``file``) names a readable, non-empty regular file: one-line
    :class:`ParameterError` naming ``heave.path`` for a missing file, a folder, a device (``/dev/null``)
    or an empty file (an empty string is refused by :class:`CMCParams` itself).  A relative path is
    resolved against ``base_dir`` (the parameter file's folder).  :func:`load` calls it: a file's
    heave is checked when the file is read; a set built or changed in code is checked when its heave
    is read (:func:`heavecomp.simulate.excitation.read_heave_csv`).

    Parameters
    ----------
    heave : Heave or None
        The ``[heave]`` table (None or another kind: nothing to check).
    base_dir : str or Path or None
        The parameter file's folder; None: a relative path is not checked.
    """
    if heave is None or heave.kind != "file" or not heave.path.strip():
        return
    path = Path(heave.path)
    if not path.is_absolute():
        if base_dir is None:
            return
        path = Path(base_dir) / path
    try:
        st = path.stat()
    except FileNotFoundError:
        raise ParameterError(f"heave.path = {heave.path!r}: file not found ({path})") from None
    except OSError as exc:
        raise ParameterError(f"heave.path = {heave.path!r}: cannot read ({type(exc).__name__})") from None
    import stat

    if stat.S_ISDIR(st.st_mode):
        raise ParameterError(f"heave.path = {heave.path!r}: a folder, not a heave file")
    if not stat.S_ISREG(st.st_mode):
        raise ParameterError(f"heave.path = {heave.path!r}: not a regular file (a device or pipe); give the heave CSV")
    if st.st_size == 0:
        raise ParameterError(f"heave.path = {heave.path!r}: empty file ({path})")


#: optional tables other modules add: name -> callable(table_dict) -> object (validated)
OPTIONAL_EXTRA: dict[str, Any] = {}


def from_dict(data: Mapping[str, Any], *, base_dir: Path | None = None) -> CMCParams:
    """Validate a nested mapping (a parsed TOML file) into :class:`CMCParams`.

    Parameters
    ----------
    data : Mapping[str, Any]
        Table name -> table (SI values), ``effects`` -> the ``[[effects]]`` array.
    base_dir : Path or None
        Folder relative paths in the file (``heave.path``) are resolved against (the file's folder).
    """
    data = dict(data)
    fx = effects_table.parse(data.pop("effects")) if "effects" in data else ()
    for tname, value in data.items():
        if tname not in TABLES and tname not in OPTIONAL_EXTRA:
            known = list(TABLES) + list(OPTIONAL_EXTRA) + ["effects"]
            raise ParameterError(f"[{tname}]: unknown table{did_you_mean(tname, known)}; known tables: {', '.join(known)}")
        if not isinstance(value, Mapping):
            raise ParameterError(f"{tname}: expected a table [{tname}], got a {type(value).__name__}")
    kw = {}
    for tname, cls in TABLES.items():
        if tname not in data:
            if tname in OPTIONAL_TABLES:
                kw[tname] = None
                continue
            raise ParameterError(f"[{tname}]: missing required table")
        kw[tname] = from_table(cls, data[tname], tname)
    extra = {t: OPTIONAL_EXTRA[t](data[t]) for t in OPTIONAL_EXTRA if t in data}
    return CMCParams(**kw, effects=fx, base_dir=base_dir, extra=extra)


def loads(text_: str, *, base_dir: Path | None = None, source: str = "<string>") -> CMCParams:
    """Parse TOML text into :class:`CMCParams`.

    Parameters
    ----------
    text_ : str
        The TOML text.
    base_dir : Path or None
        Folder relative paths in the file (``heave.path``) are resolved against (the file's folder).
    source : str
        Name of the text in error messages (the file's path).
    """
    try:
        data = tomllib.loads(text_)
    except (tomllib.TOMLDecodeError, ValueError) as exc:  # ValueError: an integer of > 4300 digits
        raise ParameterError(toml_error_message(text_, exc, source)) from None
    except RecursionError:  # tomllib parses nested inline tables / arrays recursively
        raise ParameterError(f"{source}: not valid TOML for a parameter file: tables or arrays nested too deep "
                             "(a parameter file is one level of tables)") from None
    p = from_dict(data, base_dir=base_dir)
    plausibility.check_file(p)  # what only a file can get wrong (a unit slip of the heave)
    return p


def load(path: str | Path, *, heave_file: bool = True) -> CMCParams:
    """Read and validate a CMC parameter file.

    Parameters
    ----------
    path : str or Path
        The TOML parameter file.
    heave_file : bool
        Check that a ``[heave] kind = "file"`` names a readable file beside it (the default).  A
        command that takes no heave from the file (``diagnose``, ``monitor``: the log carries the
        heave) passes False, so an unused, missing heave file does not stop it.

    Returns
    -------
    CMCParams
    """
    path = Path(path)
    raw = read_text(path, "parameter file")
    p = loads(raw, base_dir=path.resolve().parent, source=str(path))
    if heave_file:
        check_heave_path(p.heave, p.base_dir)  # a file's heave.path names a file beside it (not a set built in code)
    return p


def dumps(params: CMCParams, header: str = "") -> str:
    """TOML text of a parameter set (round-trips through :func:`loads`).

    Parameters
    ----------
    params : CMCParams
        The parameter set.
    header : str
        Comment lines put at the top (empty: none).
    """
    d = params.to_dict()
    fx = d.pop("effects", [])
    return dump_toml(d, header=header) + ("\n" + effects_table.dump(effects_table.parse(fx)) if fx else "")


def save(params: CMCParams, path: str | Path, header: str = "") -> Path:
    """Write a parameter set as TOML.

    Parameters
    ----------
    params : CMCParams
        The parameter set.
    path : str or Path
        The TOML file written (replaced if it exists).
    header : str
        Comment lines put at the top (empty: none).
    """
    path = Path(path)
    path.write_text(dumps(params, header), encoding="utf-8")
    return path


@dataclass(frozen=True, kw_only=True)
class Active:
    """``[active]`` (optional): an active cylinder beside the main cylinder.

    It pushes on the top mass with a force u (positive up), limited in size and
    rate; a controller (:mod:`heavecomp.controllers`) commands it at
    ``control_rate``.  Files without ``[active]`` are passive rigs; every key has
    a documented default.
    """

    u_max: float = q(60e3, "N", bounds=(1e3, 1e7), symbol="u_max", unit_low="kN",
                     doc="largest active force magnitude |u| (default 60 kN)",
                     why="an active cylinder of under 1 kN does nothing to a 100 t rig; it must stay below the "
                         "suspended weight (checked)")
    rate_max: float = q(300e3, "N/s", bounds=(1e3, 1e9), symbol="du_max", unit_low="kN/s",
                        doc="largest force rate |du/dt| (default 300 kN/s)",
                        why="full force u_max / rate_max in 1 ms to 60 s (checked)")
    control_rate: float = q(20.0, "Hz", bounds=(1.0, 1e3), symbol="f_c", unit_low="kHz", unit_high="mHz",
                            doc="controller sample rate; command held between samples (default 20 Hz)",
                            why="slower than 1 Hz cannot act within a wave (5-20 s); over 1 kHz is beyond the "
                                "actuator and the simulation budget")


OPTIONAL_EXTRA["active"] = lambda table: from_table(Active, table, "active")


def active(params: CMCParams) -> Active:
    """The ``[active]`` table of ``params``, or its documented defaults when absent.

    Parameters
    ----------
    params : CMCParams
        The parameter set.
    """
    return params.extra.get("active") or Active()


@dataclass(frozen=True, kw_only=True)
class Anchor:
    """``[anchor]`` (optional; ``heavecomp diagnose`` writes it into a ``calibrated.toml`` whose
    ``parameter_mismatch`` refit moved the nominal values): the values of the file the first diagnosis
    was run against.  A later diagnosis of a file that has it refits these parameters within a search box
    about them (the refit's 0.2-5 x and so on of *these*, not of the file's own values), so that a
    re-diagnosis does not step another factor past the first refit's bound each time.  A key left out
    anchors to the file's own value.  Ignored by every command but ``diagnose``.
    """

    gas_stiffness: float = q(None, "N/m", bounds=(1e3, 1e8), symbol="k_gas,0", doc="compensator.gas_stiffness "
                                                                                      "of the first file")
    static_force: float = q(None, "N", bounds=(0.0, 5e6), symbol="F_S,0", doc="friction.static_force of the "
                                                                                "first file")
    coulomb_force: float = q(None, "N", bounds=(0.0, 5e6), symbol="F_C,0", doc="friction.coulomb_force of the "
                                                                                "first file")
    viscous_coefficient: float = q(None, "N s/m", bounds=(0.0, 1e8), symbol="C_v,0",
                                   doc="friction.viscous_coefficient of the first file")
    drill_string_stiffness: float = q(None, "N/m", bounds=(1e4, 1e8), symbol="k_ds,0",
                                      doc="drill_string.stiffness of the first file")
    formation_stiffness: float = q(None, "N/m", bounds=(5e3, 1e8), symbol="k_F,0",
                                   doc="formation.stiffness of the first file")
    moving_mass: float = q(None, "kg", bounds=(1e3, 1e6), symbol="M_c,0",
                           doc="compensator.moving_mass of the first file")


OPTIONAL_EXTRA["anchor"] = lambda table: from_table(Anchor, table, "anchor")


def _measurement(table):

    return measurement.from_table(table)


OPTIONAL_EXTRA["measurement"] = _measurement  # [measurement]: columns/units of measured series
