"""Cross-parameter plausibility of a CMC parameter set: unit slips that each key's own bounds let through.

Each key's bounds (:mod:`heavecomp.params.cmc`) catch a value that no drilling
compensator can have.  A value written in the wrong unit (tonnes as kg, kN as N,
ms as s) is often still inside those bounds, but then it no longer fits the
*other* keys: the static load, the gas volume, the friction, the modes of the
rig.  :func:`check` tests those relations and raises a one-line
:class:`~heavecomp.errors.ParameterError` naming the key most likely wrong, the
derived quantity that gives it away and, where a slip by 1000 is the likely
cause, the unit it was probably written in.

The relations and their limits (each with the paper-A value, so the margin is visible):

========================  =================================================  ===========  ==============
check                      quantity                                           paper A      plausible
========================  =================================================  ===========  ==============
string in tension          T_0 = m_b g - W_0 (drill pipe cannot push)         196 kN       > 0
gas column                 V_0 / A = n (p_0 + p_atm) A / k_gas                28.9 m       1 m - 1000 m
static friction            F_S / (p_0 A)                                      2.3 %        <= 30 %
pressure friction          C_p p_0 / (p_0 A)                                  0.5 %        <= 30 %
viscous friction           C_v * 1 m/s / (p_0 A)                              1.0 %        <= 50 %
Stribeck ratio             F_S / F_C                                          1.9          <= 100
lower-mass damping ratio   (c_ds + c_F) / (2 sqrt((k_ds + k_F) m_b))          0.033        <= 10
top-mass damping ratio     c_ds / (2 sqrt((k_gas + k_ds) M_c))                0            <= 10
natural frequencies        frictionless, two masses                           0.44, 1.8 Hz 0.002 - 25 Hz
fade-in                    heave.ramp / period                                2            0, or 0.1-100
active force               [active].u_max / ((M_c + m_b) g)                   5.6 %        <= 100 %
active force rate          [active].u_max / rate_max                          0.2 s        1 ms - 60 s
heave within the stroke    crest to trough 2 a (sine), 1.86 H_s (jonswap)     2 m          <= 7.62 m
smallest heave             a (sine), H_s (jonswap)                            1 m          0, or >= 1 cm
smallest friction term     C_v * 1 m/s, C_p p_0 as a share of p_0 A           1.0, 0.5 %   0, or >= 0.01 %
smallest damping           c_ds, c_F: own damping ratio on their spring       0, 0.006     0, or >= 1e-4
========================  =================================================  ===========  ==============

Why these limits: a compensator is a soft gas spring carrying the suspended
weight, so its gas column is metres to hundreds of metres long (shorter and a
stroke of a few cm would use up the gas); seal friction is a few percent of the
load (30 % would mean a seized cylinder); drill pipe buckles in compression, so
the WOB comes from the lower mass's weight; the bit-bounce and compensator
modes of real rigs lie between ~0.01 and ~10 Hz.  ``scripts/unit_slips.py``
counts which x1000 / /1000 slips of the shipped sets these checks catch.

The last four rows close the slips that used to pass as "small but valid" (2026-11):

- the stroke follows the heave, so a heave whose largest wave is longer than the longest compensator
  stroke built (25 ft = 7.62 m; the largest of ~1000 waves of a sea state is 1.86 H_s, Rayleigh) drives
  the stroke past its physical range: the plant has no end stops and would report a 10 m stroke
  (H_s 16 m) as if it were possible;
- a non-zero heave under 1 cm is below what a motion reference unit resolves (heave accuracy 5 cm or
  5 %) and than any sea moves a drilling unit: a platform at rest is written 0; 1 mm is a metre slipped;
- a non-zero friction term under 0.01 % of the cylinder load, or a damping below the material damping
  of steel (damping ratio 1e-4), cannot be told from none by any measurement: it is written 0, and a
  value that small is a slip by 1000.
"""

from __future__ import annotations

import math

import numpy as np

from heavecomp.errors import ParameterError
from heavecomp.params.core import G

