"""Array layout shared by the compiled steppers and their callers (no numba import here).

Besides the channel and stats names, it holds the two argument tuples of the stepper
(:mod:`heavecomp.simulate.stepper`): :class:`Plant` (the plant and its effects) and
:class:`Drive` (what drives it: the active force and the heave samples), and named index
constants generated from :data:`CHANNELS` and :data:`STATS`: ``COL_<CHANNEL>`` is the column
of a channel in the stepper's ``out`` array (``COL_WOB``), ``STAT_<NAME>`` the slot of a
statistic in its ``stats`` array (``STAT_N_STICK``).
"""

import collections

STUCK = 0
SLIDING = 1

#: output channels, in column order of the stepper's ``out`` array
CHANNELS = ("t", "heave", "stroke", "pressure", "wob", "stroke_velocity", "friction", "tension",
            "lower_displacement", "lower_velocity", "stuck", "u_active")
NCH = len(CHANNELS)
#: extra channels written by the stepper when ``out`` has room (after CHANNELS): the gas
#: pressure before the line and the first three effect states X[4], X[5], X[6] (slots of ``effects.compose``;
#: a composition with more records these three)
FX_CHANNELS = ("gas_pressure", "effect_state_4", "effect_state_5", "effect_state_6")
#: slots of the ``stats`` array: time stuck [s]; counts of stick, breakaway, reversal events;
#: steps that hit the event cap (more than 8 events in one step, finished without event
#: checks) and the time [s] of the first such step (0 while there is none); bit contact switches
STATS = ("stuck_time", "n_stick", "n_breakaway", "n_reversal", "event_cap_hits", "n_contact_switch",
         "event_cap_first_t")
NSTATS = len(STATS)


def _index_constants(prefix: str, names) -> dict:
    return {f"{prefix}{name.upper()}": i for i, name in enumerate(names)}


# COL_T, COL_HEAVE, ..., COL_U_ACTIVE; COL_GAS_PRESSURE (= NCH), COL_EFFECT_STATE_4, ...;
# STAT_STUCK_TIME, STAT_N_STICK, ..., STAT_EVENT_CAP_FIRST_T (numba reads them as constants)
globals().update(_index_constants("COL_", CHANNELS + FX_CHANNELS))
globals().update(_index_constants("STAT_", STATS))

#: the plant as the stepper takes it: friction law code, friction vector FP, plant vector PP
#: (:func:`heavecomp.plants.cmc.plant_vectors`), effect parameters EP of the stepper's composition
#: (:meth:`heavecomp.effects.compose.Composition.ep`; empty without effects) and ``smooth`` (True
#: when nothing jumps with sign(v): one smooth system)
Plant = collections.namedtuple("Plant", ("code", "FP", "PP", "EP", "smooth"))
#: what drives the plant: active-cylinder force u [N] and the heave samples (z, dz, ddz) spaced sp [s]
Drive = collections.namedtuple("Drive", ("u", "sp", "Z", "DZ", "DDZ"))

#: files whose source the nominal compiled stepper is built from: the functions numba compiles or
#: inlines and the constants they read (the ahead-of-time build and the numba cache are keyed to them)
KERNEL_SOURCES = ("friction/laws.py", "plants/cmc.py", "params/cmc.py", "effects/compose.py",
                  "simulate/_kernel.py", "simulate/layout.py")


def source_hash() -> int:
    """63-bit hash of the stepper's source files (:data:`KERNEL_SOURCES`)."""
    import hashlib
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    h = hashlib.sha256()
    for rel in KERNEL_SOURCES:
        h.update((root / rel).read_bytes())
    return int(h.hexdigest()[:15], 16)
