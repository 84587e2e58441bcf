"""Fuzzing of parameter files (issue 14): the promise of ``heavecomp params`` and ``heavecomp simulate``.

Hypothesis mutates the shipped parameter sets -- keys (deleted, misspelt, unknown, moved, duplicated),
tables, value types, magnitudes (x1000, /1000, sign, 0, 1e+-300, NaN, inf, random floats), encodings
(UTF-8 BOM, latin-1, UTF-16, decimal comma) and TOML syntax -- and asserts for every file:

- ``heavecomp params FILE`` (in-process, ``cli.main``) either exits 0 and its checked copy carries every
  value of the file unchanged with finite derived quantities (no silent default, no coercion), or
  exits 2 with exactly one line on stderr that names a key, a table or the file;
- ``heavecomp simulate FILE --duration 10`` (in a forked child under ``RLIMIT_AS`` and a wall-clock
  limit) either exits 0 with finite ``metrics.json`` and ``timeseries.csv`` and a WOB >= 0, or exits 2
  with one line; never a traceback, a hang or the memory limit.

The fast variant runs in the default suite (tens of files); the ``slow`` variant runs >= 500 files
through ``params`` and 60 through ``simulate``.  Each test prints its tally (``pytest -s``).
"""

from __future__ import annotations

import io
import json
import math
import os
import re
import resource
import select
import signal
import tempfile
import tomllib
from collections import Counter
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

SIM_SECONDS = 10.0  #: simulated time of the short simulate runs [s]
SIM_WALL_LIMIT = 120.0  #: a simulate child still running after this is a hang [s] (generous: CI shares 2 cores)
SIM_MEMORY_EXTRA = 3 * 2 ** 30  #: address space a simulate child may add to the parent's [bytes]

# ---------------------------------------------------------------------------------------------------------
# base files: every shipped set in every friction model, with an [active] table and a JONSWAP sea


def _base_texts() -> list[str]:
    from heavecomp.params import FRICTION_MODELS, SETS, dumps

    out = []
    for factory in SETS.values():
        for model in FRICTION_MODELS:
            out.append(dumps(factory(model)))
        p = factory("rotating_eq7")
        out.append(dumps(p) + "\n[active]\nu_max = 60000.0\nrate_max = 300000.0\ncontrol_rate = 20.0\n")
        out.append(dumps(factory("stribeck")).replace(
            'kind = "sine"\namplitude = 1.0\nperiod = 12.0\n', 'kind = "jonswap"\nhs = 2.0\ntp = 12.0\nseed = 5\n'))
    return out


BASES = _base_texts()

ODD_VALUES = ["nan", "inf", "-inf", "+inf", "0", "0.0", "-0.0", "-1.0", "1e300", "1e-300", "-1e-300", "5e-324",
              "1e-9", "1e9", "4294967296", '"80 t"', '""', "true", "[1.0, 2.0]", "{ a = 1 }", "1979-05-27",
              '"stribeck"', "0x10", "1_000", "+5.0", "12", "-12", "'raw'", "1" + "0" * 400, "1" + "0" * 5000]


def _lines(text):
    return text.splitlines()


