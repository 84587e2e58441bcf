"""Count which x1000 and /1000 unit slips in parameter files ``heavecomp`` catches.

Every numeric key of every shipped parameter set (``heavecomp.params.SETS``, in
each friction model, with an ``[active]`` table and with a JONSWAP sea) is
multiplied by 1000 and divided by 1000, one at a time; the slipped set is
validated like a file (``from_dict``).  A slip is *caught* when validation
raises a ``ParameterError`` whose message names the slipped key or, for a
cross-key check, the key it was checked against.

Usage (from the repository root)::

    python scripts/unit_slips.py            # table + totals
    python scripts/unit_slips.py --missed   # only the slips that pass

Slips that pass are listed in :data:`PLAUSIBLE` with the reason the slipped
value is still physically possible (tests/test_params.py asserts the list is
exact).  The script uses only the long-standing API (``SETS``, ``from_dict``,
``to_dict``) so it measures older versions too.
"""

from __future__ import annotations

import argparse
import sys

FACTORS = (1000.0, 0.001)

#: (key, factor) -> why the slipped value is still a plausible rig (not caught on purpose)
PLAUSIBLE = {}  # 2026-11: the five small-but-valid slips are refused too (heavecomp.params.plausibility, last rows)


def variants():
    """(label, nested dict) of every shipped set in every friction model, with [active] and a JONSWAP sea."""
    from heavecomp.params import FRICTION_MODELS, SETS

    out = []
    for name, factory in SETS.items():
        for model in FRICTION_MODELS:
            d = factory(model).to_dict()
            d["active"] = {"u_max": 60e3, "rate_max": 300e3, "control_rate": 20.0}
            out.append((f"{name}/{model}", d))
        d = factory("stribeck").to_dict()
        d["heave"] = {"kind": "jonswap", "hs": 2.0, "tp": 12.0, "gamma": 3.3, "seed": 7, "ramp": 24.0}
        out.append((f"{name}/stribeck/jonswap", d))
    return out


def slips():
    """Yield (label, key, factor, value, message or None) for every slip."""
    from heavecomp.errors import ParameterError
    from heavecomp.params import from_dict
    from heavecomp.params.plausibility import check_file

    for label, base in variants():
        for table, keys in base.items():
            for key, value in keys.items():
                if isinstance(value, bool) or not isinstance(value, (int, float)) or value == 0:
                    continue
                if key == "seed":  # a number, not a quantity with a unit
                    continue
                for factor in FACTORS:
                    d = {t: dict(v) for t, v in base.items()}
                    d[table][key] = value * factor
                    try:  # what reading a parameter file runs (params.loads: from_dict, then the file checks)
                        check_file(from_dict(d))
                        msg = None
                    except ParameterError as exc:
                        msg = str(exc)
                    yield label, f"{table}.{key}", factor, value * factor, msg


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--missed", action="store_true", help="list only the slips that pass")
    args = ap.parse_args(argv)
    rows = list(slips())
    unique = {}
    for label, key, factor, value, msg in rows:
        unique.setdefault((key, factor), []).append(msg is not None)
    caught = sum(m is not None for *_, m in rows)
    for label, key, factor, value, msg in rows:
        if args.missed and msg is not None:
            continue
        tag = "caught" if msg else ("plausible" if (key, factor) in PLAUSIBLE else "MISSED")
        print(f"{label:28s} {key:34s} x{factor:<6g} = {value:<11.4g} {tag:9s} {msg or PLAUSIBLE.get((key, factor), '')}")
    n_keys = len(unique)
    n_keys_caught = sum(all(v) for v in unique.values())
    print(f"\n{caught} of {len(rows)} slips caught ({len(rows) - caught} pass); "
          f"{n_keys_caught} of {n_keys} distinct (key, factor) slips caught in every set")
    missed = [k for k, v in unique.items() if not all(v) and k not in PLAUSIBLE]
    print(f"not caught and not listed as plausible: {len(missed)} {missed if missed else ''}")
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
