"""Draw a figure in a forked process while the caller keeps computing.

Importing matplotlib and rendering a PNG costs ~0.5 s, more than simulating an
hour of the CMC.  :class:`BackgroundFigure` forks at construction; the child
imports matplotlib at once (in parallel with the parent's work), then waits
for one job ``(function, args, kwargs, path)``, draws and saves it.  Where
``fork`` is unavailable (Windows, macOS default) or disabled with
``HEAVECOMP_NO_FORK=1`` the job runs inline in :meth:`wait`; the result is the
same file either way.
"""

from __future__ import annotations

import logging
import os
import sys

from heavecomp.report.figures import pyplot, save

log = logging.getLogger(__name__)


def _draw(func, args, kwargs, path, save_kwargs):
    save(func(*args, **kwargs), path, **save_kwargs)


def _die_with_parent(parent_pid: int) -> None:
    """Have the kernel kill this (child) process when its parent dies (Linux ``PR_SET_PDEATHSIG``).

    Without it a child blocked in ``recv`` outlives a parent killed by SIGTERM/SIGKILL
    (issue 14.2).  The ``getppid`` check closes the race of a parent that died before
    the ``prctl`` call.
    """
    try:
        import ctypes
        import signal

        libc = ctypes.CDLL(None, use_errno=True)
        PR_SET_PDEATHSIG = 1
        libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
    except Exception:  # noqa: BLE001 - no prctl: the closed pipe below still ends the child
        pass
    if os.getppid() != parent_pid:
        os._exit(1)


def _worker(conn, send_end, parent_pid):
    try:
        _die_with_parent(parent_pid)
        # drop the child's copy of the parent's end: if the parent dies, recv() sees EOF
        send_end.close()
        pyplot()  # the expensive import happens while the parent computes
        job = conn.recv()
        if job is not None:
            _draw(*job)
        os._exit(0)
    except BaseException:  # noqa: BLE001 - the parent redraws inline on failure
        os._exit(1)


class BackgroundFigure:
    """One figure drawn in a child process (see module docstring)."""

    def __init__(self):
        self._proc = None
        self._job = None
        self._sender = None
        self._sent_ok = True
        if sys.platform.startswith("linux") and not os.environ.get("HEAVECOMP_NO_FORK"):
            import multiprocessing as mp

            ctx = mp.get_context("fork")
            recv, self._send = ctx.Pipe(duplex=False)
            self._proc = ctx.Process(target=_worker, args=(recv, self._send, os.getpid()), daemon=True)
            self._proc.start()
            recv.close()  # the parent only sends

    def draw(self, func, *args, path, save_kwargs=None, **kwargs):
        """Hand the figure job over (``func(*args, **kwargs)`` must return a Figure)."""
        self._job = (func, args, kwargs, path, save_kwargs or {})
        if self._proc is not None:
            import threading

            # the child may still be importing matplotlib: hand the (large) job over from a
            # thread so the caller can go on writing its other outputs
            self._sender = threading.Thread(target=self._send_job, daemon=True)
            self._sender.start()

    def _send_job(self):
        try:
            self._send.send(self._job)
        except Exception as exc:  # noqa: BLE001 - broken pipe, unpicklable job: wait() draws inline
            log.debug("background figure: %s; drawing inline", exc)
            self._sent_ok = False

    def wait(self):
        """Block until the figure is written (draws inline if there is no child or it failed)."""
        if self._proc is not None:
            if self._sender is not None:
                self._sender.join()
            if not self._sent_ok:
                self._stop()
            else:
                self._proc.join(timeout=300)
                ok = self._proc.exitcode == 0
                self._stop()
                if ok:
                    return
        if self._job is not None:
            _draw(*self._job)

    def _stop(self):
        if self._proc is not None:
            if self._proc.exitcode is None:
                self._proc.kill()
            self._proc.join()
            self._proc = None

    def cancel(self):
        """Stop the child without drawing (e.g. when the computation failed)."""
        if self._proc is not None:
            try:
                self._send.send(None)
            except OSError:
                pass
            self._stop()
        self._job = None
