"""The Dask side of a study: a client on a LocalCluster or on a scheduler given by address, started
only when a point has to run, and batches of points run on it with a progress line.

Engines:

- ``local`` (default): ``distributed.LocalCluster`` of N worker *processes* (spawned by Dask's nanny,
  never forked) with one thread each and :data:`~rftstatic.study.worker.THREAD_VARIABLES` set to 1 in
  their environment, so that N workers use N cores; no dashboard, no set-up;
- ``scheduler``: ``--scheduler tcp://HOST:PORT``, any running Dask scheduler (``dask scheduler`` and
  ``dask worker ADDRESS --nthreads 1``, or a deployment of dask-jobqueue, dask-kubernetes, ...). The
  connection gives up after :data:`CONNECT_TIMEOUT_S`, the wait for workers after
  :data:`WORKER_TIMEOUT_S`: a wrong address is an input error (exit 2), never a hang. The workers
  write into the study folder, which they must share with the driver (one machine, or a shared file
  system); the rows come back to the driver through Dask.

A point that raises on its worker is a failed row (:func:`~rftstatic.study.worker.run_point` catches
everything); a worker that dies under a point (Dask retries it on another worker, 3 times by default)
gives a failed row with Dask's error. With a ``timeout`` (``--timeout SECONDS``), a point still running
that long after it started (its ``points/KEY.started`` file appeared; time queued does not count) is a
failed row ``timed out after N s``: its task is cancelled and its worker restarted by its nanny (a
process stuck in compiled code is killed), so the study goes on. Dask cannot stop one task of a running
process otherwise; a worker without a nanny (``dask worker --no-nanny``) cannot be restarted (the row's
error says so) and may go on running the point.
"""

from __future__ import annotations

import logging
import os
import sys
import time
from dataclasses import dataclass

from rftstatic.study.space import StudyError
from rftstatic.study.worker import started_marker

CONNECT_TIMEOUT_S = 10.0
"""Longest wait for a scheduler to answer [s]."""
WORKER_TIMEOUT_S = 60.0
"""Longest wait for the first worker to join a scheduler [s]."""
POLL_S = 0.25
"""With a point timeout: how often the driver looks for started and overdue points [s]."""
RESTART_TIMEOUT_S = 60.0
"""Longest wait for a nanny to restart a worker whose point timed out [s]."""


def _dask_level() -> int:
    """Dask's log level: WARNING, or INFO when rftstatic logs at INFO (``-v``)."""
    return logging.INFO if logging.getLogger().getEffectiveLevel() <= logging.INFO else logging.WARNING


def _quiet() -> None:
    """Dask's INFO lines (workers joining, connections) only with ``-v``."""
    logging.getLogger("distributed").setLevel(_dask_level())


MALLOC_TRIM = "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_"
"""Dask's nanny starts its workers with ``MALLOC_TRIM_THRESHOLD_=65536``, which also turns off glibc's
dynamic mmap threshold, so every array above 128 kB is a fresh mmap whose pages fault in again: the
strip at 51 x 11 solved 35 % slower with it (6 points, 4.0-4.1 s against 5.4-5.7 s, in-process). The
LocalCluster's workers start without it (this key set to None); ``dask worker`` processes of an
external cluster get it unless their configuration unsets it (docs/howto/studies.md)."""


@dataclass(frozen=True)
class Execution:
    """Where and how the points of a study run: the ``--scheduler``, ``--workers``, ``--timeout`` and
    ``--figures`` options that ``sweep`` and ``fit`` share.

    Attributes
    ----------
    scheduler : address of a running Dask scheduler (``tcp://HOST:PORT``), or None for a LocalCluster
    workers : LocalCluster: its worker processes (None: the cores); with a scheduler: how many to wait for
    timeout : longest run of one point [s] (None: no limit; module docstring)
    figures : each point writes its PNG views (off: faster)
    """

    scheduler: str | None = None
    workers: int | None = None
    timeout: float | None = None
    figures: bool = False

    def engine(self) -> Engine:
        """The :class:`Engine` that runs the points (its cluster starts on first use)."""
        return Engine(self.scheduler, self.workers, timeout=self.timeout)


