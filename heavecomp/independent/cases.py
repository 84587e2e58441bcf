"""Cases of the independent truth: a class, drawn sizes, two logs (two seas) and ``truth.json``.

Every size is drawn from a stated, physically motivated distribution (``DISTRIBUTIONS`` below,
copied into each ``truth.json``), never sized up until the diagnosis can see it: an effect near
or below the noise floor is part of the set, and ``truth.json`` records its noise-free size
(``size_to_noise``: the rms of truth minus nominal, per channel, over the channel's noise).

Acceptable verdicts come from the contract's effect-name table only (``diagnosis-contract.md``):
the wording of each name, read against the law the class plants.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
import json
import math
from pathlib import Path

import numpy as np

from heavecomp.independent import laws
from heavecomp.independent.plant import Heave, Plant, SampledHeave, _critical_damping, simulate, G
from heavecomp.params import dumps, paper_a

#: measurement noise, 1 sigma, white Gaussian, per channel (SI)
NOISE = {"heave": 2e-3, "stroke": 2e-3, "pressure": 2e3, "wob": 400.0}
CHANNELS = ("heave", "stroke", "pressure", "wob")
DURATION = 600.0   #: s, each log
RATE = 10.0        #: Hz, the logger
SIM_RATE = 20.0    #: Hz, the plant's output before the logger samples it

#: the sizes each class draws from (U = uniform, logU = log-uniform, +- = either sign, equally likely)
DISTRIBUTIONS = {
    "sea": "Hs ~ U(1.0, 2.0) m platform heave, Tp ~ U(8, 14) s, gamma 3.3; second log: Hs x U(0.6, 0.8) or "
           "x U(1.2, 1.4), Tp +- U(2, 4) s (kept in 6-16 s), another phase seed",
    "friction_lugre": "relaxation length F_S/sigma0 ~ U(3, 6) cm; bristle damping ratio with M_c ~ U(0.3, 0.7)",
    "friction_dwell": "gain ~ U(0.15, 0.5) F_S; time constant ~ logU(1, 10) s; Kato exponent ~ U(0.5, 1); "
                      "slip distance D_c ~ U(0.5, 2) mm",
    "string_boucwen": "hysteretic share 1 - alpha ~ U(0.2, 0.5); yield force ~ U(2, 8) kN; exponent n ~ U(1, 2)",
    "gas_thermal": "N2, gamma = 1.4; thermal time constant ~ logU(2, 20) s (Pourmovahed & Otis: seconds to tens "
                   "of seconds for large bottles); charge and vessel as the nominal",
    "line_dynamics": "line diameter ~ U(0.25, 0.35) m, length ~ U(3, 12) m, valve K ~ U(2, 6); oil 870 kg/m3, "
                     "0.03 Pa s",
    "mru_filter": "heave channel through a 2nd-order high-pass, corner period ~ U(60, 150) s, zeta 0.707; plus a "
                  "drift of rms ~ U(1, 3) cm (three sines, periods ~ U(200, 900) s)",
    "sensor_gain": "channel ~ {stroke, pressure, wob}; gain 1 +- U(0.03, 0.10)",
    "sensor_offset": "channel ~ {pressure: + p_atm (read absolute), wob: +- U(2, 6) kN, stroke: +- U(5, 20) mm}",
    "sensor_delay": "channel ~ {stroke, pressure, wob}; delay ~ U(0.1, 0.5) s",
    "param_friction": "F_S and F_C both x (1 +- U(0.2, 0.35))",
    "param_gas": "gas volume / (1 +- U(0.2, 0.35)) (k_gas x the factor), charge pressure unchanged",
    "param_formation": "k_F x U(0.5, 0.75) or x U(1.3, 1.6)",
    "heavier_mass": "M_c x U(1.1, 1.25); the charge raised so the WOB is still W_0 (the driller's set-point); vessel "
                    "volume as the nominal",
    "string_second_mode": "a share U(0.2, 0.4) of m_b lumped at mid-string (two springs of 2 k_ds)",
    "formation_hardening": "k_F x U(1.6, 2.5) over U(3, 10) s, starting at U(0.3, 0.7) of the log",
    "quantised_hum": "pressure quantised to 0.25 bar; mains hum on pressure, amplitude ~ U(1, 4) kPa at "
                     "50 + U(0.01, 0.05) Hz (aliased by the 10 Hz logger); WOB through a 16-bit logger over 0-500 kN",
    "two_effects": "two of the single plant/sensor classes above, from different components, each drawn as "
                   "above; the dominant is the one whose noise-free gap (sum over channels of (rms/noise)^2) "
                   "is larger",
    "none": "the nominal plant",
}


@dataclass
class Effect:
    """One drawn effect: what it changes (plant, reading, heave channel) and what it is."""

    cls: str
    component: str
    verdicts: tuple
    in_library: bool
    params: dict
    plant: object = None      #: Plant -> Plant
    reading: object = None    #: (t, channels) -> channels (noise-free, before the logger)
    logger: object = None     #: (t, channels, rng) -> channels (after noise: quantisers, hum)
    extra: dict = field(default_factory=dict)


def _pm(rng) -> float:
    return 1.0 if rng.random() < 0.5 else -1.0


def _on(channel: str, law):
    """A reading that applies ``law(t, y)`` to one channel."""
    def reading(t, c):
        return {**c, channel: law(t, c[channel])}
    return reading


def _draw(cls: str, rng, nominal: Plant) -> Effect:
    """The class' effect with sizes drawn from ``DISTRIBUTIONS[cls]``."""
    seal = nominal.seal
    if cls == "friction_lugre":
        L, zeta = rng.uniform(0.03, 0.06), rng.uniform(0.3, 0.7)
        lug = replace(seal, relaxation_length=L)
        lug = replace(lug, micro_damping=_critical_damping(lug, nominal.moving_mass, zeta))
        return Effect(cls, "friction", ("friction_lag",), True,
                      {"relaxation_length_m": L, "bristle_damping_ratio": zeta, "sigma0_N_per_m": lug.sigma0,
                       "sigma1_N_s_per_m": lug.micro_damping},
                      plant=lambda p: p.with_(seal=lug))
    if cls == "friction_dwell":
        d = laws.DwellStiction(gain=rng.uniform(0.15, 0.5) * seal.static_force,
                               time_constant=math.exp(rng.uniform(math.log(1.0), math.log(10.0))),
                               exponent=rng.uniform(0.5, 1.0), slip_distance=rng.uniform(0.5e-3, 2e-3))
        return Effect(cls, "friction", ("dwell_stiction",), True,
                      {"gain_N": d.gain, "time_constant_s": d.time_constant, "exponent": d.exponent,
                       "slip_distance_m": d.slip_distance}, plant=lambda p: p.with_(dwell=d))
    if cls == "string_boucwen":
        share, fy, n = rng.uniform(0.2, 0.5), rng.uniform(2e3, 8e3), rng.uniform(1.0, 2.0)

        def plant(p):
            k = p.k_ds * (2.0 if p.mid_fraction > 0 else 1.0)
            return p.with_(bouc_wen=laws.BoucWen(k, 1.0 - share, fy, n))
        return Effect(cls, "string_formation", ("string_damping",), True,
                      {"hysteretic_share": share, "yield_force_N": fy, "exponent": n}, plant=plant)
    if cls == "gas_thermal":
        tau = math.exp(rng.uniform(math.log(2.0), math.log(20.0)))
        return Effect(cls, "gas_spring", ("gas_heat_transfer",), True, {"gamma": 1.4, "tau_s": tau},
                      plant=lambda p: p.with_(thermal=laws.ThermalGas(1.4, tau)))
    if cls == "line_dynamics":
        line = laws.Line(rng.uniform(0.25, 0.35), rng.uniform(3.0, 12.0), rng.uniform(2.0, 6.0))
        a = nominal.area
        return Effect(cls, "flow_line", ("flow_loss",), True,
                      {"diameter_m": line.diameter, "length_m": line.length, "valve_k": line.valve_k,
                       "drop_at_0.1_m3s_Pa": line.drop(0.1), "inertance_added_mass_kg": line.inertance * a * a},
                      plant=lambda p: p.with_(line=line))
    if cls == "mru_filter":
        tc = rng.uniform(60.0, 150.0)
        drift_rms = rng.uniform(0.01, 0.03)
        periods = rng.uniform(200.0, 900.0, 3)
        phases = rng.uniform(0, 2 * math.pi, 3)

        def heave_channel(t, z):
            dr = np.sin(2 * math.pi * t[:, None] / periods + phases).sum(axis=1)
            dr = dr - dr[0]
            dr *= drift_rms / max(np.sqrt(np.mean(dr ** 2)), 1e-12)
            return laws.mru_highpass(t, z, tc) + dr
        return Effect(cls, "heave_input", ("heave_reference",), True,
                      {"corner_period_s": tc, "drift_rms_m": drift_rms, "drift_periods_s": list(periods)},
                      extra={"heave_channel": heave_channel})
    if cls == "sensor_gain":
        ch = str(rng.choice(["stroke", "pressure", "wob"]))
        gain = 1.0 + _pm(rng) * rng.uniform(0.03, 0.10)
        return Effect(cls, "sensors", ("sensor_gain",), True, {"channel": ch, "gain": gain},
                      reading=_on(ch, lambda t, y: laws.gain_offset(y, gain=gain)))
    if cls == "sensor_offset":
        ch = str(rng.choice(["pressure", "wob", "stroke"]))
        off = {"pressure": laws.P_ATM, "wob": _pm(rng) * rng.uniform(2e3, 6e3),
               "stroke": _pm(rng) * rng.uniform(5e-3, 20e-3)}[ch]
        return Effect(cls, "sensors", ("sensor_offset",), True, {"channel": ch, "offset_SI": off},
                      reading=_on(ch, lambda t, y: laws.gain_offset(y, offset=off)))
    if cls == "sensor_delay":
        ch = str(rng.choice(["stroke", "pressure", "wob"]))
        dl = rng.uniform(0.1, 0.5)
        return Effect(cls, "sensors", ("sensor_delay",), True, {"channel": ch, "delay_s": dl},
                      reading=_on(ch, lambda t, y: laws.delayed(t, y, dl)))
    if cls == "param_friction":
        f = 1.0 + _pm(rng) * rng.uniform(0.2, 0.35)
        new = replace(seal, static_force=seal.static_force * f, coulomb_force=seal.coulomb_force * f)
        return Effect(cls, "friction", ("parameter_mismatch",), True,
                      {"factor": f, "static_force_N": new.static_force, "coulomb_force_N": new.coulomb_force},
                      plant=lambda p: p.with_(seal=new))
    if cls == "param_gas":
        f = 1.0 + _pm(rng) * rng.uniform(0.2, 0.35)
        return Effect(cls, "gas_spring", ("parameter_mismatch",), True,
                      {"gas_stiffness_factor": f, "gas_volume_m3": nominal.v0 / f},
                      plant=lambda p: p.with_(v0=p.v0 / f))
    if cls == "param_formation":
        f = rng.uniform(0.5, 0.75) if rng.random() < 0.5 else rng.uniform(1.3, 1.6)
        return Effect(cls, "string_formation", ("parameter_mismatch",), True,
                      {"formation_stiffness_factor": f, "formation_stiffness_N_per_m": nominal.k_f * f},
                      plant=lambda p: p.with_(k_f=p.k_f * f))
    if cls == "heavier_mass":
        f = rng.uniform(1.1, 1.25)

        def plant(p):
            m = p.moving_mass * f
            return p.with_(moving_mass=m, p0=((m + p.lower_mass) * G - p.wob_setpoint) / p.area)
        return Effect(cls, "friction", ("parameter_mismatch",), True,
                      {"moving_mass_factor": f, "moving_mass_kg": nominal.moving_mass * f,
                       "note": "the mass enters the top mass's force balance (the seal's equation); the raised "
                               "charge also reads on the pressure: gas_spring is accepted as its component too"},
                      plant=plant, extra={"components": ("friction", "gas_spring")})
    if cls == "string_second_mode":
        share = rng.uniform(0.2, 0.4)
        return Effect(cls, "string_formation", (), False, {"mid_mass_share": share},
                      plant=lambda p: p.with_(mid_fraction=share))
    if cls == "formation_hardening":
        fac, dur, at = rng.uniform(1.6, 2.5), rng.uniform(3.0, 10.0), rng.uniform(0.3, 0.7) * DURATION
        return Effect(cls, "string_formation", (), False, {"factor": fac, "t_start_s": at, "duration_s": dur},
                      plant=lambda p: p.with_(hardening=(fac, at, dur)))
    if cls == "quantised_hum":
        amp, fm, ph = rng.uniform(1e3, 4e3), 50.0 + rng.uniform(0.01, 0.05), rng.uniform(0, 2 * math.pi)

        def logger(t, c, _rng):
            c = dict(c)
            c["pressure"] = laws.quantise(c["pressure"] + laws.mains_hum(t, amp, fm, ph), 0.25e5)
            c["wob"] = laws.adc16(c["wob"], 0.0, 5e5)
            return c
        return Effect(cls, "sensors", ("none",), False,
                      {"pressure_step_Pa": 0.25e5, "hum_amplitude_Pa": amp, "mains_Hz": fm,
                       "aliased_Hz": abs(fm - 5 * RATE), "wob_adc_bits": 16, "wob_range_N": [0.0, 5e5],
                       "note": "a reading artefact on a nominal plant: none (measurement noise) or the sensors "
                               "component is right"},
                      logger=logger)
    raise KeyError(cls)


