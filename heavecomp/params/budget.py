"""Run-size budget: refuse, before anything is allocated, a run whose step count or memory cannot fit.

A simulation holds the heave samples (z, dz/dt, d2z/dt2 every half step: 48 bytes
per RK4 step) and the output rows (``rows x columns x 8`` bytes) in memory, and
takes time proportional to its RK4 steps.  The default step follows the
fastest plant rate, so a mass, stiffness or friction slope far outside a rig's
range, or a long ``--duration`` at a tiny ``--dt`` / huge ``--rate``, asks for
more than any machine has.  :func:`check_run_size` raises a one-line
:class:`~heavecomp.errors.ParameterError` naming what drives the size (the
parameter keys that set the default step, found by perturbing each one, or
``--dt`` / ``--rate`` / ``--duration``) before the work starts.

Budgets (module constants, per run):

- :data:`MAX_STEPS` = 2e8 RK4 steps (about a minute or two of the compiled
  stepper; 24 h of paper A at its default 25 ms step is 3.5e6);
- :data:`MAX_BYTES` = 4 GiB for heave samples plus output rows;
- :data:`MAX_REPLAY_STEPS` = 1e7 steps of one replay of the gap diagnosis (checked before any replay).

The gap diagnosis' whole run (issue 23.1): :func:`check_diagnosis_memory` estimates its peak resident
memory from the analysed span's samples, its replay steps and the concurrent jobs
(:func:`diagnosis_bytes`, coefficients measured on the long-log benchmark) and refuses, before any
replay, what would not fit the memory the process may still take (:func:`available_bytes`).
"""

from __future__ import annotations

import math
from typing import Callable

from heavecomp.errors import ParameterError
from heavecomp.errors import InputError

MAX_STEPS = 200_000_000  #: largest number of RK4 steps of one run
MAX_BYTES = 4 * 2 ** 30  #: largest memory for heave samples + output rows [bytes]
HEAVE_BYTES_PER_STEP = 3 * 8 * 2  #: z, dz, ddz at every half step [bytes]
#: longest replay the gap diagnosis takes (about 55 h at its 20 ms step on the paper-A plant; each replay ~1.5 s there, the
#: diagnosis makes several hundred, and the replay grid of 1e7 steps x 8 channels is 0.6 GB per thread)
MAX_REPLAY_STEPS = 10_000_000
MIN_DEFAULT_STEP = 1e-5  #: a parameter set whose default step is shorter cannot run an hour within MAX_STEPS [s]


def _gb(n: float) -> str:
    return f"{n / 1e9:.3g} GB"


def step_drivers(params, rate_fn: Callable, *, top: int = 3) -> list[str]:
    """``["friction.stribeck_velocity = 0.0001 m/s", ...]``: the keys the plant rate ``rate_fn(params)`` [1/s]
    depends on most (elasticity d ln rate / d ln value over a 10 % change, largest first).

    Parameters
    ----------
    params : CMCParams
        The parameter set.
    rate_fn : callable(params) -> float [1/s]
        The plant rate the default step is made from.
    top : int
        Most keys returned.
    """

    r0 = rate_fn(params)
    found = []
    for tname, table in params.to_dict().items():
        if tname not in ("compensator", "friction", "drill_string", "formation"):
            continue
        for key, value in table.items():
            if isinstance(value, bool) or not isinstance(value, (int, float)) or value == 0:
                continue
            try:
                r1 = rate_fn(params.replace(**{tname: {key: value * 1.1}}))
            except InputError:  # a 10 % change crosses a bound or a cross-key check
                try:
                    r1 = 1.0 / rate_fn(params.replace(**{tname: {key: value / 1.1}})) * r0 * r0
                except InputError:
                    continue
            e = math.log(r1 / r0) / math.log(1.1)
            if abs(e) >= 0.2:
                unit = _unit(params, tname, key)
                found.append((abs(e), f"{tname}.{key} = {value:.4g}{' ' + unit if unit else ''}"))
    found.sort(key=lambda x: -x[0])
    return [s for _, s in found[:top]]


def _unit(params, tname, key) -> str:
    import dataclasses

    for f in dataclasses.fields(getattr(params, tname)):
        if f.name == key:
            u = f.metadata.get("unit", "")
            return "" if u == "-" else u
    return ""


def _step_cause(params, h, dt, rate, rate_fn) -> str:
    if dt is not None:
        return f"dt = {h:.3g} s"
    if rate_fn is None:
        return f"the default step {h:.3g} s"
    h_plant = min(0.05, 0.6 / rate_fn(params))
    if rate and 1.0 / rate < 0.999 * h_plant:
        return f"a step of {h:.3g} s (one output interval of rate = {rate:g} Hz)"
    drivers = step_drivers(params, rate_fn)
    return (f"the default step {h:.3g} s" + (f", set by {', '.join(drivers)}" if drivers else ""))


