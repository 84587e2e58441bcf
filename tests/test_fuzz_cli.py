"""The small version of ``benchmarks/fuzz/run_fuzz.py`` (issue 21, "Done when"): freshly generated
parameter files and corrupted logs give no traceback, no hang and no confident verdict on corrupted data.

The fast tests run the generators of the fuzz script in-process (``cli.main`` for the parameter files,
``load_run`` for the logs: the input checks, not the diagnosis); the slow one runs the script itself
(``--quick``: 12 files and 4 logs (one clean, three corruption classes) through the CLI in subprocesses, each diagnosed; every corruption class is fuzzed in process by test_fuzz_inputs)."""

import importlib.util
import random
from pathlib import Path

import numpy as np
import pytest

from heavecomp.benchmark import corruption as K
from heavecomp.diagnosis.data import load_run
from heavecomp.errors import DataError
from heavecomp.params import load

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(__file__).parent / "data" / "corrupt_2026_11"


def _fuzz():
    spec = importlib.util.spec_from_file_location("run_fuzz", ROOT / "benchmarks" / "fuzz" / "run_fuzz.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_fuzzed_parameter_files_are_accepted_or_one_line(tmp_path, capsys):
    from heavecomp.cli import main

    fz = _fuzz()
    rng, bases = random.Random(7), fz.base_texts()
    tally = {"ok": 0, "refused": 0}
    for i in range(60):
        raw, desc, must = fz.mutate_params(rng, bases, tmp_path, i)
        f = tmp_path / f"p{i}.toml"
        f.write_bytes(raw)
        code = main(["params", str(f), "-o", str(tmp_path / "copy.toml")])
        err = capsys.readouterr().err.strip()
        assert code in (0, 2), (desc, code, err)
        if code == 2:
            assert len(err.splitlines()) == 1 and "Traceback" not in err, (desc, err)
        else:
            assert not must, (desc, "accepted although built to be wrong")
        tally["ok" if code == 0 else "refused"] += 1
    assert tally["ok"] and tally["refused"]  # both sides of the promise were exercised


def _c0():
    import gzip

    with gzip.open(DATA / "C0_clean_300s_20Hz.csv.gz", "rt") as f:
        d = np.genfromtxt(f, delimiter=",", names=True)
    return d["t"][:2401], {c: d[c][:2401] for c in ("heave", "stroke", "pressure", "wob")}  # 120 s


@pytest.mark.parametrize("kind", K.CLASSES)
def test_every_corruption_class_is_refused_or_capped_by_name(tmp_path, kind):
    """Three fresh draws of each class (seeded), written as a CSV and loaded as the CLI does."""
    fz = _fuzz()
    P = load(DATA / "pj.toml")
    t, cols = _c0()
    rng = np.random.default_rng(sum(map(ord, kind)))
    for k in range(3):
        t2, c2, d = K.corrupt(kind, t, cols, rng, P)
        f = fz.write_log(tmp_path / f"{kind}{k}.csv", t2, c2, torn_text=kind == "torn")
        name = f"column '{d['column']}'"
        try:
            run = load_run(f, P)
        except DataError as e:
            assert d["expect"] in ("refuse", "refuse_or_low") and name in str(e), (d, str(e))
            continue
        assert d["expect"] != "refuse", (d, run.warnings)
        if d["expect"] == "dropped":
            assert any("torn" in w and name in w for w in run.warnings) and run.t.size == t2.size - 1, d
        elif d["expect"] != "clean":
            assert run.quality.confidence_cap == "low" and any(name in w for w in run.quality.warnings), \
                (d, run.warnings)


@pytest.mark.slow
def test_quick_fuzz_run_through_the_cli(tmp_path):
    fz = _fuzz()
    out = tmp_path / "r.json"
    rc = fz.main(["--quick", "--jobs", "2", "--out", str(out)])
    import json

    s = json.loads(out.read_text())["summary"]
    assert s["bad"] == {"params": 0, "simulate": 0, "logs": 0}, s
    assert rc == 0