#: single-effect classes, in library
SINGLE = ("friction_lugre", "friction_dwell", "string_boucwen", "gas_thermal", "line_dynamics", "mru_filter",
          "sensor_gain", "sensor_offset", "sensor_delay", "param_friction", "param_gas", "param_formation",
          "heavier_mass")
#: out-of-library classes (no contract name fits: the right component is the honest answer)
OUT_OF_LIBRARY = ("string_second_mode", "formation_hardening", "quantised_hum")
#: singles that can pair in two_effects (parameter errors and mass left out: "two effects" are two mechanisms)
PAIRABLE = ("friction_lugre", "friction_dwell", "string_boucwen", "gas_thermal", "line_dynamics", "mru_filter",
            "sensor_gain", "sensor_offset", "sensor_delay")
CLASSES = SINGLE + OUT_OF_LIBRARY + ("two_effects", "none")
#: the component each single class plants (the contract's component names)
COMPONENT = {"friction_lugre": "friction", "friction_dwell": "friction", "string_boucwen": "string_formation",
             "gas_thermal": "gas_spring", "line_dynamics": "flow_line", "mru_filter": "heave_input",
             "sensor_gain": "sensors", "sensor_offset": "sensors", "sensor_delay": "sensors",
             "param_friction": "friction", "param_gas": "gas_spring", "param_formation": "string_formation",
             "heavier_mass": "friction", "string_second_mode": "string_formation",
             "formation_hardening": "string_formation", "quantised_hum": "sensors"}


