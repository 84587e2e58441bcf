"""The open search's term carried at a plant hook other than the seal friction (issue 22).

The gap diagnosis' open search (:func:`heavecomp.diagnosis.equation_error.open_search`) fits a sparse
sum of features to a component's equation residual (measured minus nominal).  On the flow line, the
gas spring and the drill string the memoryless features of the hook's own signals have a fixed form
at that hook: the residual is what the hook's value lacks, so the term is added to it (the friction
term is :mod:`heavecomp.effects.discovered_term`, a channel's misreading
:mod:`heavecomp.effects.sensor_term`):

==================  ===========  ===========================  ==============================================
effect              hook         residual (unit)              features carried (the search's names)
==================  ===========  ===========================  ==============================================
``line_term``       line         gas law, flow part (Pa)      ``const``, ``v``, ``v_abs_v``, ``abs_v``, ``p``
                                                              (v the stroke velocity, p the pressure)
``gas_term``        gas spring   gas law, rest (Pa)           ``const``, ``x`` (the stroke less ``x_mean``),
                                                              ``v``, ``v_abs_v``, ``abs_v``
``string_term``     string       lower-mass balance (N)       ``const``, ``v``, ``v_abs_v``, ``abs_v``,
                                                              ``sign_v_pos``, ``sign_v_neg`` (v the string's
                                                              relative velocity dz_h + v - v_b), ``rel``,
                                                              ``rel_abs_rel``, ``rel_cubed`` (the stretch
                                                              less ``rel_median``)
==================  ===========  ===========================  ==============================================

A feature the hook cannot compute (time, lags, stroke bands, the stretch's dead band and saturation, whose
widths are not recorded) is not carried:
:func:`carried` says which.  Not diagnosis candidates and not registered; part of the superset composition
compiled at install (:func:`heavecomp.effects.compose.library_composition`), each applied *first* at its
hook (:func:`heavecomp.effects.compose.hook_order`): it sees the hook's nominal value, the value its
features were fitted on, whatever other effect a file adds at the same hook.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from heavecomp.effects.base import Effect
from heavecomp.errors import ParameterError
from heavecomp.params.core import q
from heavecomp.params.plausibility import STROKE_MAX
from heavecomp.plants.cmc import CDS, KDS, T0, plant_vector

_V = dict(bounds=(-1e12, 1e12))


class _Term(Effect):
    """Base of a hook term: every parameter optional, all 0 adds nothing."""

    def __init_subclass__(cls, **kw):
        super().__init_subclass__(**kw)
        cls.optional = tuple(f.name for f in dataclasses.fields(cls.Params))  # every parameter

    @classmethod
    def null(cls, plant):
        return {f.name: 0.0 for f in cls.fields()}

    #: what the term's value is at its hook: "pressure" [Pa] (times the plunger area, a force) or "force" [N]
    acts_as = "pressure"

    def _added(self, params, values) -> np.ndarray:
        """What the term adds at its hook [Pa or N] over the rig's operating envelope (see :meth:`check_size`)."""
        raise NotImplementedError

    def check_size(self, params, where: str = "effects") -> None:
        """Refuse a term whose largest force over the rig's operating envelope would move the stroke past the
        longest stroke built: the term's own bounds (+-1e12) are the open search's, not the rig's, and a
        ``line_term`` ``const = 1e12`` Pa simulated to a 1.2e10 m stroke with exit 0.

        The term is taken at rest at its own centre: the pressure at p_0, the stroke at ``x_mean``, the stretch at
        ``rel_median``, the velocity 0 either way: what is left is its constant and its direction-dependent
        (Coulomb-like) part, a force that shifts the stroke.  A velocity feature is damping (a diagnosis finds
        ``line_term`` ``v_abs_v`` ~ -3e6 Pa s^2/m^2, a turbulent drop) and a stretch or stroke feature a stiffer
        spring (``rel_cubed`` ~ 8e9 N/m^3 on a stretch of cm), not a shift: if one is large or active enough to
        make the stepper run away, its divergence names the effect (:mod:`heavecomp.simulate.core`).
        The force (a pressure times the plunger area) moves the stroke by F / k_eff on the
        rig's springs in series (paper A eq. 14); more than ``STROKE_MAX`` is no compensator.  One line naming
        ``where``.key (the parameter whose term is largest alone) and the numbers.

        Parameters
        ----------
        params : CMCParams
            The plant the term is added to.
        where : str
            The entry's place in the file (``effects[0]``).
        """
        scale = params.area if self.acts_as == "pressure" else 1.0
        limit = params.k_eff * STROKE_MAX
        big = float(np.max(np.abs(self._added(params, self.values)))) * scale
        if not big > limit:  # NaN-safe: an overflow (inf) is refused too
            if np.isfinite(big):
                return
        null = self.null(None)
        alone = {k: float(np.max(np.abs(self._added(params, {**null, k: v})))) * scale
                 for k, v in self.values.items() if v != null.get(k) and k not in LEVELS.values()}
        key = max(alone, key=lambda k: alone[k]) if alone else next(iter(self.values))
        unit = next((f.metadata.get("unit", "") for f in self.fields() if f.name == key), "")
        raise ParameterError(
            f"{where}.{key} = {self.values[key]:g} {unit}: the {self.name} adds {big:.3g} N at the {self.hook} "
            f"hook at rest, which would move the stroke {big / params.k_eff:.3g} m on its "
            f"springs (k_eff {params.k_eff:.4g} N/m), past the longest stroke built ({STROKE_MAX:g} m): no rig has it "
            "and the simulation runs away")


