"""A fleet of logs (a fleet's day, a month of one rig): each log monitored, and diagnosed, as one task
of the campaign executor (issue 23 item 5).

:func:`plan` finds the logs (a folder, or a glob) and checks everything a user can get wrong before any
work: no log found, a parameter file, an unknown key of the manifest, a log whose columns cannot be
mapped or whose units do not fit (the start of each log is read with the reader ``diagnose`` uses,
:func:`heavecomp.diagnosis.data.check_head`: the same one-line messages naming the column; a log is read
whole once, in its task).

:func:`run_fleet` runs :func:`run_log` on each log through :func:`heavecomp.campaign.execute.execute`
(in this process, local processes, or Dask) and is the only writer: each finished log's result is
written into ``OUT/logs/.<key>.partial`` and renamed to ``OUT/logs/<key>`` in one step, so a log's
result is whole or absent.  ``task.json`` in it holds the status (``done`` or ``failed`` with its one-line
reason) and the task's fingerprint (the log's path, size and modification time, the parameter file's
bytes, the column mapping and units, the settings and the method's sources).  A rerun into the same
folder resumes: a log whose result is there with the same fingerprint and ``done`` is not recomputed;
a failed log is tried again.  A log that fails inside its task (a monitor or diagnosis error, a log too
short to monitor, a unit the head did not show) is recorded as failed, not a crash of the fleet.

What a log's result holds is written by a ``write(folder, result)`` function the caller gives
(:func:`heavecomp.report.fleet.write_log`: ``monitor.json``, ``segment_<i>/diagnosis.json``); the summary
table is :mod:`heavecomp.report.fleet`'s.

The manifest (optional, TOML) gives parameter files, column mappings and units, for every log or per log::

    params = "nominal.toml"          # every log (relative paths: from the manifest's folder)
    columns = {t = "Time"}           # or "t=Time,wob=WOB", as the command line takes it
    units = {pressure = "bar"}

    [logs."day01.csv"]               # one log, by its file name (or its path relative to the folder)
    params = "rig_b.toml"
    units = {wob = "kN"}

Precedence, key by key: a log's own entry, then the arguments (``params``, ``columns``, ``units``),
then the manifest's top level.
"""

from __future__ import annotations

import dataclasses
import glob
import hashlib
import json
import logging
import os
import shutil
import time
import uuid
from pathlib import Path

from heavecomp import __version__
from heavecomp.campaign.execute import execute
from heavecomp.diagnosis import monitor as M
from heavecomp.diagnosis.data import check_head, load_run
from heavecomp.effects.spec import load
from heavecomp.errors import InputError, did_you_mean
from heavecomp.io.series import check_spec, parse_mapping, short
from heavecomp.simulate.layout import source_hash

log = logging.getLogger(__name__)

RESULTS = "logs"  #: folder of the per-log results inside the output folder
TASK = "task.json"  #: a log result's status and fingerprint
#: file name endings of logs found in a folder (the reader recognises formats by content; compressed
#: text logs end in one of these plus .gz, .bz2, .xz or .zip)
LOG_SUFFIXES = (".csv", ".txt", ".tsv", ".dat", ".parquet", ".mat", ".xml", ".las")  # .xml: WITSML 1.4.1.1
COMPRESSED = (".gz", ".bz2", ".xz", ".zip")
MANIFEST_KEYS = ("params", "columns", "units", "logs")
LOG_KEYS = ("params", "columns", "units")


@dataclasses.dataclass(frozen=True)
class LogTask:
    """One log of the fleet, checked and ready to run.

    Attributes
    ----------
    key : str
        Its result folder's name (``OUT/logs/<key>``): the path relative to the fleet's folder, log
        suffix dropped, ``/`` as ``--``.
    path : str
        The log file (absolute).
    params : str
        Its parameter file (absolute).
    columns, units : dict
        Contract column -> source column / unit.
    fingerprint : str
        What the result depends on (see the module docstring), hex.
    """

    key: str
    path: str
    params: str
    columns: dict
    units: dict
    fingerprint: str


@dataclasses.dataclass(frozen=True)
class Settings:
    """What every task of a fleet does (the same for every log).

    Attributes
    ----------
    diagnose : bool
        Diagnose each segment that carries a gap (:func:`heavecomp.diagnosis.monitor.diagnose_segments`).
    block : float [s]
        The monitor's statistic block (None: :data:`heavecomp.diagnosis.monitor.BLOCK`).
    """

    diagnose: bool = False
    block: float | None = None


