"""Plumbing shared by the scenario scripts: arguments, output folder, metrics and markdown."""

from __future__ import annotations

import argparse
import hashlib
import json
import logging
import sys
from pathlib import Path

from heavecomp.errors import InputError
from heavecomp.report import invocation
from heavecomp.report.paths import out_dir
from heavecomp.report.provenance import _clean, annotate_json, stamp, stamp_report

ROOT = Path(__file__).resolve().parents[2]


def parse_args(argv, name: str, doc: str | None = None, extra=None) -> argparse.Namespace:
    """``--quick`` and ``--out DIR`` (default ``reports/<name>``) for every scenario.

    Parameters
    ----------
    argv : list of str or None
        The arguments (None: ``sys.argv[1:]``).
    name : str
        The scenario (its file name without ``.py``).
    doc : str or None
        The scenario's docstring; its first line is the help description.
    extra : callable or None
        ``extra(parser)`` adds the scenario's own arguments.

    Returns
    -------
    argparse.Namespace
        ``out`` a :class:`pathlib.Path` to a folder that exists.
    """
    p = argparse.ArgumentParser(prog=f"scenarios/{name}.py", description=(doc or "").strip().splitlines()[0] if doc else None)
    p.add_argument("--quick", action="store_true", help="short runs (for tests and a first look)")
    p.add_argument("--out", default=str(ROOT / "reports" / name), help=f"output folder (default reports/{name})")
    if extra:
        extra(p)
    args = p.parse_args(argv)
    try:
        out_dir(args.out, "--out")
    except InputError as exc:
        p.exit(2, f"{p.prog}: error: {exc}\n")

    given = list(sys.argv[1:] if argv is None else argv)
    invocation.COMMAND = ["python", f"scenarios/{name}.py", *given]
    args.out = Path(args.out)
    args.out.mkdir(parents=True, exist_ok=True)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    return args


def run(main, argv=None) -> int:
    """Run a scenario's ``main``: bad input (any :class:`InputError`) is one line on stderr and exit
    code 2, never a traceback; Ctrl-C is exit 130.

    Parameters
    ----------
    main : callable
        ``main(argv) -> int or None``: the scenario.
    argv : list of str or None
        Passed to ``main``.

    Returns
    -------
    int
        Exit code.
    """

    try:
        return int(main(argv) or 0)
    except InputError as exc:
        name = Path(sys.argv[0]).name if argv is None else "scenario"
        print(f"{name}: error: {str(exc).strip().replace(chr(10), ' ')}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130


def write_metrics(out: Path, metrics: dict) -> Path:
    """``metrics.json`` with a provenance stamp and units; wall-clock timings go to the untracked
    ``timings.json`` (a re-run leaves the tracked result unchanged).

    Parameters
    ----------
    out : pathlib.Path
        Output folder.
    metrics : dict
        The metrics [SI; units by key].

    Returns
    -------
    pathlib.Path
        The ``metrics.json`` written.
    """

    path = Path(out) / "metrics.json"
    path.write_text(json.dumps(_clean(metrics), indent=2) + "\n")
    annotate_json(path, stamp())
    return path


def settings_hash(settings: dict) -> str:
    """sha256 (16 hex digits) of a scenario's frozen settings, keys sorted.

    Parameters
    ----------
    settings : dict
        The settings (JSON-ready; anything else is hashed by its ``str``).

    Returns
    -------
    str
    """
    return hashlib.sha256(json.dumps(settings, sort_keys=True, default=str).encode()).hexdigest()[:16]


def frozen_check(which: str, digest: str, tuning_metrics: Path, owner: str, what: str) -> tuple[bool, str]:
    """(ok, message): a scoring set runs only with the settings the committed tuning report froze.

    Parameters
    ----------
    which : str
        The set asked for; only ``scoring`` is checked.
    digest : str
        The current settings' :func:`settings_hash`.
    tuning_metrics : pathlib.Path
        The committed tuning report's ``metrics.json`` (its ``settings_hash``).
    owner : str
        Whose settings, in the refusal (``monitor``, ``GapDiagnoser``).
    what : str
        What a change would have changed (``settings``, ``thresholds``).

    Returns
    -------
    (bool, str)
        Whether the set may be scored, and the sentence the report and the refusal print.
    """
    if which != "scoring":
        return True, f"settings hash `{digest}` (this tuning report freezes them for the scoring set)"
    if not tuning_metrics.is_file():
        return False, f"no tuning report at {tuning_metrics.relative_to(ROOT)}: run --set tuning first and commit it"
    frozen = json.loads(tuning_metrics.read_text()).get("settings_hash")
    if frozen != digest:
        return False, (f"{owner} settings hash {digest} differs from the tuning report's {frozen}: the {what} "
                       "were changed after tuning")
    return True, f"settings hash `{digest}` = the committed tuning report's ({what} frozen)"


def run_cases(task, items, extra, jobs: int, done, order=None) -> None:
    """``task(item, *extra, n_jobs)`` for every item: in this process with ``n_jobs`` 2 (``jobs`` 1), or in
    ``jobs`` ``spawn`` processes with ``n_jobs`` 1 each; ``done(i, result)`` in this process as each finishes.

    Parameters
    ----------
    task : callable
        A module-level function (it is pickled to the workers).
    items : sequence
        One entry per task.
    extra : tuple
        The task's arguments after the item, the same for every item.
    jobs : int
        Parallel processes (1: none).
    done : callable (int, result)
        Called with the item's index and its result, in the order they finish.
    order : sequence of int, optional
        The order the items are started in (default: as given).
    """
    order = range(len(items)) if order is None else order
    if jobs == 1:
        for i in order:
            done(i, task(items[i], *extra, 2))
        return
    import concurrent.futures as cf
    import multiprocessing as mp

    with cf.ProcessPoolExecutor(jobs, mp_context=mp.get_context("spawn")) as ex:
        futs = {ex.submit(task, items[i], *extra, 1): i for i in order}
        for f in cf.as_completed(futs):
            done(futs[f], f.result())


def md_table(header, rows, fmt="{:.2f}") -> str:
    """Markdown table; floats formatted with ``fmt``.

    Parameters
    ----------
    header : sequence of str
        Column headers.
    rows : iterable of sequence
        One sequence of cells per row.
    fmt : str
        Format of a float cell.

    Returns
    -------
    str
    """
    def cell(v):
        return fmt.format(v) if isinstance(v, float) else str(v)
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(cell(v) for v in r) + " |" for r in rows]
    return "\n".join(lines)


def write_report(out: Path, title: str, sections: list[str]) -> Path:
    """``report.md`` (ending with the provenance stamp) and its self-contained ``report.html``.

    Parameters
    ----------
    out : pathlib.Path
        Output folder.
    title : str
        The report's ``#`` heading.
    sections : list of str
        Markdown sections, in order.

    Returns
    -------
    pathlib.Path
        The ``report.md`` written.
    """

    path = Path(out) / "report.md"
    path.write_text(f"# {title}\n\n" + "\n\n".join(s.strip() for s in sections) + "\n")
    stamp_report(path, stamp())
    return path
