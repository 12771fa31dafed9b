"""Sweeps of independent runs (e.g. the Ch 6 cost functions × Ch 7 speed classes) on
dask.distributed, or serially in-process: a pure executor that knows nothing of the
problems it runs (the gait problem's batch solve is :func:`gaitlib.problems.gait.solve_specs`).

:func:`sweep` runs ``func(arg)`` for every named item; one :class:`RunRecord` per item, in
the items' order, failures included (never dropped, never raised).

Where the runs go
-----------------
* default: a :class:`distributed.LocalCluster` with ``n_workers`` (default
  ``os.cpu_count()``) worker *processes* of one thread each, and one BLAS/OpenMP thread
  per process (:data:`gaitlib.blas.SETTINGS`, set for the workers before they are spawned —
  IPOPT/MUMPS takes timing-dependent paths with more threads); the cluster is closed afterwards.
* ``scheduler="tcp://host:port"`` (or the path of a ``--scheduler-file``): an existing
  cluster, e.g. ``dask scheduler`` + ``dask worker ADDRESS --nthreads 1``; only the client
  is closed afterwards, never the cluster.
* ``serial=True``: a plain loop in this process, no dask (debugging, reference results).

Every run is wrapped on the worker: an exception becomes a record with ``ok=False``,
``status="error"`` and the traceback; a lost worker likewise. A run's ``status`` is the
IPOPT return status when the function returns a solution (an object with
``stats["status"]``, e.g. :class:`~gaitlib.problems.gait.GaitSolution`, or with a
``status`` string, e.g. :class:`~gaitlib.ocp.Solution`); ``ok`` is then True only for
``Solve_Succeeded`` and ``Solved_To_Acceptable_Level``. A mapping of solutions (a group
of solves) has their statuses (one if shared, else their counts), ``ok`` only if every
one is accepted. Any other return value gives ``status="done"``, ``ok=True``.

Results are identical to a serial run: each run is the same deterministic computation in
a fresh single-threaded process (tests/test_sweep.py compares solutions bitwise).
"""

from __future__ import annotations

import os
import socket
import sys
import time
import traceback
import uuid
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from . import blas
from .cache import NotCached

__all__ = ["RunRecord", "sweep", "local_cluster", "ACCEPTED_STATUSES", "BLAS_ENV"]

#: IPOPT return statuses counted as a solved run (``RunRecord.ok``); the status itself is
#: always kept, so an acceptable-level stop stays visible.
ACCEPTED_STATUSES = frozenset({"Solve_Succeeded", "Solved_To_Acceptable_Level"})

#: Thread-count variables set for every worker process (one BLAS/OpenMP thread).
BLAS_ENV = tuple(blas.SETTINGS)  # the variables every worker gets (gaitlib.blas)


@dataclass(frozen=True)
class RunRecord:
    """The outcome of one run of a sweep.

    Attributes
    ----------
    name : the item's name.
    ok : True if the run returned without exception and, for a solution, IPOPT's status is
        in :data:`ACCEPTED_STATUSES`.
    status : IPOPT's ``return_status`` for a solution (for a mapping of solutions their
        statuses, see the module docstring), ``"done"`` for other return values,
        ``"error"`` when the function raised (or its worker died).
    value : the function's return value (``None`` on error).
    error : the traceback text on error, else ``None``.
    wall_s : wall-clock time of the function call on the worker (s).
    worker : the worker that ran it (dask worker address, or ``"serial:<host>:<pid>"``).
    """

    name: str
    ok: bool
    status: str
    value: Any
    error: str | None
    wall_s: float
    worker: str


def _solution_status(value) -> str | None:
    stats = getattr(value, "stats", None)
    status = stats.get("status") if isinstance(stats, Mapping) else None
    if status is None and isinstance(getattr(value, "status", None), str):
        status = value.status
    return None if status is None else str(status)


def _status_of(value) -> tuple[bool, str]:
    """(ok, status) of a run's return value: a solution's IPOPT status; for a mapping of
    solutions (e.g. :func:`gaitlib.gap.solve.solve_many`'s groups) the status they share, or
    their counts (``"2 Solve_Succeeded, 1 Maximum_Iterations_Exceeded"``), ok only if all
    are accepted; anything else ``"done"``."""
    status = _solution_status(value)
    if status is not None:
        return status in ACCEPTED_STATUSES, status
    if isinstance(value, Mapping) and value:
        sts = [_solution_status(v) for v in value.values()]
        if all(s is not None for s in sts):
            counts: dict[str, int] = {}
            for s in sts:
                counts[s] = counts.get(s, 0) + 1
            text = sts[0] if len(counts) == 1 else ", ".join(f"{n} {s}" for s, n in counts.items())
            return all(s in ACCEPTED_STATUSES for s in sts), text
    return True, "done"