@dataclasses.dataclass
class FleetRun:
    """What :func:`run_fleet` did: folder, counts, timing."""

    out_dir: Path
    keys: list
    n_skipped: int
    n_computed: int
    n_failed: int
    wall_time: float
    executor: str
    workers: int

    @property
    def complete(self) -> bool:
        return self.n_skipped + self.n_computed == len(self.keys)


# ------------------------------------------------------------------------------------------- finding
def _uncompressed(name: str) -> str:
    """``name`` without its compression suffix (:data:`COMPRESSED`, any case)."""
    low = name.lower()
    return next((name[: -len(z)] for z in COMPRESSED if low.endswith(z)), name)


def _is_log(p: Path) -> bool:
    name = p.name.lower()
    if name.startswith(".") or name.endswith(".units.csv") or not p.is_file():
        return False
    return _uncompressed(name).endswith(LOG_SUFFIXES)


def _stem(name: str) -> str:
    name = _uncompressed(name)
    low = name.lower()
    return next((name[: -len(s)] for s in LOG_SUFFIXES if low.endswith(s)), name)


def find_logs(source) -> tuple[Path, list]:
    """The logs of a folder (its files ending in :data:`LOG_SUFFIXES`, compressed or not; not its
    sub-folders, hidden files and ``*.units.csv``) or of a glob pattern (``**`` for sub-folders).

    Parameters
    ----------
    source : str or os.PathLike
        A folder or a glob pattern.

    Returns
    -------
    (pathlib.Path, list of pathlib.Path)
        The folder the logs are named from (the pattern's fixed part) and the logs, sorted.

    Raises
    ------
    heavecomp.errors.InputError
        No log found.
    """
    src = str(source)
    p = Path(src)
    if p.is_dir():
        root, files = p, sorted(q for q in p.iterdir() if _is_log(q))
    elif glob.has_magic(src):
        files = sorted(Path(q) for q in glob.glob(src, recursive=True) if _is_log(Path(q)))
        fixed = []
        for part in p.parts:
            if glob.has_magic(part):
                break
            fixed.append(part)
        root = Path(*fixed) if fixed else Path(".")
    elif p.exists():
        raise InputError(f"{short(src)}: a file, not a folder of logs or a glob pattern")
    else:
        raise InputError(f"{short(src)}: no such folder")
    if not files:
        raise InputError(f"{short(src)}: no log found (files ending in {', '.join(LOG_SUFFIXES)}, "
                         f"or these compressed with {', '.join(COMPRESSED)})")
    return root, files


def _key(root: Path, path: Path) -> str:
    try:
        rel = path.resolve().relative_to(root.resolve())
    except ValueError:
        rel = Path(path.name)
    return "--".join(rel.parts[:-1] + (_stem(rel.name),))


# ------------------------------------------------------------------------------------------- manifest
def _mapping(value, where: str) -> dict:
    if isinstance(value, str):
        return parse_mapping(value, where)
    if isinstance(value, dict) and all(isinstance(v, str) for v in value.values()):
        return {str(k): v for k, v in value.items()}
    raise InputError(f"{where}: a table of strings ({{t = \"Time\"}}) or a string \"t=Time,...\", got {value!r}")


def _entry(d: dict, allowed, where: str, base: Path) -> dict:
    out = {}
    for k, v in d.items():
        if k not in allowed:
            raise InputError(f"{where}: unknown key '{k}'{did_you_mean(k, allowed)} (known: {', '.join(allowed)})")
        if k == "params":
            if not isinstance(v, str):
                raise InputError(f"{where}: key 'params': a file name, got {v!r}")
            out[k] = str((base / v).resolve())
        elif k in ("columns", "units"):
            out[k] = _mapping(v, f"{where}: key '{k}'")
    check_spec(out.get("columns"), out.get("units"), where)  # contract names, known units of the right kind
    return out


