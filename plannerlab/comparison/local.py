"""The local trial backend: one fresh process per trial, forked from a warm fork server.

:func:`plannerlab.comparison.runner.run_comparison` hands each trial to a backend and takes
its record back. This backend runs every trial in its own process on this machine.

Decisions:

* **Fork server** (default, ``start_method="forkserver"``). Python's ``multiprocessing``
  fork server is a process started once per comparison that imports
  :data:`PRELOAD_MODULES` (numpy, scipy, toppra, and :mod:`plannerlab.run.preload`:
  python-fcl, PyBullet, OMPL's Python modules and plannerlab's planners, task runner and
  simulator) and then forks one child
  per trial. Importing creates no OMPL object, so each child still seeds OMPL's
  process-global generator before any OMPL object exists
  (:func:`plannerlab.comparison.trial.run_trial` does so first), and a trial's result does
  not depend on which child ran it or on ``jobs``. The child skips the 0.6–0.7 s of
  imports a spawned interpreter pays. ``start_method="spawn"`` keeps the old behaviour.
* **The caller's script is not run again.** multiprocessing starts a child by re-importing
  the parent's ``__main__`` module (a user's script, as ``__mp_main__``), which re-runs a
  script that is not guarded by ``if __name__ == "__main__":``: its own solves, and its
  comparison, whose trials then die in their bootstrapping. A trial's process needs
  nothing of ``__main__`` (its target, its trial and its runner are plannerlab's), so the
  parent's ``__main__`` is left out of the launch (:func:`_main_module_left_out`): a script
  that calls :func:`plannerlab.compare` at its top level works as written.
* **A trial is a process**: a child that dies (a segfault in a native library) is an
  ``error`` for that trial only; a child that overruns its time limit is killed
  (SIGTERM, then SIGKILL) by :meth:`LocalBackend.kill`. Children ignore SIGINT: the
  parent decides, and on Ctrl-C it kills the children it started.
* **Output.** A child's file descriptors 1 and 2 go to a file in the store's
  ``.running/`` folder, whose tail is kept in the record; native libraries' prints
  cannot garble the parent's progress display.
* **Start-up** is measured in the child: ``startup_s`` in the record is the time from
  the parent's launch of the trial to the child being ready to load the problem, with
  plannerlab's trial modules imported.
"""

from __future__ import annotations

import contextlib
import hashlib
import multiprocessing
import os
import signal
import sys
import time
import types
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from multiprocessing.connection import Connection, wait
from pathlib import Path
from typing import Any

from plannerlab.errors import PlannerlabError
from plannerlab.record.trial import TrialRecord

#: modules the fork server imports before forking trials (no OMPL object is created)
PRELOAD_MODULES: tuple[str, ...] = (
    "numpy",
    "scipy.spatial.transform",
    "plannerlab.run.preload",  # the rooms a trial walks through
    "plannerlab.comparison.trial",  # run_trial, what a trial's process calls
    "toppra",  # imported by retiming on first use; itself imports scipy.interpolate
)
#: what a child imports before it is "started" (free when preloaded): plannerlab's
#: trial modules, which import numpy, FCL, PyBullet and OMPL (toppra only when executing)
_TRIAL_MODULES = tuple(m for m in PRELOAD_MODULES if m.startswith("plannerlab."))
START_METHODS = ("forkserver", "spawn")
#: characters of a trial process's captured output kept in its record
OUTPUT_TAIL_CHARS = 2000
#: lines of a trial process's captured output kept in its record (at most
#: :data:`OUTPUT_TAIL_CHARS` characters)
OUTPUT_TAIL_LINES = 20


def _tail(path: Path, chars: int = OUTPUT_TAIL_CHARS, lines: int = OUTPUT_TAIL_LINES) -> str:
    """The last ``lines`` whole lines of a file, at most ``chars`` characters."""
    try:
        with open(path, "rb") as fh:
            size = fh.seek(0, os.SEEK_END)
            fh.seek(max(size - 4 * chars, 0))
            text = fh.read().decode("utf-8", errors="replace")
    except OSError:
        return ""
    kept = text.splitlines()[-lines:]
    while kept and len("\n".join(kept)) > chars:
        kept = kept[1:]
    return "\n".join(kept) if kept else text[-chars:]