def check_run_size(params, *, duration: float, h: float, n_steps: int, n_rows: int, n_cols: int,
                   dt: float | None = None, rate: float | None = None, rate_fn: Callable | None = None) -> None:
    """Raise :class:`ParameterError` if a run of ``n_steps`` RK4 steps of ``h`` [s] and ``n_rows`` x ``n_cols``
    output values exceeds :data:`MAX_STEPS` or :data:`MAX_BYTES`.

    Parameters
    ----------
    params : CMCParams
    duration : float [s]
    h : float [s]
        The step the run would use.
    n_steps, n_rows, n_cols : int
        RK4 steps, output rows and columns.
    dt : float [s] or None
        The step the user asked for (None: default step).
    rate : float [Hz] or None
        Output (or control) rate.
    rate_fn : callable(params) -> float [1/s], optional
        The plant rate the default step is made from; used only to name the keys that set it.
    """
    heave_bytes = HEAVE_BYTES_PER_STEP * (n_steps + 1)
    out_bytes = 8 * n_rows * n_cols
    if n_steps <= MAX_STEPS and heave_bytes + out_bytes <= MAX_BYTES:
        return
    if out_bytes > heave_bytes and n_steps <= MAX_STEPS:
        raise ParameterError(
            f"duration = {duration:g} s at rate = {rate:g} Hz writes {n_rows:.3g} rows x {n_cols} columns "
            f"({_gb(out_bytes)}), over the {MAX_BYTES / 2 ** 30:g} GiB budget; lower the rate or the duration",
            option=("duration", "rate"))
    cause = _step_cause(params, h, dt, rate, rate_fn)
    what = (f"{n_steps:.3g} RK4 steps, over the budget of {MAX_STEPS:.3g}" if n_steps > MAX_STEPS else
            f"{_gb(heave_bytes + out_bytes)} of heave samples and output, over the {MAX_BYTES / 2 ** 30:g} GiB budget")
    raise ParameterError(f"duration = {duration:g} s at {cause} needs {what}; "
                         f"shorten the duration, pass a larger step dt, or check those values",
                         option=("duration", "dt", "rate"))


def check_default_step(params, h: float, rate_fn: Callable) -> None:
    """Raise :class:`ParameterError` if the default step ``h`` [s] of ``params`` is below :data:`MIN_DEFAULT_STEP`,
    naming the keys that set it (``heavecomp params`` checks this; no run of useful length would fit).

    Parameters
    ----------
    params : CMCParams
        The parameter set.
    h : float [s]
        Its default step.
    rate_fn : callable(params) -> float [1/s]
        The plant rate the default step is made from; used only to name the keys that set it.
    """
    if h >= MIN_DEFAULT_STEP:
        return
    drivers = step_drivers(params, rate_fn)
    raise ParameterError(
        f"{drivers[0].split(' = ')[0] if drivers else 'parameters'}: the default time step would be {h:.3g} s "
        f"(set by {', '.join(drivers) or 'the plant'}), below {MIN_DEFAULT_STEP:g} s: an hour would need "
        f"{3600 / h:.3g} RK4 steps (budget {MAX_STEPS:.3g}); check those values")


# ---------------------------------------------------------------- the gap diagnosis' memory
# Coefficients measured (benchmarks/longlog/README.md): peak RSS of `heavecomp diagnose` on the generated
# 3 h at 50 Hz and 24 h at 10 Hz logs, spans of 600 s and 1200 s, --jobs 1 and 2 (714, 1054, 648, 688 MB),
# solved for the four terms and rounded up by ~5-10 %.
#: resident memory of the diagnosis' process besides its span [bytes]: interpreter, numpy/scipy/pandas,
#: the compiled stepper, the whole log as read and checked (up to 24 h at 10 Hz)
DIAGNOSIS_BASE_BYTES = 400e6
#: per sample of the analysed span [bytes]: the measured channels and their masks, the equation
#: error's feature matrices, every fit's predicted channels kept for the verdict and the report
DIAGNOSIS_SAMPLE_BYTES = 3000.0
#: per replay step of the analysed span [bytes]: the heave samples (nominal and perturbed draws) and the
#: stepper output every kept replay holds (``_grid``: 16 channels x 8 bytes a step, tens of replays)
DIAGNOSIS_STEP_BYTES = 3500.0
#: per replay step and concurrent job [bytes]: the replays in flight on each thread
DIAGNOSIS_JOB_STEP_BYTES = 500.0


#: per row of the whole log read and checked [bytes]: its float64 columns and line numbers, the
#: contract checks and the data-quality pass's working arrays (measured 238-347 B on the long-log
#: benchmark's logs, gzip CSV and Parquet; benchmarks/longlog/README.md)
LOAD_ROW_BYTES = 400.0