def load_manifest(path) -> dict:
    """Read a fleet manifest (TOML, see the module docstring); every key is checked.

    Parameters
    ----------
    path : str or os.PathLike
        The manifest.

    Returns
    -------
    dict
        ``{"params": str, "columns": dict, "units": dict, "logs": {name: {...}}}`` (the keys present);
        parameter files absolute.

    Raises
    ------
    heavecomp.errors.InputError
        Unreadable file, bad TOML, an unknown key (named, with the closest known one).
    """
    import tomllib

    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{short(p)}: cannot read the manifest ({getattr(exc, 'strerror', None) or type(exc).__name__})") from None
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{short(p)}: not valid TOML ({exc})") from None
    top = _entry({k: v for k, v in raw.items() if k != "logs"}, MANIFEST_KEYS, str(short(p)), p.parent)
    logs = raw.get("logs", {})
    if not isinstance(logs, dict):
        raise InputError(f"{short(p)}: key 'logs': a table of logs ([logs.\"NAME\"]), got {logs!r}")
    top["logs"] = {}
    for name, d in logs.items():
        if not isinstance(d, dict):
            raise InputError(f"{short(p)}: logs.{name}: a table (params, columns, units), got {d!r}")
        top["logs"][name] = _entry(d, LOG_KEYS, f"{short(p)}: logs.\"{name}\"", p.parent)
    return top


# ------------------------------------------------------------------------------------------- checking
def _method_hash() -> str:
    """The sources a log's result is computed by: the diagnosis package and the stepper's."""
    h = hashlib.sha256(f"{__version__} {source_hash():x}".encode())
    for f in sorted((Path(__file__).parents[1] / "diagnosis").glob("*.py")):
        h.update(f.read_bytes())
    return h.hexdigest()


def check_log(path, params, *, columns=None, units=None) -> None:
    """Check a log before any work, reading only its start (:func:`heavecomp.diagnosis.data.check_head`):
    its columns map, its units are known and of the right kind, and (a text or Parquet log) the
    magnitudes of its first rows fit ``params``; of a MATLAB log only the variable headers are read.

    Parameters
    ----------
    path : str or os.PathLike
        The log.
    params : heavecomp.params.CMCParams
        Its nominal parameters.
    columns, units : dict, optional
        Contract column -> source column / unit.

    Raises
    ------
    heavecomp.errors.DataError
        One line naming the log and the column, as ``load_run`` says it.
    """
    check_head(path, params, columns=columns, units=units)


def plan(source, params=None, *, manifest=None, columns=None, units=None, check=True) -> list:
    """The fleet's tasks, every input checked before any work (see the module docstring).

    Parameters
    ----------
    source : str or os.PathLike
        A folder of logs or a glob pattern (:func:`find_logs`).
    params : str or os.PathLike, optional
        The parameter file of every log the manifest gives none for.
    manifest : str or os.PathLike, optional
        The fleet manifest (:func:`load_manifest`).
    columns, units : dict, optional
        Contract column -> source column / unit, for every log.
    check : bool
        Check each log's columns and units (:func:`check_log`).

    Returns
    -------
    list of LogTask

    Raises
    ------
    heavecomp.errors.InputError
        No log; a log without a parameter file; an unknown manifest key or a manifest entry naming no
        log of the fleet; two logs of one result name; a bad parameter file, column or unit (named).
    """
    root, files = find_logs(source)
    man = load_manifest(manifest) if manifest else {"logs": {}}
    columns, units = check_spec(columns or {}, units or {}, "fleet")
    by_name = {}
    for f in files:
        by_name.setdefault(f.name, f)
        try:
            by_name.setdefault(str(f.resolve().relative_to(root.resolve())), f)
        except ValueError:
            pass
    for name in man["logs"]:
        if name not in by_name:
            raise InputError(f"{short(manifest)}: logs.\"{name}\": no such log in {short(source)}"
                             f"{did_you_mean(name, sorted(by_name))}")
    per_log = {}
    for name, d in man["logs"].items():
        per_log[by_name[name]] = d
    code = _method_hash()
    loaded, keys, tasks = {}, {}, []
    for f in files:
        own = per_log.get(f, {})
        pfile = own.get("params") or (str(Path(params).resolve()) if params else None) or man.get("params")
        if not pfile:
            raise InputError(f"{short(f)}: no parameter file for this log (give one for every log, or per log "
                             "in the manifest)", option="params")
        cols = {**man.get("columns", {}), **columns, **own.get("columns", {})}
        uns = {**man.get("units", {}), **units, **own.get("units", {})}
        cols, uns = check_spec(cols, uns, "fleet")
        if pfile not in loaded:
            loaded[pfile] = load(pfile, heave_file=False)
        if check:
            check_log(f, loaded[pfile], columns=cols, units=uns)
        key = _key(root, f)
        if key in keys:
            raise InputError(f"{short(keys[key])} and {short(f)}: both would be the fleet's log '{key}'; rename one")
        keys[key] = f
        st = f.stat()
        fp = hashlib.sha256(json.dumps({"log": str(f.resolve()), "size": st.st_size, "mtime_ns": st.st_mtime_ns,
                                        "params": hashlib.sha256(Path(pfile).read_bytes()).hexdigest(),
                                        "columns": cols, "units": uns, "code": code}, sort_keys=True).encode())
        tasks.append(LogTask(key, str(f.resolve()), pfile, cols, uns, fp.hexdigest()))
    return tasks


