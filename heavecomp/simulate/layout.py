"""Array layout shared by the compiled steppers and their callers (no numba import here)."""

STUCK = 0
SLIDING = 1

#: output channels, in column order of the stepper's ``out`` array
CHANNELS = ("t", "heave", "stroke", "pressure", "wob", "stroke_velocity", "friction", "tension",
            "lower_displacement", "lower_velocity", "stuck", "u_active")
NCH = len(CHANNELS)
#: extra channels written by ``_kernel.advance_fx`` when ``out`` has room (after CHANNELS): the gas
#: pressure before the line and the first three effect states X[4], X[5], X[6] (slots of ``effects.compose``;
#: a composition with more records these three)
FX_CHANNELS = ("gas_pressure", "effect_state_4", "effect_state_5", "effect_state_6")
#: slots of the ``stats`` array: time stuck [s]; counts of stick, breakaway, reversal events;
#: steps that hit the event cap (more than 8 events in one step, finished without event
#: checks) and the time [s] of the first such step (0 while there is none); bit contact switches
STATS = ("stuck_time", "n_stick", "n_breakaway", "n_reversal", "event_cap_hits", "n_contact_switch",
         "event_cap_first_t")
NSTATS = len(STATS)

#: files whose source the compiled stepper is built from (the AOT build is keyed to them)
KERNEL_SOURCES = ("friction/laws.py", "plants/cmc.py", "effects/compose.py", "simulate/_kernel.py",
                  "simulate/layout.py")


def source_hash() -> int:
    """63-bit hash of the stepper's source files (friction laws, CMC equations, effect terms, kernel)."""
    import hashlib
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    h = hashlib.sha256()
    for rel in KERNEL_SOURCES:
        h.update((root / rel).read_bytes())
    return int(h.hexdigest()[:15], 16)