class LineTerm(_Term):
    """p_cyl -> p_cyl + c_0 + c_v v + c_vv v|v| + c_a |v| + c_p p (the flow_line residual's term)."""

    name = "line_term"
    hook = "line"
    component_name = "flow_line"

    @dataclass(frozen=True)
    class Params:
        const: float = q(0.0, "Pa", symbol="c_0", doc="constant pressure added", **_V)
        v: float = q(0.0, "Pa s/m", symbol="c_v", doc="pressure added per stroke velocity", **_V)
        v_abs_v: float = q(0.0, "Pa s^2/m^2", symbol="c_vv", doc="pressure added per v|v|", **_V)
        abs_v: float = q(0.0, "Pa s/m", symbol="c_a", doc="pressure added per |v|", **_V)
        p: float = q(0.0, "-", bounds=(-1.0, 1.0), symbol="c_p", doc="pressure added per pressure")

    @staticmethod
    def line(v, p, x, PP, c0, cv, cvv, ca, cp):
        return p + c0 + cv * v + cvv * v * np.abs(v) + ca * np.abs(v) + cp * p

    def _added(self, params, values):
        v, p = _envelope(), params.p0
        return self.line(v, p, None, None, *values.values()) - p



class GasTerm(_Term):
    """p_gas -> p_gas + c_0 + c_x (s - x_mean) + c_v v + c_vv v|v| + c_a |v| (the gas_spring residual's term)."""

    name = "gas_term"
    hook = "gas_spring"
    component_name = "gas_spring"

    @dataclass(frozen=True)
    class Params:
        const: float = q(0.0, "Pa", symbol="c_0", doc="constant pressure added", **_V)
        x: float = q(0.0, "Pa/m", symbol="c_x", doc="pressure added per m of stroke from x_mean", **_V)
        x_mean: float = q(0.0, "m", bounds=(-100.0, 100.0), symbol="x_m", doc="the stroke the x feature is taken from")
        v: float = q(0.0, "Pa s/m", symbol="c_v", doc="pressure added per stroke velocity", **_V)
        v_abs_v: float = q(0.0, "Pa s^2/m^2", symbol="c_vv", doc="pressure added per v|v|", **_V)
        abs_v: float = q(0.0, "Pa s/m", symbol="c_a", doc="pressure added per |v|", **_V)

    @staticmethod
    def gas(s, v, p, x, PP, c0, cx, xm, cv, cvv, ca):
        return p + c0 + cx * (s - xm) + cv * v + cvv * v * np.abs(v) + ca * np.abs(v)

    def _added(self, params, values):
        v, p = _envelope(), params.p0
        return self.gas(values["x_mean"], v, p, None, None, *values.values()) - p