def death(exitcode: int | None, output: str) -> dict[str, Any]:
    """Why a trial's process ended without reporting, as a record's fields: ``error`` in
    words, ``exit_code`` or ``signal`` (by name), ``output`` (the end of its stdout and
    stderr)."""
    out: dict[str, Any] = {"output": output}
    if exitcode is not None and exitcode < 0:
        try:
            name = signal.Signals(-exitcode).name
        except ValueError:
            name = f"signal {-exitcode}"
        out["signal"] = name
        how = f"killed by {name}"
    else:
        out["exit_code"] = exitcode
        how = f"exit code {exitcode}"
    last = output.strip().splitlines()[-1] if output.strip() else "nothing on stdout or stderr"
    out["error"] = f"trial process died ({how}) before reporting a result: {last}"
    return out


@contextlib.contextmanager
def _sigint_held() -> Iterator[None]:
    """Block SIGINT while starting a child (or the fork server), so that it starts with
    SIGINT blocked (a terminal's Ctrl-C goes to the whole process group; the parent stops
    the children; a child then ignores it for good). Blocked, not ignored, in the parent:
    a Ctrl-C that arrives meanwhile stays pending and interrupts the parent as soon as the
    child has started, instead of being lost. A no-op outside the main thread."""
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


@contextlib.contextmanager
def _main_module_left_out() -> Iterator[None]:
    """While a trial's process is launched, ``sys.modules["__main__"]`` is a bare module
    (no ``__file__``, no ``__spec__``): multiprocessing's preparation data then names no
    main module, and the child does not run the caller's script again (see the module
    docstring). Restored as soon as the launch returns (it is synchronous)."""
    main = sys.modules.get("__main__")
    sys.modules["__main__"] = types.ModuleType("__main__")
    try:
        yield
    finally:
        if main is not None:
            sys.modules["__main__"] = main


def _start_fork_server() -> None:
    """Start the fork server (once per process) with SIGINT ignored and its output sent
    to /dev/null: its imports print (PyBullet's banner goes to the C-level stdout), and
    it must not write into the parent's terminal or ``--json`` output."""
    from multiprocessing import forkserver

    sys.stdout.flush()
    sys.stderr.flush()
    saved = (os.dup(1), os.dup(2))
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 1)
        os.dup2(null, 2)
        with _sigint_held():
            forkserver.ensure_running()
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in (*saved, null):
            os.close(fd)


def _import_trial_modules() -> None:
    import importlib

    for name in _TRIAL_MODULES:
        with contextlib.suppress(ImportError):
            importlib.import_module(name)