#: reference stroke velocity for the viscous-friction check [m/s] (peak stroke velocity of a 5 m, 15 s heave ~ 1 m/s)
V_REF = 1.0
GAS_COLUMN = (1.0, 1000.0)  #: V_0 / A [m]
FRICTION_SHARE = 0.30  #: largest F_S and C_p p_0 as a share of the cylinder load p_0 A
VISCOUS_SHARE = 0.50  #: largest C_v V_REF as a share of p_0 A
STRIBECK_RATIO = 100.0  #: largest F_S / F_C
DAMPING_RATIO = 10.0  #: largest damping ratio of either mass on its springs
MODES_HZ = (0.002, 25.0)  #: natural frequencies of the frictionless rig [Hz]
RAMP_PERIODS = (0.1, 100.0)  #: heave.ramp in periods (or 0)
FULL_FORCE_TIME = (1e-3, 60.0)  #: [active] u_max / rate_max [s]
STROKE_MAX = 7.62  #: longest compensator stroke built (25 ft) [m]
HMAX_PER_HS = 1.86  #: largest of ~1000 waves over the significant height (Rayleigh) [-]
HEAVE_MIN = 0.01  #: smallest non-zero heave amplitude or H_s [m] (MRU heave resolution ~ cm)
MIN_SHARE = 1e-4  #: smallest non-zero friction term as a share of p_0 A [-]
MIN_DAMPING_RATIO = 1e-4  #: smallest non-zero damping ratio of a string or formation damper [-] (steel)


def _g(x: float) -> str:
    return f"{x:.4g}"