class StringTerm(_Term):
    """T_ds -> T_ds + c_0 + c_v dv + c_vv dv|dv| + c_a |dv| + c_+ [dv>0] - c_- [dv<0]
    + c_r e + c_rr e|e| + c_rrr e^3, e = rel - rel_m (the string_formation residual's term).

    ``rel`` is the string's stretch z_h + s - y_b [m], the displacement the open search's ``rel`` features
    are taken of (:func:`heavecomp.diagnosis.equation_error.library`, centred on their median ``rel_m``).
    The hook is handed the tension, not the stretch: it recovers the stretch by inverting the nominal
    string law T = T_0 + k_ds rel + c_ds dv (:func:`heavecomp.plants.cmc.tension`), rel = (T - T_0 - c_ds
    dv) / k_ds.  That is exact when no other string effect precedes this one at the hook: every composition
    applies the hook terms first at their hook (:func:`heavecomp.effects.compose.hook_order`), so the
    tension it is handed is the nominal one, whatever order the file lists its effects in.
    """

    name = "string_term"
    hook = "string"
    component_name = "string_formation"

    @dataclass(frozen=True)
    class Params:
        const: float = q(0.0, "N", symbol="c_0", doc="constant tension added", **_V)
        v: float = q(0.0, "N s/m", symbol="c_v", doc="tension added per relative velocity", **_V)
        v_abs_v: float = q(0.0, "N s^2/m^2", symbol="c_vv", doc="tension added per dv|dv|", **_V)
        abs_v: float = q(0.0, "N s/m", symbol="c_a", doc="tension added per |dv|", **_V)
        sign_v_pos: float = q(0.0, "N", symbol="c_+", doc="tension added while the string extends (dv > 0)", **_V)
        sign_v_neg: float = q(0.0, "N", symbol="c_-", doc="tension taken off while the string shortens (dv < 0; "
                                                         "feature sign(dv)*(dv<0))", **_V)
        rel: float = q(0.0, "N/m", symbol="c_r", doc="tension added per m of stretch from rel_median", **_V)
        rel_abs_rel: float = q(0.0, "N/m^2", symbol="c_rr", doc="tension added per e|e| (e the stretch from "
                                                                "rel_median)", **_V)
        rel_cubed: float = q(0.0, "N/m^3", symbol="c_rrr", doc="tension added per e^3 (e the stretch from "
                                                               "rel_median)", **_V)
        rel_median: float = q(0.0, "m", bounds=(-100.0, 100.0), symbol="rel_m",
                              doc="the stretch the rel features are taken from (the log's median stretch)")

    @staticmethod
    def string(dv, T, x, PP, c0, cv, cvv, ca, cp, cn, cr, crr, crrr, rm):
        e = (T - PP[T0] - PP[CDS] * dv) / PP[KDS] - rm  # the stretch from rel_m, by the nominal string law
        sv = np.sign(dv)
        return (T + c0 + cv * dv + cvv * dv * np.abs(dv) + ca * np.abs(dv) + cp * np.maximum(sv, 0.0)
                + cn * np.minimum(sv, 0.0) + cr * e + crr * e * np.abs(e) + crrr * e * e * e)

    acts_as = "force"

    def _added(self, params, values):
        PP = plant_vector(params)
        dv = _envelope()
        T = PP[T0] + PP[CDS] * dv + PP[KDS] * values["rel_median"]  # the stretch at rel_median: e = 0
        return self.string(dv, T, None, PP, *values.values()) - T


def _envelope() -> np.ndarray:
    """Velocities at rest [m/s]: 0 and a vanishing one either way (a direction-dependent term's sign).  The
    velocity terms are damping there, not a force (a dissipative one holds the stroke, an active one makes
    the stepper run away, and its divergence names the effect)."""
    return np.array([-1e-12, 0.0, 1e-12])



#: component -> the effect that carries its open-search term
BY_COMPONENT = {c.component_name: c for c in (LineTerm, GasTerm, StringTerm)}


def carried(component: str, features) -> type | None:
    """The effect class that carries the open search's ``features`` on ``component``, or None when the
    component has none or a feature has no form at its hook.

    Parameters
    ----------
    component : str
        The discovered term's component.
    features : sequence of str
        The open search's feature names.
    """
    cls = BY_COMPONENT.get(component)
    if cls is None or not features:
        return None
    names = {f.name for f in cls.fields()} - set(LEVELS.values())
    return cls if all(f in names for f in features) else None


#: feature -> the constant it is centred on (a parameter of the carrying effect, recorded by the open
#: search in ``verdict.discovered.levels``)
LEVELS = {"x": "x_mean", "rel": "rel_median", "rel_abs_rel": "rel_median", "rel_cubed": "rel_median"}


def levels_needed(features) -> set:
    """The centring constants (:data:`LEVELS`) the open search's ``features`` are taken from.

    Parameters
    ----------
    features : sequence of str
        The open search's feature names.
    """
    return {LEVELS[f] for f in features if f in LEVELS}


EFFECT = LineTerm