def _child_main(
    trial: Any,
    conn: Connection,
    out_path: str,
    launched_at: float,
    run: Callable[[Any], TrialRecord],
) -> None:
    """Entry point of a trial's process: ``run(trial)`` and send the record to the parent."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent handles Ctrl-C
    fd = os.open(out_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
    os.dup2(fd, 1)
    os.dup2(fd, 2)
    os.close(fd)
    try:
        _import_trial_modules()
        startup_s = time.time() - launched_at
        rec = run(trial)
        sys.stdout.flush()
        sys.stderr.flush()
        conn.send(rec.replace(startup_s=startup_s, output=_tail(Path(out_path))))
    finally:
        conn.close()


@dataclass
class _Running:
    trial: Any
    proc: Any
    conn: Connection
    out: Path


class LocalBackend:
    """Trials as processes on this machine (see the module docstring).

    Args:
        work_dir: folder for the children's captured output (created; emptied of stale
            files; removed by :meth:`close` when empty).
        run: what a trial's process calls with the trial, returning its record
            (:func:`plannerlab.comparison.trial.run_trial`; passed in, pickled by reference,
            so that this module does not import the runner that imports it).
        start_method: ``"forkserver"`` (default) or ``"spawn"``.
    """

    name = "local"

    def __init__(
        self,
        work_dir: str | Path,
        run: Callable[[Any], TrialRecord],
        start_method: str = "forkserver",
    ) -> None:
        self._run = run
        if start_method not in START_METHODS:
            raise PlannerlabError(
                f"start_method: expected one of {', '.join(START_METHODS)}, got {start_method!r}"
            )
        self.start_method = start_method
        self._ctx: Any = multiprocessing.get_context(start_method)
        if start_method == "forkserver":
            self._ctx.set_forkserver_preload(list(PRELOAD_MODULES))
            _start_fork_server()
        self.work_dir = Path(work_dir)
        self.work_dir.mkdir(parents=True, exist_ok=True)
        for stale in self.work_dir.glob("*.out"):  # left by a run that was killed
            stale.unlink(missing_ok=True)
        self._running: dict[Connection, _Running] = {}

    def start(self, trial: Any) -> Connection:
        """Launch a trial; returns its handle."""
        recv, send = self._ctx.Pipe(duplex=False)
        out = self.work_dir / (hashlib.sha256(trial.key.encode()).hexdigest()[:16] + ".out")
        proc = self._ctx.Process(
            target=_child_main,
            args=(trial, send, str(out), time.time(), self._run),
            name=f"trial {trial.key}",
            daemon=True,
        )
        self._running[recv] = _Running(trial, proc, recv, out)  # before start: cleanup
        with _sigint_held(), _main_module_left_out():  # SIGINT: the parent's to handle
            proc.start()
        send.close()  # the child holds the only write end now
        return recv

    def wait(
        self, handles: list[Any], timeout_s: float
    ) -> list[tuple[Any, TrialRecord | None, dict[str, Any]]]:
        """Handles that finished within ``timeout_s``: ``(handle, record or None, why)``
        (None when the process died before reporting; ``why`` then says how, as the
        record's fields: :func:`death`)."""
        done = []
        for conn in wait(handles, timeout=timeout_s):
            run = self._running.pop(conn)  # type: ignore[call-overload]
            try:
                rec = run.conn.recv()
            except (EOFError, OSError):
                rec = None
            run.conn.close()
            run.proc.join(timeout=30)
            why: dict[str, Any] = {}
            if rec is None:
                why = death(run.proc.exitcode, _tail(run.out))
            run.out.unlink(missing_ok=True)
            done.append((conn, rec, why))
        return done

    def kill(self, handle: Any) -> None:
        """Stop a running trial (SIGTERM, then SIGKILL) and forget it."""
        run = self._running.pop(handle, None)
        if run is None:
            return
        if run.proc.pid is not None:
            run.proc.terminate()
            run.proc.join(timeout=5)
            if run.proc.is_alive():
                run.proc.kill()
                run.proc.join(timeout=5)
        run.conn.close()
        run.out.unlink(missing_ok=True)

    def salvage(self) -> list[TrialRecord]:
        """Stop the running children and return the records they had already sent
        (after an interrupt)."""
        for run in self._running.values():
            if run.proc.pid is not None:
                run.proc.terminate()
        for run in self._running.values():
            if run.proc.pid is not None:
                run.proc.join(timeout=10)
        out = []
        for conn in list(self._running):
            with contextlib.suppress(Exception):
                if conn.poll(0):
                    rec = conn.recv()
                    if isinstance(rec, TrialRecord):
                        out.append(rec)
        return out

    def close(self) -> None:
        """Kill whatever still runs; remove the work folder when empty."""
        for handle in list(self._running):
            self.kill(handle)
        with contextlib.suppress(OSError):
            self.work_dir.rmdir()


__all__ = ["PRELOAD_MODULES", "START_METHODS", "LocalBackend", "death"]