@st.composite
def mutated_file(draw) -> tuple[bytes, str]:
    """(file bytes, description of the mutations)."""
    text = draw(st.sampled_from(BASES))
    lines = _lines(text)
    done = []
    for _ in range(draw(st.integers(1, 3))):
        kv = [i for i, ln in enumerate(lines) if re.match(r"^\w+ = ", ln)]
        heads = [i for i, ln in enumerate(lines) if ln.startswith("[")]
        if not kv or not heads:
            break
        kind = draw(st.sampled_from(["value", "value", "value", "magnitude", "magnitude", "key", "table", "syntax"]))
        i = draw(st.sampled_from(kv))
        key, _, val = lines[i].partition(" = ")
        if kind == "value":
            new = draw(st.one_of(st.sampled_from(ODD_VALUES),
                                 st.floats(allow_nan=True, allow_infinity=True).map(repr),
                                 st.integers(-2 ** 70, 2 ** 70).map(str)))
            lines[i] = f"{key} = {new}"
        elif kind == "magnitude":
            try:
                x = float(val)
            except ValueError:
                continue
            f = draw(st.sampled_from([1e3, 1e-3, -1.0, 0.0, 1e6, 1e-6, 10.0, 0.1, 1e-300, 1e300, 1.000001]))
            lines[i] = f"{key} = {x * f!r}"
        elif kind == "key":
            how = draw(st.sampled_from(["delete", "misspell", "unknown", "duplicate", "move", "case"]))
            if how == "delete":
                lines[i] = "# deleted"
            elif how == "misspell":
                j = draw(st.integers(0, len(key) - 1))
                lines[i] = f"{key[:j]}{key[j + 1:]} = {val}"
            elif how == "unknown":
                lines.insert(i, f"{draw(st.from_regex(r'[a-z_]{1,12}', fullmatch=True))} = 1.0")
            elif how == "duplicate":
                lines.insert(i, lines[i])
            elif how == "move":
                lines.append(lines[i])
                lines[i] = ""
            else:
                lines[i] = f"{key.upper()} = {val}"
        elif kind == "table":
            h = draw(st.sampled_from(heads))
            how = draw(st.sampled_from(["rename", "delete_header", "duplicate", "array"]))
            name = lines[h].strip("[]")
            if how == "rename":
                lines[h] = f"[{name}s]"
            elif how == "delete_header":
                lines[h] = ""
            elif how == "duplicate":
                lines.append(lines[h])
            else:
                lines[h] = f"[[{name}]]"
        else:  # syntax
            how = draw(st.sampled_from(["drop_char", "insert_char", "truncate", "quote", "bracket"]))
            flat = "\n".join(lines)
            pos = draw(st.integers(0, max(len(flat) - 1, 0)))
            if how == "drop_char":
                flat = flat[:pos] + flat[pos + 1:]
            elif how == "insert_char":
                flat = flat[:pos] + draw(st.sampled_from(list("=[]\"'#,.{}\\\t") + ["\x00", "é"])) + flat[pos:]
            elif how == "truncate":
                flat = flat[:pos]
            elif how == "quote":
                flat = flat.replace(" = ", ' = "', 1)
            else:
                flat = flat.replace("]", "", 1)
            lines = flat.split("\n")
        done.append(kind)
    text = "\n".join(lines) + "\n"
    enc = draw(st.sampled_from(["utf-8"] * 6 + ["utf-8-sig", "latin-1", "utf-16", "comma"]))
    if enc == "latin-1":
        data = ("# Größe der Anlage\n" + text).encode("latin-1", errors="replace")
    elif enc == "comma":
        data = re.sub(r"(= -?\d+)\.(\d)", r"\1,\2", text, count=1).encode()
    else:
        data = text.encode(enc, errors="replace")
    return data, "+".join(done) + "/" + enc


@st.composite
def perturbed_file(draw) -> tuple[bytes, str]:
    """A shipped set with one to three values scaled by a random factor in [0.3, 3] (or a mutated file, 1 in 3):
    mostly valid files, so that simulate runs on many of them."""
    if draw(st.integers(0, 2)) == 0:
        return draw(mutated_file())
    text = draw(st.sampled_from(BASES))
    lines = _lines(text)
    kv = [i for i, ln in enumerate(lines) if re.match(r"^\w+ = [-0-9.e+]+$", ln) and "seed" not in ln]
    for _ in range(draw(st.integers(1, 3))):
        i = draw(st.sampled_from(kv))
        key, _, val = lines[i].partition(" = ")
        f = draw(st.floats(0.3, 3.0))
        lines[i] = f"{key} = {float(val) * f!r}"
    return ("\n".join(lines) + "\n").encode(), "perturbed"


# ---------------------------------------------------------------------------------------------------------
# the promise


KNOWN_TABLES = ("heave", "compensator", "friction", "drill_string", "formation", "operating_point", "active")
#: keys the toolbox may add when a file leaves them out (documented defaults)
DEFAULTED = {("heave", "ramp"), ("heave", "gamma"), ("heave", "seed"), ("drill_string", "damping"),
             ("formation", "damping")}


