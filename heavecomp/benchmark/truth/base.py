"""What a truth law is: its draw (parameters, the one that sets its size, and that size's cap),
and how it is planted (a plant effect at the hooks, a law on the logged channels, or wrong nominal
parameters)."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numpy as np


@dataclasses.dataclass(frozen=True)
class Setting:
    """What a truth law's draw may depend on.

    Attributes
    ----------
    nominal : heavecomp.params.CMCParams
        The nominal parameters the diagnosis is given.
    duration : float [s]
        Generated length of the run (before a mid-operation log start is cut off).
    variant : str or None
        The case's variant of the law (e.g. which channel misreads).
    base : dict
        Clean channels of the drawn sea without any effect, channel -> array [SI].
    """

    nominal: object
    duration: float
    variant: str | None
    base: dict


@dataclasses.dataclass(frozen=True)
class Draw:
    """Drawn truth parameters of one law and the knob that sets its size.

    Attributes
    ----------
    parameters : dict
        The law's parameters [SI] (``parameter_mismatch``: relative changes ``"table.key": f`` [-]).
    magnitude : str or None
        The parameter that sets the size of the effect; ``"*"``: every parameter is a relative
        change scaled together; None: no size knob (only a redraw changes the size).
    cap : float or None
        Largest plausible absolute value of ``magnitude`` (of every ``|f|`` for ``"*"``) [its unit].
    """

    parameters: dict
    magnitude: str | None = None
    cap: float | None = None

    def scaled(self, factor):
        """This draw with its magnitude multiplied by ``factor`` [-], at most the cap.

        Returns
        -------
        (Draw, bool)
            The scaled draw and whether its magnitude sits at the cap.
        """
        out = dict(self.parameters)
        if self.magnitude == "*":  # every relative change
            for k, f in self.parameters.items():
                out[k] = float(np.sign(f) * min(abs(f) * factor, self.cap))
            return dataclasses.replace(self, parameters=out), all(abs(f) >= self.cap for f in out.values())
        x = self.parameters[self.magnitude]
        out[self.magnitude] = math.copysign(min(abs(x) * factor, self.cap), x)
        return dataclasses.replace(self, parameters=out), abs(out[self.magnitude]) >= self.cap


@dataclasses.dataclass(frozen=True, eq=False)
class Part:
    """One planted law as the testbed simulates it (compared by identity).

    Attributes
    ----------
    name : str
        The truth law.
    effects : tuple
        Truth-effect instances at the plant's hooks.
    changes : dict or None
        Nominal parameters replaced, ``{table: {key: value}}`` [SI].
    output : callable or None
        ``output(t, cols, **parameters) -> cols``: a law on the clean logged channels.
    parameters : dict
        Keyword arguments of ``output``.
    on_heave : bool
        ``output`` changes the heave signal (what the diagnosis replays from).
    """

    name: str
    effects: tuple = ()
    changes: dict | None = None
    output: Callable | None = None
    parameters: dict = dataclasses.field(default_factory=dict)
    on_heave: bool = False


def _as_recorded(parameters, nominal):
    return {k: (v if isinstance(v, str) else float(v)) for k, v in parameters.items()}


@dataclasses.dataclass(frozen=True)
class TruthLaw:
    """One truth law of the benchmark (one file each in :mod:`heavecomp.benchmark.truth`).

    Attributes
    ----------
    name : str
        The effect name it plants (a contract name, or one outside every name).
    component : str or None
        The model component it lives in (contract schema 2); None for ``parameter_mismatch``.
    draw : callable
        ``draw(rng, setting) -> Draw``: its random parameters, size knob and cap.
    plant : type or None
        Its own :class:`heavecomp.effects.base.Effect` subclass at the plant's hooks (never a
        candidate's class or equation).
    output : callable or None
        ``output(t, cols, **parameters) -> cols``: a law on the clean logged channels.
    on_heave : bool
        ``output`` changes the heave signal.
    changes : callable or None
        ``changes(parameters, nominal) -> {table: {key: value}}``: wrong nominal parameters.
    record : callable
        ``record(parameters, nominal) -> dict``: the parameters as the run's truth records them.
    named : bool
        A name of the contract (else an effect outside every name).
    answer : str
        The contract's class a verdict is judged against (empty: the law's own name): a law of a
        broader class (the line's inertance is a law of ``flow_loss``).
    variants : tuple of str
        The variants its draw knows (a case's ``variant``; None: the default).
    min_stuck_share : float [-]
        Planted only in a sea where the compensator is stuck at least this share of the time.
    """

    name: str
    component: str | None
    draw: Callable
    plant: type | None = None
    output: Callable | None = None
    on_heave: bool = False
    changes: Callable | None = None
    record: Callable = _as_recorded
    named: bool = True
    answer: str = ""
    variants: tuple = ()
    min_stuck_share: float = 0.0

    def part(self, parameters, nominal) -> Part:
        """What the testbed simulates for ``parameters`` (:class:`Part`)."""
        if self.plant is not None:
            return Part(self.name, effects=(self.plant(**parameters),))
        if self.changes is not None:
            return Part(self.name, changes=self.changes(parameters, nominal))
        return Part(self.name, output=self.output, parameters=dict(parameters), on_heave=self.on_heave)