class StudyProgress:
    """``label: D/N done, R running, F failed, T s`` on stderr: redrawn on a terminal, else a line at
    every tenth of the way (a batch of at most 3 points, or any batch when ``brief``: at its end only).
    R: the points on workers, min(workers, points not done), as each worker runs one point at a time."""

    def __init__(self, total: int, label: str, workers: int, stream=None, brief: bool = False):
        self.total, self.label, self.workers, self.brief = total, label, max(1, workers), brief
        self.stream = stream or sys.stderr
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.done = self.failed = 0
        self._t0 = time.perf_counter()
        self._next = 0.1

    def line(self) -> str:
        running = min(self.workers, self.total - self.done)
        return (f"{self.label}: {self.done}/{self.total} done, {running} running, {self.failed} failed, "
                f"{time.perf_counter() - self._t0:.1f} s")

    def update(self, row: dict) -> None:
        self.done += 1
        self.failed += row.get("status") == "failed"
        if self.tty:
            self.stream.write("\r" + self.line() + " " * 8)
            self.stream.flush()
        elif self.done == self.total or (self.total > 3 and not self.brief and self.done >= self._next * self.total):
            print(self.line(), file=self.stream, flush=True)
            while self._next * self.total <= self.done:
                self._next += 0.1

    def close(self) -> None:
        if self.tty:
            self.stream.write("\n")
            self.stream.flush()