def _names_something(line: str, path: str) -> bool:
    """The error line names the file, a table (``[x]`` or ``x:``) or a ``table.key`` of a known table, or the
    command-line option that drives a run's size."""
    body = line.split("error: ", 1)[-1]
    if path in body or re.search(r"\[\w+\]", body) or re.search(r"--(dt|rate|duration)\b", body):
        return True
    return bool(re.search(r"\b(" + "|".join(KNOWN_TABLES) + r")(\.\w+|:)", body))


def _same(a, b) -> bool:
    if isinstance(a, float) or isinstance(b, float):
        return float(a) == float(b)
    return a == b


def run_params(data: bytes, tally: Counter) -> tuple[int, Path | None]:
    """``heavecomp params FILE`` in-process; asserts the promise; returns (exit code, path of the file)."""
    from heavecomp.cli import main

    d = Path(tempfile.mkdtemp(prefix="fuzzp"))
    f = d / "p.toml"
    f.write_bytes(data)
    out, err = io.StringIO(), io.StringIO()
    try:
        with redirect_stdout(out), redirect_stderr(err):
            code = main(["params", str(f)])
    except SystemExit as exc:  # argparse
        code = exc.code
    except Exception as exc:  # a traceback: the promise is broken
        tally["traceback"] += 1
        raise AssertionError(f"params raised {type(exc).__name__}: {exc}") from exc
    lines = err.getvalue().strip().splitlines()
    assert code in (0, 2), (code, err.getvalue())
    assert len(lines) == 1, err.getvalue()
    if code == 2:
        tally["params exit 2"] += 1
        assert lines[0].startswith("heavecomp params: error: "), lines
        assert _names_something(lines[0], str(f)), lines[0]
        return 2, f
    tally["params exit 0"] += 1
    assert lines[0].startswith(f"{f}: valid ("), lines
    # no silent default or coercion: every value of the file is in the checked copy, unchanged
    given_ = tomllib.loads(data.decode("utf-8-sig"))
    copy = tomllib.loads(out.getvalue())
    for table, keys in given_.items():
        for key, value in keys.items():
            if not _same(copy[table][key], value):
                tally["silent wrong answer"] += 1
                raise AssertionError(f"{table}.{key} = {value!r} came back as {copy[table][key]!r}")
    for table, keys in copy.items():
        for key in keys:
            assert key in given_.get(table, {}) or (table, key) in DEFAULTED or \
                (table == "heave" and key in ("gamma", "seed", "ramp")), f"{table}.{key} added silently"
    for m in re.findall(r"= ([-+0-9.e]+) ", lines[0]):
        assert math.isfinite(float(m)) and float(m) > 0, lines[0]
    return 0, f