def _sea(rng) -> tuple[dict, dict]:
    hs, tp = rng.uniform(1.0, 2.0), rng.uniform(8.0, 14.0)
    hs2 = hs * (rng.uniform(0.6, 0.8) if rng.random() < 0.5 else rng.uniform(1.2, 1.4))
    tp2 = float(np.clip(tp + _pm(rng) * rng.uniform(2.0, 4.0), 6.0, 16.0))
    return ({"hs": hs, "tp": tp, "seed": int(rng.integers(0, 2**31))},
            {"hs": hs2, "tp": tp2, "seed": int(rng.integers(0, 2**31))})


def _run(plant: Plant, effects: list[Effect], sea, duration: float) -> dict:
    """Noise-free channels at the logger's rate, as the sensors read them (before noise); ``sea`` is
    a sea-state dict or a heave (the plant's input). ``true_heave``: the heave the plant saw."""
    heave = Heave(sea["hs"], sea["tp"], seed=sea["seed"]) if isinstance(sea, dict) else sea
    for e in effects:
        if e.plant is not None:
            plant = e.plant(plant)
    r = simulate(plant, heave, duration, rate=SIM_RATE)
    t = r["t"]
    ch = {k: r[k] for k in CHANNELS}
    for e in effects:
        if "heave_channel" in e.extra:
            ch["heave"] = e.extra["heave_channel"](t, ch["heave"])
        if e.reading is not None:
            ch = e.reading(t, ch)
    step = int(round(SIM_RATE / RATE))
    return {"t": t[::step], **{k: v[::step] for k, v in ch.items()}, "true_heave": r["heave"][::step]}


