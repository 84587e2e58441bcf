"""parameter_mismatch, as generated: no missing physics, two of four nominal parameters shifted by
30-50 % (the nominal law itself, with wrong values).

The diagnosis refits six multipliers.  The run's truth records the wrong values it was made with.
"""

from __future__ import annotations

from heavecomp.benchmark.truth.base import Draw, TruthLaw

#: the nominal parameters that may be off, "table.key"
KEYS = ("compensator.gas_stiffness", "friction.coulomb_force", "drill_string.stiffness", "formation.stiffness")


def draw(rng, setting):
    """Two of :data:`KEYS`, each off by +-30-50 %; the relative changes are scaled together ("*"),
    each at most 60 %.

    Parameters
    ----------
    rng : numpy.random.Generator
        The case's random stream.
    setting : heavecomp.benchmark.truth.Setting
        What the draw may depend on; this law reads none of it (the signature every draw shares).

    Returns
    -------
    heavecomp.benchmark.truth.Draw
        The law's parameters [SI], the parameter that sets its size and that size's cap.
    """
    pick = rng.choice(len(KEYS), size=2, replace=False)
    return Draw({KEYS[i]: float(rng.choice([-1, 1]) * rng.uniform(0.3, 0.5)) for i in sorted(pick)}, "*", 0.6)


def changes(parameters, nominal):
    """The wrong parameters, ``{table: {key: value}}`` [SI].

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
        ``"table.key": nominal value x (1 + f)`` [SI].
    """
    return {path: getattr(getattr(nominal, path.split(".")[0]), path.split(".")[1]) * (1 + f)
            for path, f in parameters.items()}


LAW = TruthLaw("parameter_mismatch", None, draw, changes=changes, record=record)
