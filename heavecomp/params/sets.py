"""Named parameter sets.

Each set is a function returning a validated :class:`~heavecomp.params.cmc.CMCParams`;
its docstring is the citation and the list of assumptions.  ``SETS`` maps names
(as used by ``heavecomp params NAME``) to these functions.
"""

from __future__ import annotations

from heavecomp.params.cmc import CMCParams, from_dict


def paper_a(model: str = "stribeck") -> CMCParams:
    """Paper A load case: short drill string in a hard formation.

    Ottestad, Nilsen & Hansen, "Reducing the static friction in hydraulic
    cylinders by maintaining relative velocity between piston and cylinder",
    ICCAS 2012, tables 3-4 and section 4.

    Parameters
    ----------
    model : {"stribeck", "rotating_eq7", "rotating_eq6", "none"}
        Friction regime: full static friction (eq. 4), reduced static friction
        by a rotating piston (eq. 7, or eq. 6), or no friction.

    Notes
    -----
    Legible in the paper: heave 1 m sine, T = 12 s; WOB set-point 10 t g;
    k_gas = 46 kN/m (effective, after force equalizers); friction by eq. 4 with
    F_S = 23 kN, F_C = 12 kN, v_S = 10 mm/s, C_v = 10 kN s/m, C_p = 200 N/bar;
    drill string L = 300 m; formation k_F = 1000 kN/m.

    Assumptions and illegible values (the project's physics notes):

    - plunger diameter 0.72 m: digits uncertain in the OCR;
    - drill-string stiffness printed as "208 kN/m"; 300 m of drill pipe
      (EA ~ 6e8 N) gives ~2 MN/m, so 2.08 MN/m is used; ``scenarios/sensitivity.py``
      shows both;
    - moving masses are not legible: 80 t top mass (crown block, travelling
      block, top drive, plungers) and 30 t lumped string + BHA (assumed);
    - polytropic index 1.3 (assumed; nitrogen between isothermal and adiabatic);
    - drill-string damping 0 and formation damping 20 kN s/m (assumed);
    - tangential velocity of the rotating piston 0.05 m/s, taken from the
      test rig (table 1: omega ~ 0.77 rad/s on a 125 mm piston) — not stated
      for the CMC;
    - heave ramp 24 s (two periods), ours, so the start does not ring.
    """
    friction = {"model": model}
    if model != "none":
        friction.update(static_force=23e3, coulomb_force=12e3, stribeck_velocity=0.01,
                        viscous_coefficient=10e3, pressure_coefficient=2e-3)
        if model.startswith("rotating"):
            friction["tangential_velocity"] = 0.05
    return from_dict({
        "heave": {"kind": "sine", "amplitude": 1.0, "period": 12.0, "ramp": 24.0},
        "compensator": {"plunger_diameter": 0.72, "moving_mass": 80000.0, "gas_stiffness": 46e3,
                        "polytropic_index": 1.3},
        "friction": friction,
        "drill_string": {"stiffness": 2.08e6, "damping": 0.0, "lower_mass": 30000.0},
        "formation": {"stiffness": 1e6, "damping": 20e3},
        "operating_point": {"wob_setpoint": 98.1e3},
    })


#: name -> factory (``heavecomp params NAME`` writes it as TOML)
SETS = {"paper_a": paper_a}
