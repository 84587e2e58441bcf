"""Logs of the maintainers' third held-back set's classes (issue 30), made with the project's own generator,
and their verdicts: does the diagnosis name the right component on each?

    python scripts/third_set_logs.py make DIR       # writes DIR/<class>.csv, .toml, .truth.json
    python scripts/third_set_logs.py drawn DIR      # the two plant classes at their drawn (held-back) sizes
    python scripts/third_set_logs.py diagnose DIR OUT.json

``diagnose`` imports only ``load_run``, ``GapDiagnoser`` and ``load``, so the same logs can be diagnosed by
another tree (``PYTHONPATH=/path/to/other/tree``): the verdicts before and after a change.

The classes, each at about 5 x the noise floor (its largest channel's own gap, ``Case.size``):

- ``friction_memory``: a LuGre bristle friction, relaxation length 3-6 cm (truth ``friction_memory``);
- ``mru_heave``: the heave through an MRU's 2nd-order high-pass (corner ~100 s) plus a drift of ~2 cm
  (truth ``heave_reference``, variant ``mru_drift``);
- ``hardening_formation``: the formation's stiffness doubled over 5 s half-way (``long_log``, ``hardening``, 150 s into the 300 s log);
  diagnosed whole and, as ``monitor --diagnose`` does, per segment of the monitor (``segments``);
- ``quantised_pressure``: a run without any plant effect whose pressure is read on a 0.25 bar grid with
  0.1 bar of mains hum aliased to 0.02 Hz (``corruption.quantised``).
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

#: class -> (the component a right verdict names, what was planted)
EXPECT = {"friction_memory": "friction", "mru_heave": "heave_input", "hardening_formation": "string_formation",
          "quantised_pressure": "sensors"}
SIZE = (4.5, 5.5)  #: the planted effect's largest channel gap over the noise floor [-]


def make(out: Path) -> None:
    from heavecomp.benchmark import Case, corruption, generate
    from heavecomp.benchmark.generate import TestRun
    from heavecomp.benchmark.long_logs import long_log
    from heavecomp.report.provenance import write_params

    out.mkdir(parents=True, exist_ok=True)
    runs = {
        "friction_memory": lambda: generate(Case("friction_memory", 300001, "named", duration=300.0, size=SIZE)),
        "mru_heave": lambda: generate(Case("heave_reference", 300002, "named", duration=300.0, variant="mru_drift",
                                           size=SIZE)),
        "hardening_formation": lambda: long_log([(150.0, "hardening")], seed=300003, duration=300.0, rate=50.0,
                                                size=5.0),
    }
    for name, fn in runs.items():
        print("making", name, flush=True)
        tr = fn()
        tr.to_csv(out / f"{name}.csv")
        write_params(out, tr.nominal, f"{name}.toml")
        (out / f"{name}.truth.json").write_text(json.dumps(tr.truth, indent=1, default=str))
    tr = generate(Case("none", 300004, "none", duration=300.0))
    t, cols, desc = corruption.quantised(tr.t, tr.columns, "pressure", 25e3, hum=10e3, hum_frequency=0.02)
    q = TestRun(t=t, columns=cols, nominal=tr.nominal, truth={**tr.truth, "reading": desc})
    q.to_csv(out / "quantised_pressure.csv")
    write_params(out, tr.nominal, "quantised_pressure.toml")
    (out / "quantised_pressure.truth.json").write_text(json.dumps(q.truth, indent=1, default=str))


def drawn(out: Path) -> None:
    """The friction memory and the MRU heave at the sizes their draws give (the whole friction in a 3-6 cm
    bristle; a high-pass corner of 0.008-0.012 Hz with a 2 cm drift), not sized to 5 x the noise."""
    from heavecomp.benchmark import Case, generate
    from heavecomp.report.provenance import write_params

    out.mkdir(parents=True, exist_ok=True)
    for name, case in (("friction_memory", Case("friction_memory", 300011, "named", duration=300.0)),
                       ("mru_heave", Case("heave_reference", 300012, "named", duration=300.0, variant="mru_drift"))):
        print("making", name, flush=True)
        tr = generate(case)
        tr.to_csv(out / f"{name}.csv")
        write_params(out, tr.nominal, f"{name}.toml")
        (out / f"{name}.truth.json").write_text(json.dumps(tr.truth, indent=1, default=str))


def diagnose(folder: Path, out: Path) -> None:
    from heavecomp.diagnosis import GapDiagnoser, load_run
    from heavecomp.params import load

    rows = {}
    for name, component in EXPECT.items():
        if not (folder / f"{name}.csv").exists():
            continue
        t0 = time.perf_counter()
        nominal = load(folder / f"{name}.toml")
        run = load_run(folder / f"{name}.csv", nominal)
        d = GapDiagnoser(nominal, n_jobs=1).fit(run)
        v = d.verdict_
        q = getattr(run, "quality", None)
        rows[name] = {"expected_component": component, "effect": v["effect"], "law": v.get("law"),
                      "member": v.get("member"), "confidence": v["confidence"],
                      "component": v.get("component"), "right_component": v.get("component") == component,
                      "parameters": v.get("parameters"), "explained": v.get("explained"), "shrink": v.get("shrink"),
                      "shrink_channel": v.get("shrink_channel"), "gap_to_noise": v.get("gap_to_noise"),
                      "discovered": (v.get("discovered") or {}).get("term"),
                      "quality": [i["kind"] + ":" + i["column"] for i in (q.issues if q is not None else [])],
                      "noise_floor": {c: g.get("noise_floor") for c, g in d.gap_["channels"].items()},
                      "wall_time_s": time.perf_counter() - t0}
        if name == "hardening_formation":  # a change part-way: the monitor's segments, each diagnosed on its own
            from heavecomp.diagnosis import monitor as M

            res = M.monitor(run, nominal)
            M.diagnose_segments(res, run, nominal, n_jobs=1)
            rows[name]["monitor_changes"] = [{k: c.get(k) for k in ("t", "onset", "kind", "component")}
                                             for c in res.changes]
            rows[name]["segments"] = [{"start": s["start"], "end": s["end"], "verdict": s.get("verdict")}
                                      for s in res.segments]
            rows[name]["wall_time_s"] = time.perf_counter() - t0
        print(name, json.dumps(rows[name], default=str), flush=True)
    out.write_text(json.dumps(rows, indent=1, default=str))


if __name__ == "__main__":
    if len(sys.argv) >= 3 and sys.argv[1] == "make":
        make(Path(sys.argv[2]))
    elif len(sys.argv) >= 3 and sys.argv[1] == "drawn":
        drawn(Path(sys.argv[2]))
    elif len(sys.argv) >= 4 and sys.argv[1] == "diagnose":
        diagnose(Path(sys.argv[2]), Path(sys.argv[3]))
    else:
        sys.exit("usage: third_set_logs.py make DIR | drawn DIR | diagnose DIR OUT.json")
