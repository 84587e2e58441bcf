"""parameter_mismatch, as generated: no missing physics, two of four nominal parameters shifted by
30-50 % (the nominal law itself, with wrong values); variant ``moving_mass``: the compensator's top
mass 10-25 % heavier than the file, run as a rig runs it -- the charge raised in the same gas bank until
the WOB is the driller's set-point again.

The diagnosis refits multipliers of the nominal's parameters (``MISMATCH_KEYS``).  The run's truth
records the wrong values it was made with.
"""

from __future__ import annotations

from heavecomp.benchmark.truth.base import Draw, TruthLaw

#: the nominal parameters that may be off, "table.key"
KEYS = ("compensator.gas_stiffness", "friction.coulomb_force", "drill_string.stiffness", "formation.stiffness")
#: the top mass, the parameter the ``moving_mass`` variant moves
MASS = "compensator.moving_mass"


def draw(rng, setting):
    """Two of :data:`KEYS`, each off by +-30-50 %; the relative changes are scaled together ("*"),
    each at most 60 %.  Variant ``moving_mass``: the top mass heavier by 10-25 % (:func:`changes` raises
    the charge with it).

    Parameters
    ----------
    rng : numpy.random.Generator
        The case's random stream.
    setting : heavecomp.benchmark.truth.Setting
        What the draw may depend on; this law reads ``variant``.

    Returns
    -------
    heavecomp.benchmark.truth.Draw
        The law's parameters [SI], the parameter that sets its size and that size's cap.
    """
    if setting.variant == "moving_mass":
        return Draw({MASS: float(rng.uniform(0.10, 0.25))}, "*", 0.6)
    pick = rng.choice(len(KEYS), size=2, replace=False)
    return Draw({KEYS[i]: float(rng.choice([-1, 1]) * rng.uniform(0.3, 0.5)) for i in sorted(pick)}, "*", 0.6)


def changes(parameters, nominal):
    """The wrong parameters, ``{table: {key: value}}`` [SI].

    A top mass that is off keeps the driller's WOB set-point as a rig runs it: the operating point's
    charge p_0 = ((M_c + m_b) g - W_0) / A follows the mass (the parameter set derives it), in the same
    gas bank: the gas volume V_0 is held, so the gas stiffness n (p_0 + p_atm) A^2 / V_0 rises with the
    absolute charge.

    Parameters
    ----------
    parameters : dict
        Relative changes ``"table.key": f`` [-] (the drawn :class:`~heavecomp.benchmark.truth.Draw`).
    nominal : heavecomp.params.CMCParams
        The nominal parameters the changes apply to.

    Returns
    -------
    dict
        ``{table: {key: nominal value x (1 + f)}}`` [SI].
    """
    ch = {}
    for path, f in parameters.items():
        table, key = path.split(".")
        ch.setdefault(table, {})[key] = getattr(getattr(nominal, table), key) * (1 + f)
    comp = ch.get("compensator", {})
    if "moving_mass" in comp:  # the same bank, charged for the true mass
        bank = nominal.replace(compensator={k: v for k, v in comp.items() if k != "moving_mass"}).gas_volume
        comp["gas_stiffness"] = (comp.get("gas_stiffness", nominal.compensator.gas_stiffness)
                                 * nominal.replace(**ch).gas_volume / bank)
    return ch


def record(parameters, nominal):
    """The wrong values the run was generated with, ``"table.key": value`` [SI].

    Parameters
    ----------
    parameters : dict
        Relative changes ``"table.key": f`` [-].
    nominal : heavecomp.params.CMCParams
        The nominal parameters the changes apply to.

    Returns
    -------
    dict
        ``"table.key": value`` [SI] of every parameter :func:`changes` moved (nominal value x (1 + f); a
        moved top mass's gas stiffness too).
    """
    return {f"{table}.{key}": value for table, kv in changes(parameters, nominal).items() for key, value in kv.items()}


LAW = TruthLaw("parameter_mismatch", None, draw, changes=changes, record=record, variants=("moving_mass",))
