"""Which stretch of a long log the gap diagnosis analyses (issue 23 item 1: long logs in bounded memory).

The diagnosis replays its log hundreds of times, so its memory and time grow with the stretch it
replays.  It is validated on runs of 300-600 s (``docs/diagnosis.md``, tuning and scoring sets), and
over hours the plant may change (a seal wears, the driller moves the set-point): one verdict for a whole
day would mix them.  So a log longer than :data:`MAX_WHOLE` is not replayed whole.  The rule, never a
silent one:

- a span the user names (``START:END`` in s from the log's first sample) is analysed as named;
- otherwise a log of at most :data:`MAX_WHOLE` s is analysed whole (every excerpt the diagnosis was
  validated on, 10-20 minutes);
- otherwise the **last** :data:`DEFAULT_SPAN` s (the longest run the diagnosis is validated on; the last
  because it is the plant as it is now), and the diagnosis says so (``diagnosis.json`` ``span``, a
  warning in the report) and points to ``heavecomp monitor`` for the whole log: the monitor follows the
  equation error over every window of the log and diagnoses each stationary segment on request.

The whole log is still read (in chunks), checked against the contract and assessed for corruption
(:func:`heavecomp.diagnosis.data.load_run`); its data-quality warnings and confidence cap apply to the
span's verdict even when the problem lies outside the span.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from heavecomp.errors import InputError

#: the longest log diagnosed whole [s] (the 10-20 minute excerpts every validation used)
MAX_WHOLE = 1200.0
#: the span analysed of a longer log [s]: the longest run of the diagnosis' tuning and scoring sets
DEFAULT_SPAN = 600.0


@dataclasses.dataclass(frozen=True)
class Span:
    """The analysed stretch: ``start`` and ``end`` [s from the log's first sample], the log's length
    ``log_duration`` [s], ``rule`` (``"whole"``, ``"user"``, ``"last"``,
    ``"monitor"``: a segment ``heavecomp monitor --diagnose`` chose) and a one-line ``reason``."""

    start: float
    end: float
    log_duration: float
    rule: str
    reason: str

    @property
    def whole(self) -> bool:
        return self.rule == "whole"

    def to_json(self) -> dict:
        """The ``span`` block of ``diagnosis.json``."""
        return {"start_s": self.start, "end_s": self.end, "duration_s": self.end - self.start,
                "log_duration_s": self.log_duration, "rule": self.rule, "reason": self.reason}


def parse(text) -> tuple:
    """``"START:END"`` [s] -> ``(start, end)`` (either None when left out, ``"3600:"``); None -> None.

    Parameters
    ----------
    text : str or None
        The span as the user wrote it.
    """
    if text is None:
        return None
    parts = str(text).split(":")
    if len(parts) != 2:
        raise InputError(f"span: expected START:END in s (e.g. 3600:4200), got {text!r}")
    out = []
    for p in parts:
        p = p.strip()
        if not p:
            out.append(None)
            continue
        try:
            v = float(p)
        except ValueError:
            raise InputError(f"span: {p!r} is not a number of seconds (START:END, e.g. 3600:4200)") from None
        if not math.isfinite(v) or v < 0:
            raise InputError(f"span: {p!r} must be a finite time >= 0 s from the log's first sample")
        out.append(v)
    if out[0] is not None and out[1] is not None and out[1] <= out[0]:
        raise InputError(f"span: END {out[1]:g} s must come after START {out[0]:g} s")
    return tuple(out)



#: shortest log (or span) diagnosed or replayed [s]: a third held out must still hold a few 5-20 s wave periods
MIN_DURATION = 60.0


def check_length(run, command: str = "diagnose", noun: str = "run") -> None:
    """Refuse a log shorter than :data:`MIN_DURATION`, in one line naming its time column.

    Parameters
    ----------
    run : heavecomp.diagnosis.data.MeasuredRun
        The log as read.
    command : str
        The command named in the message (``diagnose``, ``replay``).
    noun : str
        What the message calls the log (``run``, ``log``).
    """
    if run.duration < MIN_DURATION:
        raise InputError(f"{run.source}: column 't': the {noun} spans {run.duration:.3g} s; {command} needs at least "
                         f"{MIN_DURATION:g} s (a fitted and a held-out part of several wave periods each)")

def choose(duration: float, span=None, *, min_duration: float = MIN_DURATION) -> Span:
    """The span of a log of ``duration`` [s] the diagnosis analyses (the rule in the module docstring).

    Parameters
    ----------
    duration : float [s]
        The log's length (last sample's time minus the first's).
    span : tuple (start, end) [s] or None
        The user's span (:func:`parse`; either end None: the log's start or end); None: the default rule.
    min_duration : float [s]
        Shortest span diagnosed.
    """
    if span is not None:
        a = 0.0 if span[0] is None else float(span[0])
        b = duration if span[1] is None else float(span[1])
        if a >= duration:
            raise InputError(f"span: START {a:g} s is past the log's end ({duration:.6g} s)")
        if b > duration * (1 + 1e-9) + 1e-9:
            raise InputError(f"span: END {b:g} s is past the log's end ({duration:.6g} s)")
        b = min(b, duration)
        if b - a < min_duration:
            raise InputError(f"span: {a:g}:{b:g} s spans {b - a:.3g} s; diagnose needs at least {min_duration:g} s")
        return Span(a, b, duration, "user", f"the span {a:g}-{b:g} s asked for, of a {_length(duration)} log")
    if duration <= MAX_WHOLE:
        return Span(0.0, duration, duration, "whole", "the whole log")
    a = duration - DEFAULT_SPAN
    return Span(a, duration, duration, "last",
                f"the log is {_length(duration)} long: the diagnosis analyses its last {DEFAULT_SPAN:g} s "
                f"({a:g}-{duration:.6g} s; the longest run it is validated on, and the plant as it is now), "
                f"not the whole log; name another span, or monitor the whole log (heavecomp monitor)")


def segment(duration: float, start: float, end: float, index: int, *, min_duration: float = MIN_DURATION) -> Span:
    """The span of segment ``index`` that ``heavecomp monitor --diagnose`` chose (``start``-``end`` [s] of a
    log of ``duration`` [s]): checked as a user's span (:func:`choose`), its rule ``"monitor"``.

    Parameters
    ----------
    duration : float [s]
        The log's length.
    start, end : float [s]
        The segment's diagnosed stretch, from the log's first sample.
    index : int
        The monitor's segment number.
    min_duration : float [s]
        Shortest span diagnosed.
    """
    sp = choose(duration, (start, end), min_duration=min_duration)
    return dataclasses.replace(sp, rule="monitor", reason=f"the monitor's segment {index}, {sp.start:g}-{sp.end:g} s "
                                                        f"of a {_length(duration)} log")


def _length(seconds: float) -> str:
    return f"{seconds / 3600:.3g} h" if seconds >= 3600 else f"{seconds:.4g} s"


def cut(run, span: Span):
    """The run's samples within ``span``, the clock restarted at the span's start, the span's reason
    added to its warnings (unless the span is the whole log); the whole log's arrays are not kept.

    Parameters
    ----------
    run : heavecomp.diagnosis.data.MeasuredRun
        The checked whole log.
    span : Span
        The stretch to keep.
    """
    if span.whole:
        return run
    t = run.t
    i0 = int(np.searchsorted(t, span.start - 1e-9, side="left"))
    i1 = int(np.searchsorted(t, span.end + 1e-9, side="right"))
    sl = slice(i0, i1)
    warnings = list(run.warnings) + [f"analysed span: {span.reason}"]
    return dataclasses.replace(run, t=t[sl] - t[i0], columns={k: np.array(v[sl]) for k, v in run.columns.items()},
                               warnings=warnings)
