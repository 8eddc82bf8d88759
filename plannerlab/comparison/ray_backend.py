"""The Ray trial backend: each trial a Ray task in a fresh worker process.

``plannerlab compare … --backend ray [--address ADDR]`` hands every trial to Ray. The
task is declared with ``max_calls=1``: Ray starts a new worker process for it and ends
the process after it, so OMPL's process-global seed is set (first thing in
:func:`plannerlab.comparison.trial.run_trial`) before any OMPL object exists, exactly as in
the local backend, and the same seeds give the same table. Everything else (the store,
resuming, the per-trial time limit, the progress display, the reports) belongs to
:func:`plannerlab.comparison.runner.run_comparison` and does not depend on the backend.

Decisions:

* **Connecting.** ``address=None`` uses the Ray instance this process already joined,
  else joins a running local one (``ray start --head``) or starts a private one for
  this comparison (``ray.init`` without a dashboard), which :meth:`RayBackend.close`
  shuts down again. An address (``HOST:6379``, ``ray://HOST:10001``, or ``auto``) joins
  that cluster; every node needs plannerlab installed (``pip install .[ray]``) and the
  problem files at the same path.
* **Killing.** A trial past its time limit is cancelled with ``ray.cancel(force=True)``,
  which kills its worker process.
* **Output.** Workers' output stays in Ray's logs (``log_to_driver=False``), so it cannot
  garble the progress display.
* Ray is an optional dependency (``pip install .[ray]``); it is imported only here.
"""

from __future__ import annotations

import time
import traceback
from collections.abc import Callable
from typing import Any

from plannerlab.errors import PlannerlabError
from plannerlab.record.trial import TrialRecord


def _ray_trial(trial: Any, launched_at: float, run: Callable[[Any], TrialRecord]) -> TrialRecord:
    """The Ray task: ``run(trial)`` in this (fresh) worker process."""
    from plannerlab.comparison.local import _import_trial_modules

    _import_trial_modules()
    startup_s = time.time() - launched_at
    return run(trial).replace(startup_s=startup_s)


class RayBackend:
    """Trials as Ray tasks (see the module docstring).

    Args:
        run: what a task calls with the trial (:func:`plannerlab.comparison.trial.run_trial`,
            passed in so that this module does not import the runner that imports it).
        address: a Ray cluster's address, or None for a local instance.
        num_cpus: CPUs of a private local instance (None: Ray's default, all of them).

    Raises:
        PlannerlabError: Ray is not installed, or the cluster cannot be reached.
    """

    name = "ray"

    def __init__(
        self,
        run: Callable[[Any], TrialRecord],
        address: str | None = None,
        num_cpus: int | None = None,
    ) -> None:
        self._run = run
        try:
            import ray
        except ImportError:
            raise PlannerlabError(
                "--backend ray needs Ray: pip install 'plannerlab[ray]' (or pip install ray)"
            ) from None
        self._ray = ray
        self._owned = False
        if not ray.is_initialized():
            kwargs: dict[str, Any] = {"log_to_driver": False, "include_dashboard": False}
            if num_cpus is not None and address is None:
                kwargs["num_cpus"] = int(num_cpus)
            try:
                ray.init(address=address, **kwargs)
            except Exception as exc:  # ConnectionError, ValueError, RuntimeError...
                last = traceback.format_exception_only(type(exc), exc)[-1].strip()
                where = f"the Ray cluster at {address}" if address else "a local Ray instance"
                raise PlannerlabError(
                    f"--backend ray: cannot start or join {where}: {last}"
                ) from None
            self._owned = True
        self._task = ray.remote(max_calls=1, num_cpus=1, max_retries=0)(_ray_trial)
        self._trials: dict[Any, Any] = {}

    def start(self, trial: Any) -> Any:
        """Submit a trial; returns its handle (an object reference)."""
        ref = self._task.remote(trial, time.time(), self._run)
        self._trials[ref] = trial
        return ref

    def wait(
        self, handles: list[Any], timeout_s: float
    ) -> list[tuple[Any, TrialRecord | None, dict[str, Any]]]:
        """Handles that finished within ``timeout_s``: ``(handle, record or None, why)``
        (``why``: the fields of a died trial's record)."""
        ray = self._ray
        if not handles:
            return []
        ready, _ = ray.wait(handles, num_returns=len(handles), timeout=timeout_s)
        done: list[tuple[Any, TrialRecord | None, dict[str, Any]]] = []
        for ref in ready:
            self._trials.pop(ref, None)
            try:
                done.append((ref, ray.get(ref), {}))
            except Exception as exc:  # the worker died, or the task could not run
                last = traceback.format_exception_only(type(exc), exc)[-1].strip()
                done.append((ref, None, {"error": f"Ray task failed: {last}"}))
        return done

    def kill(self, handle: Any) -> None:
        """Cancel a running trial, killing its worker process."""
        if self._trials.pop(handle, None) is not None:
            self._ray.cancel(handle, force=True)

    def salvage(self) -> list[TrialRecord]:
        """Records of tasks that already finished; the others are cancelled."""
        out = []
        handles = list(self._trials)
        if handles:
            ready, _ = self._ray.wait(handles, num_returns=len(handles), timeout=0)
            for ref in ready:
                self._trials.pop(ref, None)
                try:
                    out.append(self._ray.get(ref))
                except Exception:  # a failed task has nothing to salvage
                    continue
        for ref in list(self._trials):
            self.kill(ref)
        return out

    def close(self) -> None:
        """Cancel what still runs; shut down a Ray instance this backend started."""
        for ref in list(self._trials):
            self.kill(ref)
        if self._owned:
            self._ray.shutdown()
            self._owned = False


__all__ = ["RayBackend"]