def _log(clean: dict, effects: list[Effect], rng, noise_scale: float) -> dict:
    out = {"t": clean["t"]}
    for k in CHANNELS:
        out[k] = clean[k] + rng.normal(0.0, NOISE[k] * noise_scale, clean[k].size)
    for e in effects:
        if e.logger is not None:
            out = e.logger(out["t"], out, rng)
    return out


def write_csv(path: Path, cols: dict) -> Path:
    """A measured-run CSV (header ``t,heave,stroke,pressure,wob``, SI units).

    Parameters
    ----------
    path : pathlib.Path
        The file.
    cols : dict
        t and the four channels [SI].

    Returns
    -------
    pathlib.Path
        path.
    """
    names = ["t", *CHANNELS]
    np.savetxt(path, np.column_stack([cols[k] for k in names]), delimiter=",", header=",".join(names),
               comments="", fmt="%.9g")
    return path


def _size_to_noise(a: dict, b: dict) -> dict:
    return {k: float(np.sqrt(np.mean((a[k] - b[k]) ** 2)) / NOISE[k]) for k in CHANNELS}


def _gap(size: dict) -> float:
    return float(sum(v * v for v in size.values()))


def _draw_case(seed: int, cls: str):
    """(rng, sea, sea2, nominal parameters, nominal plant, effects) of a case: the same for the same
    (seed, class), so :func:`truth_replay` rebuilds the truth :func:`make_case` logged."""
    rng = np.random.default_rng([seed, CLASSES.index(cls)])
    sea1, sea2 = _sea(rng)
    params = paper_a().replace(heave={"kind": "jonswap", "hs": round(sea1["hs"], 3), "tp": round(sea1["tp"], 3),
                                      "gamma": 3.3, "seed": sea1["seed"], "amplitude": None, "period": None,
                                      "ramp": None})
    nominal = Plant.from_params(params)
    if cls == "none":
        effects = []
    elif cls == "two_effects":
        a = str(rng.choice(PAIRABLE))
        b = str(rng.choice([c for c in PAIRABLE if COMPONENT[c] != COMPONENT[a]]))
        effects = [_draw(a, rng, nominal), _draw(b, rng, nominal)]
    else:
        effects = [_draw(cls, rng, nominal)]
    return rng, sea1, sea2, params, nominal, effects