# ------------------------------------------------------------------------------------------- one task
def _reason(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    if isinstance(exc, InputError):
        return text
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def run_log(settings: Settings, task: LogTask) -> dict:
    """One task: read the log, monitor it and (``settings.diagnose``) diagnose its segments.

    Any error of the log is caught and returned as a failure (the fleet goes on).

    Parameters
    ----------
    settings : Settings
        What every task does.
    task : LogTask
        The log.

    Returns
    -------
    dict
        ``key``, ``status`` (``done`` or ``failed``), ``reason`` (failed: one line), ``monitor`` (the
        ``monitor.json`` content), ``diagnoses`` (segment index -> ``diagnosis.json`` content),
        ``wall_s`` [s], ``cpu_s`` [s] (this process' CPU time of the task), ``pid``.
    """
    t0, c0 = time.perf_counter(), time.process_time()
    out = {"key": task.key, "status": "done", "reason": "", "monitor": None, "diagnoses": {}, "pid": os.getpid()}
    try:
        params = load(task.params, heave_file=False)
        run = load_run(task.path, params, columns=task.columns, units=task.units)
        if run.duration < M.MIN_DURATION:
            raise InputError(f"{run.source}: the log spans {run.duration:.3g} s; the monitor needs at least "
                             f"{M.MIN_DURATION:g} s")
        block = M.BLOCK if settings.block is None else settings.block
        res = M.monitor(run, params, block=block)
        if settings.diagnose:
            out["diagnoses"] = M.diagnose_segments(res, run, params, n_jobs=1)
        d = res.to_json()
        if run.measurement:
            d["measurement"] = run.measurement
        out["monitor"] = d
    except Exception as exc:  # noqa: BLE001 - a log's failure is recorded, the fleet goes on
        log.info("%s: failed: %s", task.key, _reason(exc))
        out.update(status="failed", reason=_reason(exc), monitor=None, diagnoses={})
    out["wall_s"], out["cpu_s"] = time.perf_counter() - t0, time.process_time() - c0
    return out


# ------------------------------------------------------------------------------------------- the fleet
def fingerprint(task: LogTask, settings: Settings) -> str:
    """The fingerprint a log's result is stored with (:attr:`LogTask.fingerprint` and ``settings``).

    Parameters
    ----------
    task : LogTask
    settings : Settings

    Returns
    -------
    str
        Hex digest.
    """
    return hashlib.sha256(f"{task.fingerprint} {json.dumps(dataclasses.asdict(settings), sort_keys=True)}"
                          .encode()).hexdigest()


def read_task(folder) -> dict | None:
    """The ``task.json`` of a log's result folder, or None (absent, unreadable).

    Parameters
    ----------
    folder : str or os.PathLike
        ``OUT/logs/<key>``.
    """
    return read_json(Path(folder) / TASK)


def read_json(path):
    """The content of a JSON file of a fleet's result, or None (absent, unreadable, not JSON).

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    """
    try:
        return json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def finished(out_dir, tasks, settings: Settings) -> set:
    """Keys of the logs whose result is in ``out_dir`` with their fingerprint, ``done``.

    Parameters
    ----------
    out_dir : str or os.PathLike
        The fleet's output folder.
    tasks : list of LogTask
    settings : Settings

    Returns
    -------
    set of str
    """
    done = set()
    for t in tasks:
        folder = Path(out_dir) / RESULTS / t.key
        info = read_task(folder)
        if (info and info.get("status") == "done" and info.get("fingerprint") == fingerprint(t, settings)
                and intact(folder, info)):
            done.add(t.key)
    return done


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def intact(folder, info) -> bool:
    """Whether a finished log's result folder holds what its ``task.json`` says it wrote: every file it lists
    (``files``: name -> sha256) with those bytes, and a readable ``monitor.json`` (a result of an earlier
    version lists none).  A file torn by a crash or a full disk, or replaced by another log's, is not: the
    log is computed again (``fleet --resume`` took a torn ``monitor.json`` over and reported the log done,
    with no data).

    Parameters
    ----------
    folder : str or os.PathLike
        ``OUT/logs/<key>``.
    info : dict
        Its ``task.json``.
    """
    folder = Path(folder)
    try:
        if any(_digest(folder / name) != h for name, h in (info.get("files") or {}).items()):
            return False
    except OSError:
        return False
    mon = read_json(folder / "monitor.json")
    return isinstance(mon, dict) and "segments" in mon and "changes" in mon


def _durable(folder: Path) -> None:
    """Every file under ``folder`` and the folders themselves flushed to the disk (fsync), so a rename that
    follows publishes whole files after a power loss too."""
    for p in sorted(folder.rglob("*")) + [folder]:
        _fsync_dir(p)


def _write_json(path: Path, d) -> None:
    path.write_text(json.dumps(d, indent=2) + "\n", encoding="utf-8")


def _fsync_dir(path: Path) -> None:
    """fsync one file or folder (a folder: its entries, e.g. a rename in it)."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _place(out: Path, key: str, result: dict, fp: str, run_id: str, write) -> None:
    """Write one log's result whole: into ``.key.partial``, then renamed to ``key``."""
    results = out / RESULTS
    work = results / f".{key}.partial"
    if work.exists():
        shutil.rmtree(work)
    work.mkdir(parents=True)
    if result["status"] == "done":
        write(work, result)
    files = {str(p.relative_to(work)): _digest(p) for p in sorted(work.rglob("*")) if p.is_file()}
    _write_json(work / TASK, {"key": key, "status": result["status"], "reason": result["reason"], "fingerprint": fp,
                              "fleet_run": run_id, "wall_s": round(result["wall_s"], 3),
                              "cpu_s": round(result["cpu_s"], 3), "files": files})
    _durable(work)
    final = results / key
    if final.exists():
        shutil.rmtree(final)
    os.rename(work, final)
    _fsync_dir(results)  # the rename itself


def run_fleet(tasks, out_dir, settings: Settings, write, *, workers: int | None = None, scheduler: str | None = None,
              client=None, progress=None, limit: int | None = None) -> FleetRun:
    """Run every task not yet finished in ``out_dir`` (see the module docstring); this process writes.

    Parameters
    ----------
    tasks : list of LogTask
        :func:`plan`'s answer.
    out_dir : str or os.PathLike
        Output folder (created); rerunning into it resumes.
    settings : Settings
        What every task does.
    write : callable (folder, result)
        Writes a finished log's result (:func:`run_log`'s dict) into ``folder`` (a module-level function
        of the report layer: :func:`heavecomp.report.fleet.write_log`).
    workers : int, optional
        Local worker processes (default: all cores); ignored with a scheduler.
    scheduler : str, optional
        Address of a Dask scheduler.
    client : dask.distributed.Client, optional
        An existing client (takes precedence over ``scheduler``).
    progress : callable (done, total), optional
        Called after each finished log with log counts.
    limit : int, optional
        Run at most this many pending logs and stop (a deliberately partial fleet).

    Returns
    -------
    FleetRun
    """
    out = Path(out_dir)
    (out / RESULTS).mkdir(parents=True, exist_ok=True)
    done = finished(out, tasks, settings)
    pending = [t for t in tasks if t.key not in done]
    if limit is not None:
        pending = pending[:max(0, int(limit))]
    fps = {t.key: fingerprint(t, settings) for t in tasks}
    run_id = uuid.uuid4().hex[:12]
    total, count, failed = len(tasks), len(done), 0
    if done:
        log.info("resuming: %d of %d logs already in %s", len(done), total, out / RESULTS)
    if progress:
        progress(count, total)
    t0 = time.perf_counter()

    def finish(result):
        nonlocal count, failed
        _place(out, result["key"], result, fps[result["key"]], run_id, write)
        count += 1
        failed += result["status"] != "done"
        if progress:
            progress(count, total)

    executor, nw = execute(run_log, pending, finish, shared=settings, workers=workers, scheduler=scheduler,
                           client=client)
    wall = time.perf_counter() - t0
    log.info("%d logs in %.1f s (%s, %d workers), %d failed", count - len(done), wall, executor, nw, failed)
    return FleetRun(out, [t.key for t in tasks], len(done), count - len(done), failed, wall, executor, nw)