def _where() -> str:
    if "distributed" in sys.modules:  # only a dask worker process has it for sure
        try:
            return sys.modules["distributed"].get_worker().address
        except ValueError:  # not on a worker
            pass
    return f"serial:{socket.gethostname()}:{os.getpid()}"


def _run_one(func: Callable, name: str, arg) -> RunRecord:
    """Run ``func(arg)`` and wrap the outcome (executed on the worker)."""
    blas.pin()  # workers of an existing cluster may not have them; casadi loads its OpenBLAS at the first solver
    t0 = time.perf_counter()
    try:
        value = func(arg)
    except BaseException:  # noqa: BLE001 — a run's failure is its result
        return RunRecord(name, False, "error", None, traceback.format_exc(), time.perf_counter() - t0, _where())
    ok, status = _status_of(value)
    return RunRecord(name, ok, status, value, None, time.perf_counter() - t0, _where())


def _normalise_items(items) -> list[tuple[str, Any]]:
    if isinstance(items, Mapping):
        pairs = list(items.items())
    elif isinstance(items, Sequence) and not isinstance(items, (str, bytes)):
        pairs = []
        for i, it in enumerate(items):
            if not (isinstance(it, Sequence) and len(it) == 2):
                raise TypeError(f"items[{i}] must be a (name, arg) pair, got {it!r}")
            pairs.append((it[0], it[1]))
    else:
        raise TypeError(f"items must be a mapping name -> arg or a sequence of (name, arg), got {type(items).__name__}")
    names = [n for n, _ in pairs]
    bad = [n for n in names if not isinstance(n, str)]
    if bad:
        raise TypeError(f"run names must be strings, got {bad[:3]!r}")
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ValueError(f"duplicate run names: {dup}")
    return pairs


class _Progress:
    """One line per finished run on stderr: ``[k/n] name  status  wall  worker``."""

    def __init__(self, total: int, enabled: bool):
        self.total, self.done, self.enabled = total, 0, enabled
        self.t0 = time.perf_counter()
        self.width = 0

    def start(self, names, where: str):
        self.width = max((len(n) for n in names), default=0)
        self._print(f"sweep: {self.total} runs on {where}")

    def __call__(self, rec: RunRecord):
        self.done += 1
        flag = "" if rec.ok else "  FAILED"
        self._print(f"[{self.done:>{len(str(self.total))}}/{self.total}] {rec.name:<{self.width}}  "
                    f"{rec.status:<26} {rec.wall_s:8.1f} s  {rec.worker}{flag}")

    def finish(self, records):
        n_bad = sum(not r.ok for r in records)
        self._print(f"sweep: {len(records) - n_bad}/{len(records)} ok, {n_bad} failed, "
                    f"{time.perf_counter() - self.t0:.1f} s elapsed")

    def _print(self, line: str):
        if self.enabled:
            print(line, file=sys.stderr, flush=True)


def _worker_env() -> dict[str, str]:
    # gaitlib.blas's settings, unless the user set the variables
    return {v: os.environ.get(v, default) for v, default in blas.SETTINGS.items()}


def _refuse_missing(records: list[RunRecord]) -> list[RunRecord]:
    """Raise :class:`gaitlib.cache.NotCached` if a run hit a missing solution inside
    :func:`gaitlib.cache.only` (its worker's error says so); else the records."""
    missing = [r for r in records if r.error and f"{NotCached.__name__}:" in r.error]
    if missing:
        last = missing[0].error.strip().splitlines()[-1]
        raise NotCached(f"{len(missing)} of {len(records)} runs need a solve (first: {missing[0].name}: {last})")
    return records


def _configured_scheduler() -> str | None:
    """dask's own setting of a scheduler address (``DASK_SCHEDULER_ADDRESS`` in the
    environment, or ``scheduler-address`` in a dask config file), or None."""
    import dask

    return dask.config.get("scheduler-address", None) or None


def _start_cluster(n: int):
    """A LocalCluster of ``n`` single-threaded worker processes with gaitlib's BLAS settings."""
    import dask
    from distributed import LocalCluster

    env = _worker_env()
    with dask.config.set({"distributed.nanny.pre-spawn-environ": env}):
        return LocalCluster(n_workers=n, threads_per_worker=1, processes=True, env=env,
                            dashboard_address=None, silence_logs=40)