def run_simulate(path: Path, tally: Counter) -> int:
    """``heavecomp simulate PATH --duration 10`` in a forked child with RLIMIT_AS and a wall-clock limit."""
    _warm()
    out_dir = path.parent / "out"
    rfd, wfd = os.pipe()
    pid = os.fork()
    if pid == 0:  # child
        code = 99
        try:
            os.close(rfd)
            vm = int(re.search(r"VmSize:\s+(\d+) kB", Path("/proc/self/status").read_text()).group(1)) * 1024
            resource.setrlimit(resource.RLIMIT_AS, (vm + SIM_MEMORY_EXTRA, vm + SIM_MEMORY_EXTRA))
            from heavecomp.cli import main

            err = io.StringIO()
            with redirect_stderr(err), redirect_stdout(io.StringIO()):
                try:
                    code = main(["simulate", str(path), "--duration", str(SIM_SECONDS), "--out", str(out_dir)])
                except MemoryError:
                    code = 98
                except BaseException as exc:  # noqa: BLE001 - reported to the parent as a traceback
                    err.write(f"TRACEBACK {type(exc).__name__}: {exc}\n")
                    code = 97
            os.write(wfd, json.dumps({"code": code, "err": err.getvalue()}).encode() + b"\n")
        finally:
            import multiprocessing

            for proc in multiprocessing.active_children():  # the figure worker, if a run left it behind
                proc.terminate()
            os._exit(0)
    os.close(wfd)
    chunks, deadline = [], SIM_WALL_LIMIT
    import time

    t0 = time.monotonic()
    while True:
        r, _, _ = select.select([rfd], [], [], max(0.0, deadline - (time.monotonic() - t0)))
        if not r:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            os.close(rfd)
            tally["hang"] += 1
            raise AssertionError(f"simulate {path} still running after {SIM_WALL_LIMIT:g} s")
        b = os.read(rfd, 65536)
        chunks.append(b)
        if not b or b.endswith(b"\n"):
            break
    os.close(rfd)
    os.waitpid(pid, 0)
    rep = json.loads(b"".join(chunks) or b'{"code": 96, "err": "child died"}')
    code, err = rep["code"], rep["err"].strip()
    if code in (96, 97):
        tally["traceback"] += 1
    if code == 98:
        tally["memory limit"] += 1
    assert code in (0, 2), (code, err)
    lines = err.splitlines()
    if code == 2:
        tally["simulate exit 2"] += 1
        assert len(lines) == 1 and lines[0].startswith("heavecomp simulate: error: "), err
        assert _names_something(lines[0], str(path)), lines[0]
        return 2
    tally["simulate exit 0"] += 1
    metrics = json.loads((out_dir / "metrics.json").read_text())
    for k in ("wob_mean", "wob_std", "wob_min", "wob_max", "stroke_max", "pressure_min", "pressure_max"):
        if not math.isfinite(metrics[k]):
            tally["silent wrong answer"] += 1
            raise AssertionError(f"metrics {k} = {metrics[k]}")
    data = np.loadtxt(out_dir / "timeseries.csv", delimiter=",", skiprows=1)
    assert np.isfinite(data).all() and data.shape[0] == int(round(SIM_SECONDS * 20)) + 1
    assert metrics["wob_min"] >= 0.0  # WOB is one-sided contact
    return 0


def _warm():
    """Load the compiled stepper and matplotlib once in the parent, so that each forked child inherits them."""
    from heavecomp.simulate.core import stepper

    stepper()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot  # noqa: F401

    from heavecomp.report import figures  # noqa: F401


SETTINGS = dict(deadline=None, database=None, derandomize=True, suppress_health_check=list(HealthCheck))


def _report(tally, name):
    print(f"\n{name}: " + ", ".join(f"{k} {v}" for k, v in sorted(tally.items())))


# ---------------------------------------------------------------------------------------------------------
# fast variant (default run)

FAST = Counter()


@settings(max_examples=40, **SETTINGS)
@given(st.one_of(mutated_file(), perturbed_file()))
def test_fuzz_params_fast(case):
    data, desc = case
    run_params(data, FAST)


SIM_FAST = Counter()


@settings(max_examples=4, **SETTINGS)
@given(perturbed_file())
def test_fuzz_simulate_fast(case):
    data, desc = case
    code, path = run_params(data, SIM_FAST)
    run_simulate(path, SIM_FAST)


# ---------------------------------------------------------------------------------------------------------
# long variant

SLOW = Counter()


@pytest.mark.slow
@settings(max_examples=520, **SETTINGS)
@given(st.one_of(mutated_file(), perturbed_file()))
def test_fuzz_params_long(case):
    data, desc = case
    run_params(data, SLOW)


SIM_SLOW = Counter()


@pytest.mark.slow
@settings(max_examples=50, **SETTINGS)
@given(perturbed_file())
def test_fuzz_simulate_long(case):
    data, desc = case
    _, path = run_params(data, SIM_SLOW)
    run_simulate(path, SIM_SLOW)


@pytest.fixture(scope="module", autouse=True)
def _print_tallies():
    yield
    for name, t in (("params fast", FAST), ("simulate fast", SIM_FAST), ("params long", SLOW),
                    ("simulate long", SIM_SLOW)):
        if t:
            _report(t, name)


def test_shipped_sets_pass_the_oracle():
    """The oracle accepts every unmutated base file and a simulate of one runs clean (the fuzz can fail only
    through the mutation)."""
    tally = Counter()
    for text in BASES:
        assert run_params(text.encode(), tally)[0] == 0
    assert run_simulate(run_params(BASES[1].encode(), tally)[1], tally) == 0
    assert tally["params exit 0"] == len(BASES) + 1 and tally["simulate exit 0"] == 1
