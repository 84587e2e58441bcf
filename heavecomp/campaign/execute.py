"""Run a campaign: local processes by default, or a Dask cluster; resumable.

The unit of work is a *chunk* of ``campaign.chunk_size`` runs, executed by
:func:`heavecomp.campaign.batch.run_chunk` (one compiled batch call).  The
parent process is the only writer: each finished chunk is appended to
``DIR/runs.csv`` (one row per run, key ``run_id``) and flushed to disk, so an
interrupted campaign loses at most the chunks in flight.  A rerun with the same
``--out`` reads ``runs.csv``, skips every ``run_id`` already there (a partly
written last line is discarded) and simulates the rest.  ``DIR/manifest.json``
holds the campaign's fingerprint; resuming into a folder of a *different*
campaign is refused.

Executors (no home-made job system; :func:`execute`, which the fleet of logs,
:mod:`heavecomp.campaign.fleet`, runs on too):

- ``workers == 1``: in this process;
- ``workers > 1`` (default: all cores): :class:`concurrent.futures.ProcessPoolExecutor`
  (``spawn``), one numba thread per process;
- ``scheduler=ADDRESS`` or ``client=``: :mod:`dask.distributed` (``Client.map`` +
  ``as_completed``); workers need ``heavecomp`` installed.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import logging
import os
import time
from pathlib import Path

from heavecomp.errors import InputError
from heavecomp.simulate.layout import source_hash
from heavecomp.io.series import short

log = logging.getLogger(__name__)

TABLE = "runs.csv"
MANIFEST = "manifest.json"
STRING_COLUMNS = ("run_id", "regime", "variant")
CONNECT_TIMEOUT = "15s"  #: how long to wait for a Dask scheduler


@dataclasses.dataclass
class CampaignRun:
    """What :func:`run_campaign` did: folder, counts, timing."""

    out_dir: Path
    n_total: int
    n_skipped: int
    n_simulated: int
    wall_time: float
    executor: str
    workers: int

    @property
    def table_path(self) -> Path:
        return self.out_dir / TABLE

    @property
    def complete(self) -> bool:
        return self.n_skipped + self.n_simulated == self.n_total


def _check_manifest(campaign, out: Path):
    man = out / MANIFEST
    fp = campaign.fingerprint()
    physics = f"{source_hash():x}"  # the stepper's source files: results of other physics are not resumed
    if man.is_file():
        try:
            old = json.loads(man.read_text())
        except json.JSONDecodeError:
            raise InputError(f"{out}: {MANIFEST} is not valid JSON (remove the folder or choose another output folder)",
                             option="out") from None
        if old.get("fingerprint") != fp:
            raise InputError(f"{out}: holds results of a different campaign (fingerprint {old.get('fingerprint')} "
                             f"!= {fp}); choose another output folder", option="out")
        if old.get("physics", physics) != physics:
            raise InputError(f"{out}: holds results of another version of the plant/stepper source "
                             f"({old.get('physics')} != {physics}); choose another output folder or remove it",
                             option="out")
    else:
        out.mkdir(parents=True, exist_ok=True)
        man.write_text(json.dumps({"schema": 1, "campaign": campaign.settings.name, "fingerprint": fp,
                                   "physics": physics, "n_runs": len(campaign.runs())}, indent=2) + "\n")
        (out / "campaign.toml").write_text(campaign.source_text)


def finished_ids(path: Path) -> tuple[set, list | None]:
    """run_ids already in ``runs.csv`` and its header; a partial last line is cut off.

    Parameters
    ----------
    path : pathlib.Path
        The results table (need not exist).

    Returns
    -------
    (set of str, list of str or None)
        The run_ids and the header; (empty set, None) for a missing or empty table.

    Raises
    ------
    heavecomp.errors.InputError
        The table has no ``run_id`` column.
    """
    if not path.is_file():
        return set(), None
    raw = path.read_bytes()
    if raw and not raw.endswith(b"\n"):
        cut = raw.rfind(b"\n") + 1
        log.warning("%s: discarding a partly written last line (interrupted run)", path)
        with path.open("r+b") as fh:
            fh.truncate(cut)
    reader = csv.reader(io.StringIO(_table_text(path)))
    header = next(reader, None)
    if header is None:
        return set(), None
    if "run_id" not in header:
        raise InputError(f"{path}: column 'run_id' missing — not a campaign table")
    k = header.index("run_id")
    ids = {row[k] for row in reader if len(row) == len(header)}
    return ids, header


def _table_text(path: Path) -> str:
    """Text of ``runs.csv`` (heavecomp writes plain UTF-8); a compressed, binary or non-UTF-8 file is a
    one-line InputError, not a traceback."""

    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise InputError(f"{short(path)}: cannot read ({exc.strerror or type(exc).__name__})") from None
    if raw[:2] == b"\x1f\x8b" or raw[:3] == b"BZh" or raw[:4] in (b"PK\x03\x04", b"PAR1") or b"\x00" in raw[:4096]:
        raise InputError(f"{short(path)}: not the plain CSV table heavecomp writes (compressed or binary); "
                         "restore it or remove it to rerun the campaign")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"{short(path)}: not UTF-8 text (byte {exc.start}); not a table heavecomp wrote") from None


class _Writer:
    def __init__(self, path: Path, header):
        self.path = path
        self.header = header

    def write(self, rows):
        if not rows:
            return
        new = self.header is None
        if new:
            self.header = list(rows[0])
        elif set(rows[0]) != set(self.header):
            raise InputError(f"{self.path}: its columns differ from this heavecomp version's table "
                             "(written by another version?); choose another output folder", option="out")
        with self.path.open("a", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=self.header, extrasaction="raise")
            if new:
                w.writeheader()
            for r in rows:
                w.writerow({k: (repr(float(v)) if isinstance(v, float) else v) for k, v in r.items()})
            fh.flush()
            os.fsync(fh.fileno())


def _init_worker(parent_pid: int):
    """Pool worker set-up: one numba thread; exit if the parent dies (e.g. killed by SIGTERM/SIGKILL),
    instead of lingering as an orphan blocked on the task queue."""
    import threading

    import numba

    numba.set_num_threads(1)

    def watch():
        while os.getppid() == parent_pid:
            time.sleep(0.5)
        os._exit(1)

    threading.Thread(target=watch, daemon=True).start()


def run_campaign(campaign, out_dir, *, workers: int | None = None, scheduler: str | None = None, client=None,
                 progress=None, limit: int | None = None) -> CampaignRun:
    """Simulate every run of ``campaign`` not yet in ``out_dir/runs.csv``.

    Parameters
    ----------
    campaign : Campaign
    out_dir : path
        Results folder (created).  Rerunning into it resumes.
    workers : int, optional
        Local worker processes (default: all cores); ignored with a scheduler.
    scheduler : str, optional
        Address of a Dask scheduler (``tcp://host:8786``).
    client : dask.distributed.Client, optional
        An existing client (takes precedence over ``scheduler``).
    progress : callable(done, total), optional
        Called after each finished chunk with run counts.
    limit : int, optional
        Simulate at most this many pending runs (whole chunks) and stop — a
        deliberately partial campaign (used to test resumption).

    Returns
    -------
    CampaignRun
    """
    from heavecomp.campaign.batch import check_budget

    out = Path(out_dir)
    _check_manifest(campaign, out)
    runs = campaign.runs()
    check_budget(campaign, runs)  # before any chunk runs (one line, exit 2 from the CLI)
    done, header = finished_ids(out / TABLE)
    pending = [r.run_id for r in runs if r.run_id not in done]
    n_skip = len(runs) - len(pending)
    if limit is not None:
        pending = pending[:max(0, int(limit))]
    cs = campaign.settings.chunk_size
    chunks = [pending[i:i + cs] for i in range(0, len(pending), cs)]
    writer = _Writer(out / TABLE, header)
    total, count = len(runs), n_skip
    if n_skip:
        log.info("resuming: %d of %d runs already in %s", n_skip, total, out / TABLE)
    if progress:
        progress(count, total)
    t0 = time.perf_counter()

    def finished(rows):
        nonlocal count
        writer.write(rows)
        count += len(rows)
        if progress:
            progress(count, total)

    executor, nw = execute(_campaign_chunk, chunks, finished, shared=campaign, workers=workers,
                           scheduler=scheduler, client=client)
    wall = time.perf_counter() - t0
    n_sim = count - n_skip
    log.info("%d runs simulated in %.1f s (%s, %d workers)", n_sim, wall, executor, nw)
    return CampaignRun(out, total, n_skip, n_sim, wall, executor, nw)


def _campaign_chunk(campaign, run_ids):
    """One task of a campaign: a chunk of runs in one compiled batch call, one numba thread."""
    from heavecomp.campaign.batch import run_chunk

    return run_chunk(campaign, run_ids, 1)


def execute(task, items, finished, *, shared=None, workers: int | None = None, scheduler: str | None = None,
            client=None) -> tuple[str, int]:
    """Run ``task(shared, item)`` for every item on the executor asked for; ``finished(result)`` is called
    in this process as each task completes (the parent is the only writer).

    The executor of :func:`run_campaign` and of :func:`heavecomp.campaign.fleet.run_fleet` (see the module
    docstring): in this process (``workers == 1``), local ``spawn`` processes with one numba thread each
    (``workers > 1``, default all cores, at most one per item), or :mod:`dask.distributed` (``scheduler``
    or ``client``; ``shared`` is scattered to every worker once).

    Parameters
    ----------
    task : callable (shared, item) -> result
        A module-level function (it is pickled to the workers).
    items : sequence
        One entry per task.
    finished : callable (result)
        Called in this process with each task's result, in the order they complete.
    shared : object, optional
        The task's first argument, the same for every item (picklable).
    workers : int, optional
        Local worker processes (default: all cores); ignored with a scheduler.
    scheduler : str, optional
        Address of a Dask scheduler (``tcp://host:8786``).
    client : dask.distributed.Client, optional
        An existing client (takes precedence over ``scheduler``).

    Returns
    -------
    (str, int)
        The executor (``in-process``, ``processes``, ``dask``) and its number of workers.

    Raises
    ------
    heavecomp.errors.InputError
        ``workers`` < 1; no ``dask.distributed``; a scheduler that cannot be reached.
    """
    if client is not None or scheduler:
        return _run_dask(task, items, finished, shared, scheduler, client)
    nw = int(workers) if workers else (os.cpu_count() or 1)
    if nw < 1:
        raise InputError(f"workers must be >= 1, got {workers}", option="workers")
    nw = min(nw, max(1, len(items)))
    if nw == 1:
        for it in items:
            finished(task(shared, it))
        return "in-process", nw
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor, as_completed

    with ProcessPoolExecutor(max_workers=nw, mp_context=mp.get_context("spawn"),
                             initializer=_init_worker, initargs=(os.getpid(),)) as pool:
        futs = [pool.submit(task, shared, it) for it in items]
        try:
            for f in as_completed(futs):
                finished(f.result())
        except BaseException:
            for f in futs:
                f.cancel()
            raise
    return "processes", nw


def _run_dask(task, items, finished, shared, scheduler, client):
    try:
        from dask.distributed import Client, as_completed
    except ImportError:
        raise InputError("scheduler needs dask.distributed (pip install 'heavecomp[cluster]')",
                         option="scheduler") from None

    own = client is None
    if own:
        try:
            client = Client(scheduler, timeout=CONNECT_TIMEOUT)
        except (OSError, TimeoutError, ValueError) as exc:
            raise InputError(f"scheduler {scheduler}: cannot connect ({type(exc).__name__}: {exc})",
                             option="scheduler") from None
    try:
        nw = len(client.scheduler_info().get("workers", {}))
        fs = client.scatter(shared, broadcast=True)
        futs = client.map(task, [fs] * len(items), list(items), pure=False)
        for f in as_completed(futs):
            finished(f.result())
    finally:
        if own:
            client.close()
    return "dask", nw


def _is_float(v) -> bool:
    try:
        float(v)
    except ValueError:
        return False
    return True


def read_table(path, campaign=None) -> dict:
    """``runs.csv`` as columns (numpy arrays; run_id/regime/variant as str).

    Each run counts once: a row repeated exactly is dropped (warning); two different rows with
    the same ``run_id``, a ``run_id`` that is not a run of ``campaign`` (when given), a row
    with more or fewer fields than the header and a non-numeric cell are one-line
    :class:`InputError` naming the row or run.

    Parameters
    ----------
    path : str or os.PathLike
        The results table.
    campaign : heavecomp.campaign.spec.Campaign or None
        When given, every ``run_id`` must be one of its runs.

    Returns
    -------
    dict
        Column name -> array over the runs [SI, the units of ``runs.csv``].
    """
    import numpy as np

    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: results table not found")
    reader = csv.reader(io.StringIO(_table_text(path)))
    header = next(reader, None)
    if not header:
        raise InputError(f"{path}: empty results table")
    if "run_id" not in header:
        raise InputError(f"{path}: column 'run_id' missing — not a campaign table")
    k = header.index("run_id")
    known = {r.run_id for r in campaign.runs()} if campaign is not None else None
    rows, seen, dropped = [], {}, 0
    for line, r in enumerate(reader, start=2):
        if not r:
            continue
        if len(r) != len(header):
            raise InputError(f"{path}: row {line} has {len(r)} fields, the header has {len(header)}")
        rid = r[k]
        if known is not None and rid not in known:
            raise InputError(f"{path}: row {line}: run_id '{rid}' is not a run of this campaign "
                             "(a table from another campaign?)")
        if rid in seen:
            if rows[seen[rid]] != r:
                raise InputError(f"{path}: row {line}: run_id '{rid}' appears twice with different results")
            dropped += 1
            continue
        seen[rid] = len(rows)
        rows.append(r)
    if dropped:
        log.warning("%s: %d duplicated rows counted once", path, dropped)
    cols = {}
    for j, name in enumerate(header):
        vals = [r[j] for r in rows]
        if name in STRING_COLUMNS:
            cols[name] = np.array(vals, dtype=object)
        else:
            try:
                cols[name] = np.array([float(v) for v in vals])
            except ValueError:
                bad = next(i for i, v in enumerate(vals) if not _is_float(v))
                raise InputError(f"{path}: column '{name}', run_id '{rows[bad][k]}': non-numeric value "
                                 f"{vals[bad][:20]!r}") from None
    return cols
