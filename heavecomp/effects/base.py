"""Effects as submodels at the CMC's hooks.

The CMC (:mod:`heavecomp.plants.cmc`) has named hook points, each with a "none"
default (the nominal equation).  An effect is one class in one file of
:mod:`heavecomp.effects`: its parameters (a frozen dataclass of :func:`heavecomp.params.core.q`
fields: unit, bounds, symbol; the default is the fit's initial guess), its extra states and
its ``np.*`` terms, one static method per hook it acts at.  numba compiles those methods
into the stepper (:func:`heavecomp.simulate._kernel.kernel_for`) and casadi traces the very
same source (:func:`heavecomp.effects.model.casadi_model`), so ``simulate``, ``linearise``, the
MPCs and the diagnosis accept any effect.

Hooks (:data:`HOOKS`).  Every method gets the value so far at its hook and returns the
new one (effects at one hook are chained in the composition's order: the open search's hook
terms first, then registry order, :func:`heavecomp.effects.compose.hook_order`); ``x`` is the tuple of the
effect's own states, ``*prm`` its parameters in the order of the ``Params`` fields:

=============  =================================================  ======================================
hook (slot)    method                                             nominal ("none")
=============  =================================================  ======================================
gas spring     ``gas(s, v, p, x, PP, *prm) -> p_gas [Pa]``        polytropic, fixed charge
line           ``line(v, p, x, PP, *prm) -> p_cyl [Pa]``          lossless, p_cyl = p_gas
               ``line_mass(v, m, x, PP, *prm) -> m [kg]``         no oil inertia, m = 0
                                                                  (the oil's inertance I A^2: the stroke
                                                                  accelerates as M_c + m, the cylinder
                                                                  reads p_cyl - m a / A)
string         ``string(dv, T, x, PP, *prm) -> T_ds [N]``         spring + dashpot (dv = dz_h + v - v_b)
seal friction  ``jump(code, a, p, J, s, d, x, FP, *prm) -> J``    the friction law's J [N] (paper A eq. 4/6/7)
               ``static(code, p, lim, tau, s, d, x, FP, *prm)``   static limit J(0, p) [N]; tau = dwell time
                                                                  (``lim`` is J at v = 0 in direction d
                                                                  through the ``jump`` hooks: add to it,
                                                                  never lower it, see below)
states         ``rates(s, v, p, x, PP, FP, *prm) -> dx/dt``       (no extra states)
               ``string_rates(dv, e, x, PP, *prm) -> dx/dt``      (a string effect's states: e the
                                                                  string's stretch z_h + s - y_b from the
                                                                  operating point, dv its rate)
               ``initial(FP, PP, *prm) -> x`` at rest,
               ``steady(v, FP, PP, *prm) -> x`` sliding at v
               (None: a slow state, carried over a restart)
measured       ``apply(t, tg, y, *prm) -> y_meas``                ideal sensor
               (:class:`ChannelEffect`, on the recorded channel)
heave input    ``seen(t, z, *prm) -> z`` (:class:`HeaveEffect`)    measured = seen
=============  =================================================  ======================================

At the seal-friction hook ``s`` is the stroke [m] and ``d`` the direction of the (impending) motion:
+1 while the stroke grows (v > 0, extending), -1 while it shrinks (retracting); at rest the sign of
the holding force that would start the motion; in the smooth casadi model tanh(v / eps).

The static limit an effect's ``static`` receives already has every ``jump`` hook applied at v = 0 in the
direction ``d``: an effect that scales J scales the static limit through its ``jump`` alone.  ``static``
adds what rest alone brings (``dwell_stiction``'s gain with the dwell time) and must not lower the limit
below that J: at a stop the stepper reverses the stroke when the holding force exceeds the limit, and the
motion can only start if the sliding friction at v = 0 is no larger (``tests/test_conformance.py``,
``test_static_limit_holds_the_friction_the_motion_starts_against``).

A method must use ``np.*`` only and branch on parameters or the law ``code``, never on a
state (casadi traces it).  ``PP`` / ``FP`` are indexed by the named constants of
:mod:`heavecomp.plants.cmc` / :mod:`heavecomp.friction.laws`.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from heavecomp.errors import ParameterError, did_you_mean

#: hook slot -> the methods an effect defines there (kernel hooks first; ``channel`` and
#: ``heave`` act outside the kernel)
HOOKS = {"seal_friction": ("jump", "static"), "gas_spring": ("gas",), "line": ("line", "line_mass"),
         "string": ("string",), "channel": (), "heave": ()}
#: model components of the gap diagnosis (contract schema 2, ``where.components``), in report order
COMPONENTS = ("friction", "gas_spring", "flow_line", "string_formation", "sensors", "heave_input")
#: the component each hook belongs to
HOOK_COMPONENT = {"seal_friction": "friction", "gas_spring": "gas_spring", "line": "flow_line",
                  "string": "string_formation", "channel": "sensors", "heave": "heave_input"}
#: the methods the stepper and the casadi model call, in the order they are composed
METHODS = ("gas", "line", "line_mass", "string", "jump", "static", "rates", "string_rates")
#: measured channels a channel effect (:class:`ChannelEffect`) may act on
SENSOR_CHANNELS = ("wob", "stroke", "pressure", "heave")


@dataclasses.dataclass(frozen=True)
class FitSpec:
    """How the gap diagnosis fits an effect: everything on an effect class that is not its physics
    (``fit = FitSpec(...)`` on the class; every field has a default)."""

    candidate: bool = False
    """The gap diagnosis fits it by default (the contract's effects, ``diagnosis-contract.md``)."""
    log: tuple = ()
    """Parameters fitted on a log scale."""
    feature_grid: tuple = ()
    """Values of one nonlinear shape parameter searched by the equation-error fit (empty: none)."""
    feature_shape: tuple | None = None
    """(name, unit) of that shape parameter (None: the effect has none)."""
    feature_units: dict = dataclasses.field(default_factory=dict)
    """Units of the equation-error coefficients (``features``) by column name."""
    screened: bool = True
    """Its component's equation residual sees the effect wherever it acts (the gap diagnosis may then
    skip its replay when that component shows no gap); False where the residual is blind to it (e.g. a
    breakaway force, a damping below the balance's noise)."""
    optional: tuple = ()
    """Parameters fitted only when they pay (held at their null value otherwise, and then not counted
    in the parsimony penalty); empty: every parameter is always fitted."""
    limits: tuple = ()
    """Parameters whose search bounds are the ends of their physical range (e.g. a share in [0, 1]): a
    fit at such a bound is an answer, not a sign that the effect stands in for another."""
    rugged: tuple = ()
    """Parameters whose fit cost is rugged (stick-slip timing jumps with them): the diagnosis rescans
    them over their search box for a second start."""
    linear: bool = False
    """A channel reading affine in its parameters (fitted by linear least squares)."""
    released_last: tuple = ()
    """Parameters held at their defaults while the others are fitted as before (coarse start grid and
    Nelder-Mead for two), then released together from that optimum by least squares: a parameter that
    refines the others' law never leaves the fit on the fit part worse than the fit without it."""
    family: str = ""
    """The contract's name the diagnosis reports this effect under (``diagnosis-contract.md``, the effect
    table), when the effect is one law of a broader class: ``friction_memory`` (a memory over sliding
    distance) is a law of ``friction_lag`` (frictional memory).  Empty: the effect's own ``name``."""
    law: str = ""
    """The law of the family this effect is (``"time"``, ``"distance"``): the verdict names the family and
    carries the law (``verdict.law``) and the effect fitted (``verdict.member``).  Empty: no family of laws."""
    coefficients: dict = dataclasses.field(default_factory=dict)
    """Equation-error columns whose coefficient is a parameter itself, in its unit (column name -> parameter
    name): the default :meth:`Effect.from_equation_error` reads each (:meth:`Effect.coefficient_value`) as
    the replay fit's start; empty: the effect writes its own, or has none."""
    smooth: bool = False
    """The replay responds smoothly to every parameter (no stick event's timing jumps with it: a damping,
    not a friction force): the diagnosis fits it by Gauss-Newton (bounded least squares) from its start,
    with no coarse grid and no Nelder-Mead, and a fit from the score test starts at the test's step
    (:func:`heavecomp.diagnosis.score_test.start`)."""
    probes: tuple = ()
    """Parameter sets (tuples of (name, value) pairs) the diagnosis's score test replays an unscreened
    candidate at before a full fit (:mod:`heavecomp.diagnosis.score_test`): a moderate amplitude at two or
    three values of its shape parameter (a lag time, a relaxation length, an exponent), each a secant
    column of the replay's Jacobian from the null; empty: no score test (the candidate is always fitted)."""


class Effect:
    """Base class of an effect (a submodel at one of the plant's hooks): its physics, plus how the gap
    diagnosis fits it (``fit``, a :class:`FitSpec`).

    Class attributes: ``name`` (the contract name), ``hook`` (a key of :data:`HOOKS`),
    ``Params`` (frozen dataclass), ``states`` (names of extra states), ``adds_stiction``
    (adds friction that jumps with sign(v): the stepper must treat even a smooth law as
    stick-slip), ``kind`` (``"plant"``: terms at kernel hooks; ``"output"``: acts on a
    measured channel; ``"nominal"``: refits nominal parameters), ``fit`` (log-scaled parameters,
    ``candidate``: fitted by default, equation-error grid and units, ...).  The fields of ``fit`` are
    mirrored as read-only class attributes of the same names (``cls.log``, ``cls.feature_grid``, ...)
    for older readers; set them on ``fit``.  An instance carries parameter values:
    ``FlowLoss(resistance=2e5)``.

    Parameters
    ----------
    **values : float
        Parameter values [SI; each field's ``unit`` metadata] by field name of ``Params``;
        an unknown name raises :class:`heavecomp.errors.ParameterError`.
    """

    name: str = ""
    hook: str = ""
    Params: type = None
    states: tuple = ()
    adds_stiction: bool = False
    kind: str = "plant"
    fit: FitSpec = FitSpec()
    #: True for a reading whose dynamics are read on the model side (the replay's prediction read through
    #: them, :mod:`heavecomp.effects.sensor_lag`), never undone on the log
    model_side: bool = False
    # hook methods (staticmethods in subclasses); None: the effect does not act there
    gas = line = line_mass = string = jump = static = rates = string_rates = initial = steady = None

    def __init_subclass__(cls, **kw):
        super().__init_subclass__(**kw)
        _mirror_fit(cls)

    @classmethod
    def component(cls) -> str:
        """The model component the effect lives in (:data:`COMPONENTS`; from its hook)."""
        return HOOK_COMPONENT.get(cls.hook, "")

    @classmethod
    def features(cls, sig, shape=None):
        """Equation-error regressors (issue 12 item 3): columns, linear in their coefficients, that
        this effect adds to its component's equation residual, built from measured signals only.

        ``sig`` maps signal names to arrays at the same samples (which names a plant provides:
        ``heavecomp.diagnosis.components``; at least ``t`` [s], ``x`` position of the sliding
        element [m], ``v`` [m/s], ``a`` [m/s^2], ``dwell`` time at rest so far [s], and ``p`` [Pa]
        where the plant has a pressure); ``shape`` is one value of :attr:`feature_grid` (None when
        the grid is empty).  Returns ``{column name: array}``, or None when the effect has no
        equation-error form or a signal it needs is missing.

        The CMC adds: ``heave`` measured heave z_h [m], ``heave_velocity`` [m/s], ``wob`` [N],
        ``dz`` the drill string's extension from the measured signals [m] (tension
        T_ds = T_0 + k_ds dz: more tension, less WOB), ``p_gas_abs`` the nominal gas spring's
        absolute pressure at the measured stroke [Pa] and ``p_charge_abs`` its absolute pre-charge
        at stroke 0 [Pa] (a number), and, for the ``sensors`` component, ``y`` the measured
        channel whose residual is fitted (its SI unit).  Residuals are measured minus nominal, so a
        column is the effect's contribution to the measured quantity per unit coefficient.
        """
        return None

    def __init__(self, **values):
        names = [f.name for f in self.fields()]
        for k in values:
            if k not in names:
                raise ParameterError(f"effect {self.name}: unknown parameter {k!r}{did_you_mean(k, names)}; "
                                     f"parameters: {', '.join(names)}")
        self.params = self.Params(**values)

    def __repr__(self):
        return f"{type(self).__name__}({', '.join(f'{k}={v!r}' for k, v in self.values.items())})"

    @property
    def values(self) -> dict:
        """Parameter values by name [SI]."""
        return {f.name: getattr(self.params, f.name) for f in self.fields()}

    @property
    def prm(self) -> tuple:
        """Parameter values in field order (the ``*prm`` of the hook methods)."""
        return tuple(float(getattr(self.params, f.name)) for f in self.fields())

    @classmethod
    def methods(cls) -> tuple:
        """The hook methods this effect defines (subset of :data:`METHODS`)."""
        return tuple(m for m in METHODS if getattr(cls, m) is not None)

    @classmethod
    def for_input(cls, hs) -> type:
        """The class to fit for the replay's heave samples ``hs``
        (:class:`heavecomp.simulate.excitation.HeaveSamples`): this one; an effect with parameters
        that need an input the run may lack returns a variant without them (``heave_reference``
        without a logged angle)."""
        return cls

    @classmethod
    def from_equation_error(cls, fit, sig) -> dict | None:
        """Parameter values [SI] that the equation-error fit ``fit`` (a row of
        :func:`heavecomp.diagnosis.equation_error.rank_effects`: ``coefficients``, ``shape``) of this
        effect's :meth:`features` on signals ``sig`` stands for: a start for the replay's fit; None
        when the features do not fix every parameter.  The default reads ``fit.coefficients`` (each
        listed column's coefficient as its parameter, inside its bounds): None when it lists none or the
        fit lacks one of them."""
        values = {param: cls.coefficient_value(fit, col, param) for col, param in cls.fit.coefficients.items()}
        return values if values and None not in values.values() else None

    @classmethod
    def coefficient_value(cls, fit, feature, param) -> float | None:
        """Parameter ``param`` [SI] read as the equation-error coefficient of ``feature`` itself (a
        feature whose coefficient is that parameter, in its unit), inside the parameter's bounds (a
        coefficient of the wrong sign sits at the bound); None when the fit has no such coefficient.
        The helper of :meth:`from_equation_error` where one coefficient is one parameter."""
        coef = (fit or {}).get("coefficients") or {}
        if feature not in coef or not np.isfinite(coef[feature]):
            return None
        lo, hi = cls.Params.__dataclass_fields__[param].metadata["bounds"]
        return float(min(max(float(coef[feature]), lo), hi))

    @classmethod
    def null(cls, plant) -> dict | None:
        """Parameter values at which the effect reproduces the nominal plant bit for bit
        (``plant``: :class:`heavecomp.plants.cmc.PlantVectors`), or None when it has none
        (e.g. a memory whose zero time constant is singular)."""
        return None

    # --- metadata and the fit vector ----------------------------------------
    @classmethod
    def fields(cls):
        return dataclasses.fields(cls.Params)

    @classmethod
    def n_params(cls) -> int:
        return len(cls.fields())

    @classmethod
    def describe(cls) -> list[dict]:
        """Name, unit, bounds, symbol and initial guess of every parameter."""
        return [{"name": f.name, "unit": f.metadata["unit"], "bounds": list(f.metadata["bounds"]),
                 "symbol": f.metadata.get("symbol"), "initial": f.default, "doc": f.metadata.get("doc", "")}
                for f in cls.fields()]

    @classmethod
    def x0(cls) -> np.ndarray:
        """The fit's start: the defaults, a ``limits`` parameter at a bound moved 1e-9 inside (the
        fitters clip their start into the open box the same way)."""
        x = cls.to_x({f.name: f.default for f in cls.fields()})
        if cls.fit.limits:
            lo, hi = cls.bounds_x()
            at = np.array([f.name in cls.fit.limits for f in cls.fields()])
            x = np.where(at, np.clip(x, lo + 1e-9, hi - 1e-9), x)
        return x

    @classmethod
    def search_box(cls, params):
        """Bounds of the fit vector on the parameter set ``params`` the fit runs against: the fields'
        bounds (:meth:`bounds_x`); a candidate whose box depends on the file overrides it."""
        return cls.bounds_x()

    @classmethod
    def bounds_x(cls):
        lo, hi = [], []
        for f in cls.fields():
            a, b = f.metadata["bounds"]
            if f.name in cls.fit.log:
                a, b = np.log(a), np.log(b)
            lo.append(a)
            hi.append(b)
        return np.array(lo), np.array(hi)

    @classmethod
    def to_x(cls, values: dict) -> np.ndarray:
        return np.array([np.log(values[f.name]) if f.name in cls.fit.log else values[f.name] for f in cls.fields()])

    @classmethod
    def from_x(cls, x) -> dict:
        return {f.name: float(np.exp(xi) if f.name in cls.fit.log else xi) for f, xi in zip(cls.fields(), x)}


def _mirror_fit(cls) -> None:
    """The fields of ``cls.fit`` as class attributes of the same names (``feature_shape`` only when
    set: readers test for it).  A class written with the loose attributes instead (``feature_grid =
    ...`` on the class, no ``fit`` of its own) gets them as its ``fit``."""
    loose = {f.name: cls.__dict__[f.name] for f in dataclasses.fields(FitSpec) if f.name in cls.__dict__}
    if loose and "fit" not in cls.__dict__:
        cls.fit = dataclasses.replace(cls.fit, **loose)
    for f in dataclasses.fields(FitSpec):
        value = getattr(cls.fit, f.name)
        if f.name == "feature_shape" and value is None:
            continue
        setattr(cls, f.name, value)


_mirror_fit(Effect)


class ChannelEffect(Effect):
    """Base of an effect on one measured channel (hook ``channel``, ``kind = "output"``): the plant is
    nominal, the recorded channel misreads.  ``apply(t, tg, y, *prm)`` gives the recorded channel at
    times ``t`` [s] from the true one ``y`` on the grid ``tg`` [s]; an instance names its channel
    (:data:`SENSOR_CHANNELS`): ``SensorGain(channel="wob", factor=1.08)``.

    Parameters
    ----------
    channel : str
        The measured channel that misreads (one of :data:`SENSOR_CHANNELS`).
    **values : float
        Parameter values [SI] by field name of ``Params``.
    """

    hook = "channel"
    kind = "output"
    apply = None
    #: parameters of a reading's dynamics around a static map that carries something of its own (a
    #: factor): a finite-state, time-invariant model (the controllers') reads the channel through the
    #: static map, with these at their :meth:`null` values (:meth:`static_map`), and says what it leaves
    #: out.  Empty: the whole reading must be static, else the model refuses it.
    dynamic_params: tuple = ()

    def __init__(self, channel: str = "wob", **values):
        if channel not in SENSOR_CHANNELS:
            raise ParameterError(f"effect {self.name}: unknown channel {channel!r}{did_you_mean(channel, SENSOR_CHANNELS)}; "
                                 f"channels: {', '.join(SENSOR_CHANNELS)}")
        self.channel = channel
        super().__init__(**values)

    def __repr__(self):
        vals = "".join(f", {k}={v!r}" for k, v in self.values.items())
        return f"{type(self).__name__}(channel={self.channel!r}{vals})"

    def static_map(self):
        """The same reading with its :attr:`dynamic_params` at their :meth:`null` values (itself when it
        has none): its static map."""
        if not self.dynamic_params:
            return self
        null = self.null(None)
        return type(self)(channel=self.channel, **{**self.values, **{k: null[k] for k in self.dynamic_params}})

    def undo_reading(self, t, y, cols=None):
        """The true channel from the reading ``y`` at times ``t``: an affine reading (``fit.linear``)
        inverted exactly, a pure delay shifted back (unknown past the log's end: NaN); an effect with an
        explicit correction overrides this (``cols``: the log's channels, for a reading that reads them).

        Parameters
        ----------
        t : numpy.ndarray [s]
            Times of the reading.
        y : numpy.ndarray [unit of the channel]
            The reading.
        cols : dict, optional
            The log's channels by name.
        """
        if self.linear:  # affine reading y_meas = a0(t) + a1(t) y: invert it
            a0 = self.apply(t, t, np.zeros_like(y), *self.prm)
            a1 = self.apply(t, t, np.ones_like(y), *self.prm) - a0
            if np.any(np.abs(a1) < 1e-12):
                raise ParameterError(f"effect {self.name} on {self.channel}: a reading factor of 0 cannot be undone")
            return (y - a0) / a1
        if set(self.values) == {"delay"}:  # y_meas(t) = y(t - t_d): y(t) = y_meas(t + t_d), unknown past the end
            d = float(self.values["delay"])
            return np.interp(t + d, t, y, right=np.nan)
        raise ParameterError(f"effect {self.name}: no inverse of its reading is known; it cannot correct a log")

    def measure(self, t, tg, y, motion=None):
        """The recorded channel at times ``t`` from the true ``y`` on the grid ``tg`` (``motion``: the
        string top's position z_h + s [m], for a reading that depends on it, e.g. ``sensor_term``'s
        ``*_motion`` terms; the library's readings do not)."""
        return self.apply(np.asarray(t, dtype=float), np.asarray(tg, dtype=float), np.asarray(y, dtype=float),
                          *self.prm)


class HeaveEffect(Effect):
    """Base of an effect on the heave input (hook ``heave``, ``kind = "heave"``): the heave the
    compensator sees is not the measured one.  ``seen(t, z, *prm)`` maps a measured heave series
    (or its derivatives: the map is linear and time-invariant) on the uniform grid ``t`` [s] to the
    one the plant sees."""

    hook = "heave"
    kind = "heave"
    seen = None
    #: parameters that act through a logged vessel angle (``HeaveSamples.angle``), not through ``seen``
    angle_params: tuple = ()

    def transform(self, hs):
        """The heave samples the plant sees (:class:`heavecomp.simulate.excitation.HeaveSamples`)
        from the measured ones ``hs``."""
        t = hs.t
        return dataclasses.replace(hs, z=self.seen(t, hs.z, *self.prm), dz=self.seen(t, hs.dz, *self.prm),
                                   ddz=self.seen(t, hs.ddz, *self.prm),
                                   info={**hs.info, "heave_effect": repr(self)},
                                   kink=hs.kink if self.null_like() else None)

    def null_like(self) -> bool:
        """True when the effect leaves the heave as it is (its :meth:`null` values)."""
        n = self.null(None)
        return n is not None and all(self.values[k] == v for k, v in n.items())