def check(p) -> None:
    """Raise :class:`ParameterError` for the first implausible relation between keys of ``p`` (a CMCParams).

    Parameters
    ----------
    p : CMCParams
        A parameter set whose tables passed their own key checks (SI values).
    """
    c, f, ds, fo, op = p.compensator, p.friction, p.drill_string, p.formation, p.operating_point
    mb_g = ds.lower_mass * G
    if op.wob_setpoint >= mb_g:
        raise ParameterError(
            f"operating_point.wob_setpoint = {_g(op.wob_setpoint)} N is not below the lower mass's weight "
            f"drill_string.lower_mass g = {_g(mb_g)} N: the drill string would push on the top mass "
            f"(T_0 = m_b g - W_0 <= 0; drill pipe buckles in compression); is drill_string.lower_mass in t? (SI: kg)")
    load = p.p0 * p.area  # cylinder load at the operating point [N]
    column = p.gas_volume / p.area
    if not GAS_COLUMN[0] <= column <= GAS_COLUMN[1]:
        low = column < GAS_COLUMN[0]
        raise ParameterError(
            f"compensator.gas_stiffness = {_g(c.gas_stiffness)} N/m gives a gas volume V_0 = {_g(p.gas_volume)} m^3, "
            f"a gas column V_0/A = {_g(column)} m, outside {GAS_COLUMN[0]:g}-{GAS_COLUMN[1]:g} m "
            + ("(a few cm of stroke would use up the gas)" if low else "(no compensator carries that much gas)")
            + ("" if low else "; is it in kN/m? (SI: N/m)"))
    if f.model != "none":
        if f.static_force > FRICTION_SHARE * load:
            raise ParameterError(
                f"friction.static_force = {_g(f.static_force)} N is {100 * f.static_force / load:.0f} % of the "
                f"cylinder load p_0 A = {_g(load)} N (seal friction is a few %, at most {100 * FRICTION_SHARE:.0f} %)")
        if f.pressure_coefficient * p.p0 > FRICTION_SHARE * load:
            raise ParameterError(
                f"friction.pressure_coefficient = {_g(f.pressure_coefficient)} N/Pa gives C_p p_0 = "
                f"{_g(f.pressure_coefficient * p.p0)} N, {100 * f.pressure_coefficient * p.p0 / load:.0f} % of the "
                f"cylinder load p_0 A = {_g(load)} N (at most {100 * FRICTION_SHARE:.0f} %); is it in N/bar? (SI: N/Pa)")
        if f.viscous_coefficient * V_REF > VISCOUS_SHARE * load:
            raise ParameterError(
                f"friction.viscous_coefficient = {_g(f.viscous_coefficient)} N s/m gives "
                f"{_g(f.viscous_coefficient * V_REF)} N at {V_REF:g} m/s, over {100 * VISCOUS_SHARE:.0f} % of the "
                f"cylinder load p_0 A = {_g(load)} N")
        for key, force in (("viscous_coefficient", f.viscous_coefficient * V_REF),
                           ("pressure_coefficient", f.pressure_coefficient * p.p0)):
            if 0 < force < MIN_SHARE * load:
                raise ParameterError(
                    f"friction.{key} = {_g(getattr(f, key))} gives {_g(force)} N, under {100 * MIN_SHARE:g} % of the "
                    f"cylinder load p_0 A = {_g(load)} N: no measurement tells that from none (write 0), or a unit "
                    "slip by 1000?")
        if f.static_force > STRIBECK_RATIO * f.coulomb_force:
            raise ParameterError(
                f"friction.coulomb_force = {_g(f.coulomb_force)} N is below 1/{STRIBECK_RATIO:g} of "
                f"friction.static_force = {_g(f.static_force)} N (cylinder seals: F_S/F_C ~ 1-3); is it in kN? (SI: N)")
    for key, c_, k_ in (("drill_string.damping", ds.damping, ds.stiffness), ("formation.damping", fo.damping, fo.stiffness)):
        zeta = c_ / (2 * math.sqrt(k_ * ds.lower_mass))
        if 0 < zeta < MIN_DAMPING_RATIO:
            raise ParameterError(f"{key} = {_g(c_)} N s/m is a damping ratio of {_g(zeta)} on its spring, under "
                                 f"{MIN_DAMPING_RATIO:g} (the material damping of steel): write 0 for none, or a unit "
                                 "slip by 1000?")
    zeta_b = (ds.damping + fo.damping) / (2 * math.sqrt((ds.stiffness + fo.stiffness) * ds.lower_mass))
    if zeta_b > DAMPING_RATIO:
        key = "formation.damping" if fo.damping >= ds.damping else "drill_string.damping"
        val = max(fo.damping, ds.damping)
        raise ParameterError(f"{key} = {_g(val)} N s/m makes the lower mass's damping ratio {_g(zeta_b)} "
                             f"(at most {DAMPING_RATIO:g}: a rig's modes are lightly damped)")
    zeta_c = ds.damping / (2 * math.sqrt((c.gas_stiffness + ds.stiffness) * c.moving_mass))
    if zeta_c > DAMPING_RATIO:
        raise ParameterError(f"drill_string.damping = {_g(ds.damping)} N s/m makes the top mass's damping ratio "
                             f"{_g(zeta_c)} (at most {DAMPING_RATIO:g})")
    _check_modes(p)
    _check_sea(p.heave)
    _check_ramp(p.heave)
    act = p.extra.get("active")
    if act is not None:
        weight = (c.moving_mass + ds.lower_mass) * G
        if act.u_max > weight:
            raise ParameterError(f"active.u_max = {_g(act.u_max)} N is above the suspended weight "
                                 f"(M_c + m_b) g = {_g(weight)} N (an active cylinder assists the main cylinder)")
        t_full = act.u_max / act.rate_max
        if not FULL_FORCE_TIME[0] <= t_full <= FULL_FORCE_TIME[1]:
            raise ParameterError(
                f"active.rate_max = {_g(act.rate_max)} N/s takes u_max / rate_max = {_g(t_full)} s to full force "
                f"active.u_max = {_g(act.u_max)} N, outside {FULL_FORCE_TIME[0]:g}-{FULL_FORCE_TIME[1]:g} s"
                + ("; is it in kN/s? (SI: N/s)" if t_full > FULL_FORCE_TIME[1] else ""))