def truth_replay(seed: int, cls: str, t: np.ndarray, heave: np.ndarray) -> dict | None:
    """The case's true model (plant and sensors, no noise) driven by the heave samples (t, heave):
    a replay of the truth, as a user replays a model on a log's heave. None for a truth whose heave
    channel is filtered (``mru_filter``): the logged heave is not the heave its plant saw.

    Parameters
    ----------
    seed : int
        The case's seed.
    cls : str
        Its class.
    t : ndarray [s]
        Heave sample times.
    heave : ndarray [m]
        The heave the plant sees.

    Returns
    -------
    dict or None
        Noise-free channels at 10 Hz [SI].
    """
    if cls not in CLASSES:
        raise ValueError(f"class: unknown {cls!r}")
    _, _, _, _, nominal, effects = _draw_case(seed, cls)
    if any("heave_channel" in e.extra for e in effects):
        return None  # the true model reads its heave through the MRU: the logged heave is not its input
    return _run(nominal, effects, SampledHeave(t, heave), float(t[-1] - t[0]))


def make_case(seed: int, cls: str, out: str | Path, *, noise_scale: float = 1.0,
              duration: float = DURATION) -> dict:
    """Generate one case of class ``cls`` into folder ``out``; return its truth (also ``truth.json``).

    Files: ``log.csv`` (the measured-run contract: t, heave, stroke, pressure, wob; SI, 10 Hz),
    ``nominal.toml`` (the paper-A set with JONSWAP heave of the log's sea), ``truth_channels.csv``
    (noise-free, as the sensors read them), ``log_sea2.csv`` and ``truth_channels_sea2.csv`` (the
    same truth plant and sensors in another sea), ``truth.json``. :func:`truth_replay` runs the same
    truth under another heave.

    Parameters
    ----------
    seed : int
        Case seed (with the class, it fixes every draw).
    cls : str
        One of ``CLASSES``.
    out : str or pathlib.Path
        Folder to write.
    noise_scale : float [-]
        Multiplies ``NOISE``.
    duration : float [s]
        Length of each log.

    Returns
    -------
    dict
        The truth (as in ``truth.json``).
    """
    if cls not in CLASSES:
        raise ValueError(f"class: unknown {cls!r}; known: {', '.join(CLASSES)}")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    rng, sea1, sea2, params, nominal, effects = _draw_case(seed, cls)

    clean = _run(nominal, effects, sea1, duration)
    nom_clean = _run(nominal, [], sea1, duration)
    size = _size_to_noise(clean, nom_clean)
    truth = {"class": cls, "seed": seed, "noise": {k: NOISE[k] * noise_scale for k in CHANNELS},
             "noise_note": "white Gaussian, 1 sigma, SI (m, m, Pa, N)", "rate_Hz": RATE, "duration_s": duration,
             "sea": sea1, "sea2": sea2, "size_to_noise": size, "distributions": DISTRIBUTIONS[cls]}
    if cls == "none":
        truth.update(component=None, verdicts=["none"], in_library=True, dominant=None, effects=[])
    elif cls == "two_effects":
        sizes = [_size_to_noise(_run(nominal, [e], sea1, duration), nom_clean) for e in effects]
        gaps = [_gap(s) for s in sizes]
        dom = effects[int(np.argmax(gaps))]
        truth.update(component=dom.component, verdicts=list(dom.verdicts), in_library=dom.in_library,
                     dominant=dom.cls, dominance_ratio=max(gaps) / max(min(gaps), 1e-12),
                     components=list(dom.extra.get("components", (dom.component,))),
                     effects=[{"class": e.cls, "component": e.component, "verdicts": list(e.verdicts),
                               "params": e.params, "size_to_noise": s} for e, s in zip(effects, sizes)])
    else:
        e = effects[0]
        truth.update(component=e.component, verdicts=list(e.verdicts), in_library=e.in_library, dominant=None,
                     components=list(e.extra.get("components", (e.component,))),
                     effects=[{"class": e.cls, "component": e.component, "params": e.params}])
    if cls != "none":
        truth["honest"] = ("a named verdict not in `verdicts` at medium/high confidence is confident-wrong; "
                           "inconclusive/discovered with a component in `components` is honest")

    log = _log(clean, effects, rng, noise_scale)
    clean2 = _run(nominal, effects, sea2, duration)
    log2 = _log(clean2, effects, rng, noise_scale)
    for name, cols in (("log", log), ("truth_channels", clean), ("log_sea2", log2), ("truth_channels_sea2", clean2)):
        write_csv(out / f"{name}.csv", cols)

    (out / "nominal.toml").write_text(dumps(params, header=f"independent truth, class {cls}, seed {seed}: the "
                                                           "nominal the user believes"))
    (out / "truth.json").write_text(json.dumps(truth, indent=2, default=float))
    return truth