def check_read_memory(rows, *, source: str, available=None) -> float:
    """Refuse, before a log is read, one whose reading and whole-log checks (:data:`LOAD_ROW_BYTES` a
    row) do not fit what the process may still take (:func:`available_bytes`): one line naming the
    rows.  ``rows`` None (not known before reading: bzip2, xz) passes; the reader then refuses at
    the row where its arrays exceed its own cap.  Returns the estimate [bytes].

    Parameters
    ----------
    rows : int or None
        The log's rows, estimated from its size (:func:`heavecomp.io.series.estimate_rows`).
    source : str
        The log's name, at the start of the message.
    available : tuple (room, what, resident) or None
        As :func:`check_diagnosis_memory`.
    """
    if rows is None:
        return 0.0
    need = LOAD_ROW_BYTES * rows
    room, what, _resident = available_bytes() if available is None else available
    if need <= room:
        return need
    raise InputError(f"{source}: reading and checking the log's {rows:.3g} rows (estimated from its size) would "
                     f"take {_gb(need)}, over the {_gb(room)} that {what} leaves; cut the log into parts")


def diagnosis_bytes(n_samples: int, n_steps: int, jobs: int) -> dict:
    """Estimated peak resident memory of a gap diagnosis, by part [bytes].

    Parameters
    ----------
    n_samples : int
        Samples of the analysed span.
    n_steps : int
        Replay steps of the analysed span (its duration over the replay step).
    jobs : int
        Candidates fitted concurrently.

    Returns
    -------
    dict
        ``base``, ``samples``, ``replays`` and ``total`` [bytes].
    """
    parts = {"base": DIAGNOSIS_BASE_BYTES, "samples": DIAGNOSIS_SAMPLE_BYTES * n_samples,
             "replays": (DIAGNOSIS_STEP_BYTES + DIAGNOSIS_JOB_STEP_BYTES * jobs) * n_steps}
    parts["total"] = sum(parts.values())
    return parts


def available_bytes() -> tuple:
    """``(room, what limits it, resident)`` [bytes]: the memory this process may still take (the smallest
    of the system's available memory, ``MemAvailable``, and what the address-space and data limits,
    ``ulimit -v`` / ``-d``, leave above the process' present size), and its present resident size.
    ``(inf, "", 0)`` where none is known (not Linux)."""
    import os
    import resource

    room, what = math.inf, ""
    try:
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    room, what = float(line.split()[1]) * 1024.0, "the memory available on this machine"
    except OSError:
        pass
    size = resident = 0.0
    try:
        with open(f"/proc/{os.getpid()}/statm", encoding="ascii") as fh:
            fields = fh.read().split()
        page = os.sysconf("SC_PAGE_SIZE")
        size, resident = float(fields[0]) * page, float(fields[1]) * page
    except (OSError, ValueError, IndexError):
        pass
    for lim, name in ((resource.RLIMIT_AS, "the address-space limit (ulimit -v)"),
                      (resource.RLIMIT_DATA, "the data-size limit (ulimit -d)")):
        soft = resource.getrlimit(lim)[0]
        if soft != resource.RLIM_INFINITY and soft - size < room:
            room, what = max(0.0, soft - size), name
    return room, what, resident


def check_diagnosis_memory(n_samples: int, n_steps: int, *, jobs: int, duration: float, rate: float,
                           source: str, available=None) -> dict:
    """Refuse, before any replay, a gap diagnosis whose estimated peak memory (:func:`diagnosis_bytes`)
    does not fit what the process may take (:func:`available_bytes`): one line naming what would not fit
    (the span's samples and its replays with the jobs) and what to change.  Returns the estimate.

    Parameters
    ----------
    n_samples : int
        Samples of the analysed span.
    n_steps : int
        Replay steps of the analysed span.
    jobs : int
        Candidates fitted concurrently.
    duration : float [s]
        Length of the analysed span (for the message).
    rate : float [Hz]
        Its sampling rate (for the message).
    source : str
        The log's name, at the start of the message.
    available : tuple (room, what, resident) or None
        The memory the process may still take, what limits it, and its present resident size [bytes];
        None: :func:`available_bytes`.
    """
    need = diagnosis_bytes(n_samples, n_steps, jobs)
    room, what, resident = available_bytes() if available is None else available
    # the base (and the span's arrays) are resident already: the growth is what must fit the room
    grow = need["total"] - min(resident, DIAGNOSIS_BASE_BYTES)
    if grow <= room:
        return need
    detail = (f"its {n_samples:.3g} samples ({duration:.4g} s at {rate:.3g} Hz) need {_gb(need['samples'])}, its "
              f"replays ({n_steps:.3g} steps, {jobs} job{'s' if jobs != 1 else ''}) {_gb(need['replays'])}")
    fix = "a shorter span" + (" or fewer jobs" if jobs > 1 else "")
    raise InputError(f"{source}: the diagnosis of {duration:.4g} s would take {_gb(grow)} more, over the "
                     f"{_gb(room)} that {what} leaves: {detail}; diagnose {fix}", option=("span", "jobs"))