class Engine:
    """A Dask client, created on first use (:meth:`client`), closed by :meth:`close`.

    Parameters
    ----------
    scheduler : address of a running scheduler (``tcp://HOST:PORT``), or None for a LocalCluster
    workers : LocalCluster: its number of worker processes (default: the machine's cores); with a
        scheduler: how many workers to wait for before starting (default 1)
    timeout : longest run of one point [s] (None: no limit; module docstring)
    """

    def __init__(self, scheduler: str | None = None, workers: int | None = None, *,
                 connect_timeout: float | None = None, worker_timeout: float | None = None,
                 timeout: float | None = None):
        if workers is not None and workers < 1:
            raise StudyError(f"--workers {workers}: must be >= 1")
        if timeout is not None and not timeout > 0:
            raise StudyError(f"--timeout {timeout:g}: must be > 0 seconds")
        self.scheduler, self.workers, self.timeout = scheduler, workers, timeout
        self.connect_timeout = CONNECT_TIMEOUT_S if connect_timeout is None else connect_timeout
        self.worker_timeout = WORKER_TIMEOUT_S if worker_timeout is None else worker_timeout
        self._client = self._cluster = None

    @property
    def started(self) -> bool:
        return self._client is not None

    def client(self):
        if self._client is None:
            self._client = self._connect() if self.scheduler else self._local()
            info = self.info()
            print(f"Dask {info['engine']} scheduler {info['address']}, {len(info['workers'])} workers",
                  flush=True)
        return self._client

    def _local(self):
        from distributed import Client, LocalCluster

        from rftstatic.study.worker import worker_environment

        import dask

        n = self.workers or os.cpu_count() or 1
        _quiet()
        env = {**worker_environment(), "DASK_LOGGING__DISTRIBUTED": logging.getLevelName(_dask_level()).lower()}
        with dask.config.set({MALLOC_TRIM: None}):  # read when each nanny is made
            self._cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                                         scheduler_kwargs={"dashboard": False}, silence_logs=_dask_level(), env=env)
        return Client(self._cluster)

    def _connect(self):
        from distributed import Client

        address = self.scheduler
        _quiet()
        try:
            client = Client(address, timeout=self.connect_timeout)
        except (OSError, TimeoutError, ValueError, TypeError) as exc:
            raise StudyError(f"--scheduler {address}: no Dask scheduler answered within {self.connect_timeout:g} s "
                             f"({type(exc).__name__}: {' '.join(str(exc).split())[:160]}); start one with "
                             "`dask scheduler` and give the address it prints") from None
        try:
            client.wait_for_workers(self.workers or 1, timeout=self.worker_timeout)
        except TimeoutError:
            client.close()
            raise StudyError(f"--scheduler {address}: fewer than {self.workers or 1} workers joined within "
                             f"{self.worker_timeout:g} s; start them with `dask worker {address} --nthreads 1`") \
                from None
        return client

    def info(self) -> dict:
        """``engine`` (local / scheduler / none), scheduler ``address`` and ``workers`` (address -> threads)."""
        if self._client is None:
            return {"engine": "none", "address": None, "workers": {}}
        sinfo = self._client.scheduler_info()
        workers = {a: w.get("nthreads") for a, w in sinfo.get("workers", {}).items()}
        return {"engine": "scheduler" if self.scheduler else "local", "address": sinfo.get("address"),
                "workers": workers}

    def run(self, specs: list[dict], on_row, *, label: str = "points", brief: bool = False) -> list[dict]:
        """Run ``specs`` (:func:`~rftstatic.study.worker.run_point`); call ``on_row(row)`` as each finishes
        (in completion order); return the rows in the order of ``specs``. ``brief``: off a terminal, one
        progress line at the end (a fit's batches, many and short)."""
        if not specs:
            return []
        from distributed import as_completed

        from rftstatic.study.worker import run_point

        client = self.client()
        progress = StudyProgress(len(specs), label, len(self.info()["workers"]), brief=brief)
        if self.timeout is not None:
            for spec in specs:  # a marker left by a killed driver's attempt would start the clock too early
                _remove(started_marker(spec["folder"]))
        futures = {client.submit(run_point, spec, key=f"rftstatic-point-{spec['key']}", pure=False): spec
                   for spec in specs}
        rows = {}

        def finish(row):
            rows[row["key"]] = row
            on_row(row)
            progress.update(row)

        try:
            if self.timeout is None:
                for future in as_completed(futures):
                    finish(_result(future, futures[future]))
            else:
                self._watch(client, futures, finish)
        finally:
            progress.close()
            for future in futures:
                if not future.done():
                    future.cancel()
        return [rows[spec["key"]] for spec in specs]

    def _watch(self, client, futures: dict, finish) -> None:
        """:meth:`run` with a point timeout: wait for the futures, every :data:`POLL_S` noting which points
        started (their marker file) and stopping those running longer than ``timeout``."""
        from distributed import wait

        pending, started = dict(futures), {}
        while pending:
            try:
                wait(list(pending), timeout=POLL_S, return_when="FIRST_COMPLETED")
            except TimeoutError:
                pass
            now = time.monotonic()
            for future, spec in list(pending.items()):
                if future.done():
                    del pending[future]
                    finish(_result(future, spec))
                elif future not in started:
                    if os.path.exists(started_marker(spec["folder"])):
                        started[future] = now
                elif now - started[future] > self.timeout:
                    del pending[future]
                    finish(self._stop(client, future, spec, now - started[future]))

    def _stop(self, client, future, spec: dict, elapsed: float) -> dict:
        """Cancel the overdue point and restart its worker; its failed row."""
        key = future.key
        holders = [w for w, keys in client.processing().items() if key in keys]
        future.cancel()  # first: a restart would otherwise hand the point to another worker
        how = "no worker held it any more"
        if holders:
            try:
                status = client.restart_workers(holders, timeout=RESTART_TIMEOUT_S, raise_for_error=False)
                how = ("its worker was restarted" if set(status.values()) == {"OK"} else
                       f"its worker could not be restarted ({', '.join(map(str, status.values()))}) and may still run it")
            except Exception as exc:  # noqa: BLE001 - e.g. a worker without a nanny
                how = f"its worker could not be restarted ({type(exc).__name__}: {exc}) and may still run it"
        _remove(started_marker(spec["folder"]))
        return {"key": spec["key"], **spec["values"], "status": "failed", "folder": f"points/{spec['key']}",
                "worker": holders[0] if holders else None, "wall_time_s": elapsed,
                "error": f"timed out after {self.timeout:g} s (--timeout; {how})"}

    def close(self) -> None:
        if self._client is not None:
            self._client.close()
        if self._cluster is not None:
            self._cluster.close()
        self._client = self._cluster = None

def _result(future, spec: dict) -> dict:
    """The row a finished future returned, or a failed row with Dask's error (the worker died under it)."""
    try:
        return future.result()
    except Exception as exc:  # noqa: BLE001 - a worker died under the point: a failed row
        return {"key": spec["key"], **spec["values"], "status": "failed", "folder": f"points/{spec['key']}",
                "error": f"{type(exc).__name__}: {' '.join(str(exc).split())[:400]}"}


def _remove(path: str) -> None:
    try:
        os.remove(path)
    except FileNotFoundError:
        pass
