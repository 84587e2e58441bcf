"""One estimator base for every sim-to-real gap diagnoser (issue 11 item 5).

The CMC's :class:`heavecomp.diagnosis.GapDiagnoser` and the 1-DOF axis'
:class:`heavecomp.identification.residual.ResidualDiagnoser` answer the same
question for several plants (the CMC; the EMPS axis and the O-ring seal rig, whose diagnoser
takes the same candidates: the effect library's classes, through their equation-error
features): where does the held-out residual of the nominal model
live, and which candidate effect shrinks it.  Both follow the scikit-learn /
pysindy convention (settings in ``__init__``, ``fit(data)`` returns ``self``,
learned results end in ``_``) and share this base, which gives them the same
door:

- :meth:`get_params` — the settings, by ``__init__`` name;
- :attr:`fitted` and :meth:`check_fitted` — a clear error before ``fit``;
- :attr:`ranking_` — every candidate tried, best first (dicts with ``effect``
  and ``shrink``);
- :attr:`effect_` — the effect the diagnoser names, or None when none earns it
  (no gap, inconclusive, or no candidate worth its parameters);
- :attr:`where_` — where the residual lives (each diagnoser's own blocks).

A subclass says which of its attributes hold the ranking and the choice
(``_ranking_attr``, ``_choice_attr``) and implements ``fit``.
"""

from __future__ import annotations

import inspect

from heavecomp.errors import InputError

#: verdicts that name no effect
NO_EFFECT = ("none", "inconclusive", "discovered")  # discovered: an open-search term, never a named effect


class NotFittedError(InputError):
    """A result was asked for before ``fit``."""


class GapEstimator:
    """Base of the gap diagnosers (see the module docstring)."""

    #: attribute holding every candidate's result, best first
    _ranking_attr = "results_"
    #: attribute holding the chosen candidate (a dict with ``effect``) or None
    _choice_attr = "best_"

    def fit(self, data) -> "GapEstimator":  # pragma: no cover - every diagnoser implements it
        raise NotImplementedError

    @classmethod
    def _param_names(cls) -> list[str]:
        sig = inspect.signature(cls.__init__)
        return [n for n, p in sig.parameters.items()
                if n != "self" and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]

    def get_params(self) -> dict:
        """The settings given at construction, by ``__init__`` parameter name."""
        return {n: getattr(self, n) for n in self._param_names() if hasattr(self, n)}

    @property
    def fitted(self) -> bool:
        """True once :meth:`fit` has run."""
        return hasattr(self, self._ranking_attr)

    def check_fitted(self) -> None:
        """Raise :class:`NotFittedError` (one line) if :meth:`fit` has not run."""
        if not self.fitted:
            raise NotFittedError(f"{type(self).__name__}: call fit() first")

    @property
    def ranking_(self) -> list[dict]:
        """Every candidate tried, best first (``effect``, ``shrink``, ...)."""
        self.check_fitted()
        return getattr(self, self._ranking_attr)

    @property
    def effect_(self) -> str | None:
        """The effect the diagnoser names, or None (no gap, inconclusive, nothing earns its parameters)."""
        self.check_fitted()
        choice = getattr(self, self._choice_attr, None)
        effect = choice.get("effect") if choice else None
        return None if effect in NO_EFFECT else effect

    def __repr__(self) -> str:
        sig = inspect.signature(type(self).__init__)
        shown = []
        for n, v in self.get_params().items():
            default = sig.parameters[n].default
            try:
                same = default is not inspect.Parameter.empty and bool(v == default)
            except Exception:  # noqa: BLE001 - arrays and objects without a plain ==
                same = False
            if not same:
                shown.append(f"{n}={v!r}" if isinstance(v, (int, float, str, tuple, type(None))) else f"{n}=...")
        return f"{type(self).__name__}({', '.join(shown)})"