def natural_frequencies(p) -> tuple[np.ndarray, np.ndarray]:
    """Undamped natural frequencies [Hz] of the frictionless two-mass rig and the mode shapes (columns).

    Parameters
    ----------
    p : CMCParams
        The parameter set (masses [kg], stiffnesses [N/m]).
    """
    c, ds, fo = p.compensator, p.drill_string, p.formation
    K = np.array([[c.gas_stiffness + ds.stiffness, -ds.stiffness], [-ds.stiffness, ds.stiffness + fo.stiffness]])
    m = np.array([c.moving_mass, ds.lower_mass])
    # symmetric form M^-1/2 K M^-1/2
    s = 1.0 / np.sqrt(m)
    w2, phi = np.linalg.eigh(K * np.outer(s, s))
    return np.sqrt(np.maximum(w2, 0.0)) / (2 * np.pi), phi


def _check_modes(p) -> None:
    f_hz, phi = natural_frequencies(p)
    lo, hi = MODES_HZ
    for i, fi in enumerate(f_hz):
        if lo <= fi <= hi:
            continue
        top = phi[0, i] ** 2 >= phi[1, i] ** 2  # which mass the mode moves most (kinetic-energy share)
        keys = ("compensator.moving_mass", "compensator.gas_stiffness", "drill_string.stiffness") if top else \
            ("drill_string.lower_mass", "drill_string.stiffness", "formation.stiffness")
        vals = ", ".join(f"{k} = {_g(_get(p, k))}" for k in keys)
        raise ParameterError(
            f"{keys[0]}: a natural frequency of the rig is {_g(fi)} Hz, outside {lo:g}-{hi:g} Hz "
            f"({vals}; {'too light or too stiff' if fi > hi else 'too heavy or too soft'} — a unit slip?)")


def _get(p, dotted: str) -> float:
    table, key = dotted.split(".")
    return getattr(getattr(p, table), key)


def check_file(p) -> None:
    """Checks of what a parameter *file* says (``heavecomp.params.load``/``loads``), beyond :func:`check`:
    a non-zero heave under :data:`HEAVE_MIN` is a unit slip there (1 mm written for 1 m).  A set built in
    code for a study may go lower (the CMC stick map scans breakout amplitudes of a few millimetres).

    Parameters
    ----------
    p : CMCParams
        The parameter set read from the file.
    """
    h = p.heave
    if h is None or h.kind == "file":
        return
    key, x = ("heave.amplitude", h.amplitude) if h.kind == "sine" else ("heave.hs", h.hs)
    if 0 < x < HEAVE_MIN:
        raise ParameterError(f"{key} = {_g(x)} m is under {100 * HEAVE_MIN:g} cm: no sea moves a drilling unit that "
                             "little and no motion sensor resolves it (write 0 for no heave), or a unit slip by 1000?")


def _check_sea(h) -> None:
    """The heave's largest crest to trough within the longest stroke (:data:`STROKE_MAX`)."""
    if h is None or h.kind == "file":
        return
    key, x = ("heave.amplitude", h.amplitude) if h.kind == "sine" else ("heave.hs", h.hs)
    span, how = (2 * x, "2 x heave.amplitude") if h.kind == "sine" else (HMAX_PER_HS * x, f"the largest wave, {HMAX_PER_HS:g} x heave.hs")
    if span > STROKE_MAX:
        raise ParameterError(f"{key} = {_g(x)} m: {how} = {_g(span)} m crest to trough is longer than any compensator's "
                             f"stroke ({STROKE_MAX:g} m, 25 ft) — the stroke would pass its physical range (the model has "
                             "no end stops); drilling stops long before such a sea")


def _check_ramp(h) -> None:
    if h is None or h.kind == "file" or h.ramp is None or h.ramp == 0:
        return
    period, pname = (h.period, "heave.period") if h.kind == "sine" else (h.tp, "heave.tp")
    n = h.ramp / period
    lo, hi = RAMP_PERIODS
    if not lo <= n <= hi:
        raise ParameterError(
            f"heave.ramp = {_g(h.ramp)} s is {_g(n)} periods of {pname} = {_g(period)} s, outside {lo:g}-{hi:g} periods"
            + (" (use 0 for no fade-in)" if n < lo else "; is it in ms? (SI: s)"))
