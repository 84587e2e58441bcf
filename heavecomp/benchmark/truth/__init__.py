"""The benchmark's truth laws: the generator's own effects, one file each, never the candidates'.

Each file holds one law: its own effect class (plugged into the plant's hooks through the same
mechanism as the library's effects, :mod:`heavecomp.effects.base`, but **not** registered) or its
own law on the logged channels, its draw, the parameter that sets its size and that size's cap
(:class:`~heavecomp.benchmark.truth.base.TruthLaw`).  No file imports a candidate's module
(:mod:`heavecomp.effects`): a benchmark whose generator used the candidates' equations would prove
nothing (``tests/test_benchmark_truth.py`` checks both).

======================  =================  ===========================================  ===============================
truth law               component          generated with (here)                         fitted with (candidate)
======================  =================  ===========================================  ===============================
friction_lag            friction           Stribeck curve of a lagged speed w            lagged Stribeck excess force E
dwell_stiction          friction           dF (1 - exp(-tau/tau_d))                      a tau^beta
pressure_friction       friction           k max(p - p_th, 0), p_th = 0.9 p_0            dC_p |p|
gas_heat_transfer       gas_spring         thermal state, gamma = 1.4, tau_th            n_eff + linear loss c_g v
flow_loss               flow_line          orifice K v|v|                                laminar R v
string_damping          string_formation   quadratic drag c_q dv|dv|                     linear dashpot c dv
sensor_delay            sensors            first-order sensor lag (causal IIR)           pure transport delay
parameter_mismatch      -                  nominal law, 2 parameters shifted             7 multipliers refitted
asymmetric_friction     friction           J (1 + alpha d), d a lagged direction
position_friction       friction           J (1 + beta parabolic bump in the stroke)
gas_leak                gas_spring         laminar leak of the gas mass fraction
sensor_gain             sensors            g LP(y), 5 Hz bandwidth; g = -1 (sign flip)
sensor_offset           sensors            absolute pressure, stroke zero, WOB warm-up drift
heave_reference         heave_input        lever arm x synthetic pitch, or an MRU high-pass
line_inertance          flow_line          oil column inertance (a law of flow_loss)
seal_warming            friction           J (1 - beta theta), seal temperature theta (outside)
stiffening_string       string_formation   T += k_3 e^3 (outside every name)
wob_saturation          sensors            the WOB load cell clips (outside every name)
stroke_backlash         sensors            the stroke read through a play (outside every name)
friction_memory         friction           LuGre bristle, length L_c g(v)/F_C, clipped   Dahl share delta, constant sigma
======================  =================  ===========================================  ===============================

The plant laws are compiled in two truth steppers (:func:`truth_composition`), each law off behind its slot until
a run switches it on: the benchmark's six (:data:`INSTALLED`, compiled at install: the scenarios and the fast
tests run them) and every other law in one more.  A run with some laws on is bit for bit the run of a stepper
holding those alone (the hooks of a law that is off add nothing, and its states move no other).
"""

from __future__ import annotations

from heavecomp.benchmark.truth import (asymmetric_friction, dwell_stiction, flow_loss, friction_lag, friction_memory,
                                      gas_heat_transfer,
                                      gas_leak, heave_reference, line_inertance, parameter_mismatch, position_friction,
                                      pressure_friction, seal_warming, sensor_delay, sensor_gain, sensor_offset,
                                      stiffening_string, string_damping, stroke_backlash, wob_saturation)
from heavecomp.benchmark.truth.base import Draw, Part, Setting, TruthLaw
from heavecomp.benchmark.truth.dwell_stiction import TruthDwell
from heavecomp.benchmark.truth.flow_loss import TruthOrifice
from heavecomp.benchmark.truth.gas_heat_transfer import TruthThermalGas
from heavecomp.effects.compose import composition

#: truth law name -> :class:`TruthLaw`, the registry (its order is the order of the compiled steppers' states)
LAWS = {m.LAW.name: m.LAW for m in (
    friction_lag, dwell_stiction, pressure_friction, gas_heat_transfer, flow_loss, string_damping, sensor_delay,
    parameter_mismatch, asymmetric_friction, position_friction, gas_leak, sensor_gain, sensor_offset, heave_reference,
    line_inertance, seal_warming, stiffening_string, wob_saturation, stroke_backlash, friction_memory)}
#: truth law name -> its own effect class, for every law that acts inside the plant
TRUTH = {n: law.plant for n, law in LAWS.items() if law.plant is not None}
#: truth law name -> model component (contract schema 2); ``none`` has none
COMPONENT = {**{n: law.component for n, law in LAWS.items()}, "none": None}
#: truth laws outside every contract name
OUT_OF_LIBRARY = tuple(n for n, law in LAWS.items() if not law.named)


#: the benchmark's six plant laws: their stepper is compiled at install (setup.py), and runs a plant with no law too
INSTALLED = ("friction_lag", "dwell_stiction", "pressure_friction", "gas_heat_transfer", "flow_loss", "string_damping")


def truth_composition(name=None):
    """The compiled truth stepper holding the plant law ``name``: the benchmark's six (:data:`INSTALLED`; also
    for None, or a law with no plant part), else the stepper of every other plant law (one compile for them all).

    Parameters
    ----------
    name : str or None
        A truth law of :data:`LAWS`.

    Returns
    -------
    heavecomp.effects.compose.Composition
        The composition of the plant laws of that stepper, in the order of :data:`LAWS`.
    """
    law = LAWS.get(name)
    installed = law is None or law.plant is None or name in INSTALLED
    return composition(tuple(x.plant for n, x in LAWS.items() if x.plant is not None and (n in INSTALLED) == installed))


__all__ = ["LAWS", "TRUTH", "COMPONENT", "OUT_OF_LIBRARY", "INSTALLED", "truth_composition", "Draw", "Part", "Setting",
           "TruthLaw", "TruthDwell", "TruthOrifice", "TruthThermalGas"]