@contextmanager
def local_cluster(n_workers: int | None = None, *, scheduler: str | None = None,
                  serial: bool = False) -> Iterator[str | None]:
    """One LocalCluster for several :func:`sweep` calls: yields its scheduler address (pass
    it as ``scheduler=``) and closes it afterwards. Starting a cluster costs seconds, which
    several short sweeps (a gap diagnosis's baseline starts and candidates) would otherwise pay
    each. With ``scheduler`` (an existing cluster) or ``serial`` nothing is started and that
    ``scheduler`` is yielded unchanged."""
    scheduler = scheduler or _configured_scheduler()
    if scheduler is not None or serial:
        yield scheduler
        return
    cluster = _start_cluster(int(n_workers or os.cpu_count() or 1))
    try:
        yield cluster.scheduler_address
    finally:
        cluster.close()


def sweep(func: Callable[[Any], Any], items, *, scheduler: str | None = None, n_workers: int | None = None,
          serial: bool = False, progress: bool = True) -> list[RunRecord]:
    """Run ``func(arg)`` for every ``(name, arg)`` of ``items``, in parallel on dask.distributed.

    Parameters
    ----------
    func : a picklable, module-level function of one argument (it runs in worker processes;
        a function defined in ``__main__`` or a test module must be importable there).
    items : mapping name → arg, or a sequence of ``(name, arg)`` pairs; names are unique
        strings.
    scheduler : address of an existing dask scheduler (``"tcp://host:port"``) or path of its
        scheduler file; ``None`` (default): dask's configured scheduler address if one is set
        (``DASK_SCHEDULER_ADDRESS``, so a whole book build can run on a cluster started with
        ``dask scheduler`` / ``dask worker``), else start a :class:`distributed.LocalCluster`
        for this sweep and close it afterwards. An existing cluster is never shut down.
    n_workers : LocalCluster worker processes (default ``os.cpu_count()``, at most the
        number of runs); ignored with ``scheduler``.
    serial : run in this process, one after another, without dask.
    progress : print a line per finished run (name, status, wall time, worker, k/n) to
        stderr.

    Returns
    -------
    list of :class:`RunRecord`, in the order of ``items``; a failed run (exception, lost
    worker, non-success IPOPT status) is a record with ``ok=False``, never dropped.

    Raises
    ------
    gaitlib.cache.NotCached
        inside :func:`gaitlib.cache.only`, when a run needed a solve: a solution that is not
        stored is missing, not a failed run, and must not be reported as one.
    """
    pairs = _normalise_items(items)
    prog = _Progress(len(pairs), progress)
    if serial:
        prog.start([n for n, _ in pairs], f"this process (serial, pid {os.getpid()})")
        records = []
        for name, arg in pairs:
            rec = _run_one(func, name, arg)
            prog(rec)
            records.append(rec)
        prog.finish(records)
        return _refuse_missing(records)
    if not pairs:
        return []

    from distributed import Client, as_completed

    cluster = None
    scheduler = scheduler or _configured_scheduler()
    if scheduler is None:
        n = int(n_workers or os.cpu_count() or 1)
        n = max(1, min(n, len(pairs)))
        cluster = _start_cluster(n)
        client = Client(cluster)
        where = f"LocalCluster({n} workers x 1 thread, {cluster.scheduler_address})"
    elif isinstance(scheduler, (str, os.PathLike)) and Path(scheduler).is_file():
        client = Client(scheduler_file=str(scheduler))
        where = f"existing cluster {client.scheduler.address} ({len(client.scheduler_info()['workers'])} workers)"
    else:
        client = Client(scheduler)
        where = f"existing cluster {scheduler} ({len(client.scheduler_info()['workers'])} workers)"
    try:
        prog.start([n for n, _ in pairs], where)
        token = uuid.uuid4().hex[:8]
        futures = {}
        for i, (name, arg) in enumerate(pairs):
            fut = client.submit(_run_one, func, name, arg, key=f"gaitlib-sweep-{token}-{i}", pure=False,
                                priority=len(pairs) - i)  # start in the items' order
            futures[fut.key] = (i, name, fut)
        records: list[RunRecord | None] = [None] * len(pairs)
        for fut in as_completed([f for _, _, f in futures.values()]):
            i, name, _ = futures[fut.key]
            try:
                rec = fut.result()
            except BaseException:  # lost worker, unpicklable result, …: reported, not dropped
                rec = RunRecord(name, False, "error", None, traceback.format_exc(), float("nan"),
                                "unknown (task failed outside the run)")
            records[i] = rec
            prog(rec)
            fut.release()
        prog.finish(records)
        return _refuse_missing(records)  # type: ignore[arg-type]
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
