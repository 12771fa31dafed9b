"""The sweep engine (issue 6 item 4): the same coarse gait OCPs solved serially, on a
LocalCluster and on a separately started ``dask scheduler`` + ``dask worker`` processes
give bitwise-identical solutions; failures (an exception, a non-success IPOPT status) are
reported with their status, in place, never dropped; the cache root reaches the workers
explicitly."""

from __future__ import annotations

import math
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from gaitlib import sweep as sw
from gaitlib.problems import gait as gait_ocp

COARSE = dict(model="SK", cost="DT", n_intervals=8, degree=3)
SPECS = {
    "SK_DT_Slow": gait_ocp.GaitSpec(**COARSE, speed_class="Slow"),
    "SK_DT_Fast": gait_ocp.GaitSpec(**COARSE, speed_class="Fast"),
    # stopped after 3 iterations: a run that does not converge, to be reported as such
    "SK_DT_Free_3it": gait_ocp.GaitSpec(**COARSE, speed_class="Free", max_iter=3),
}
pytestmark = pytest.mark.filterwarnings("ignore::gaitlib.ocp.SolveFailedWarning")  # the 3-iteration run
FRAMES = ("q", "qd", "torques", "torques_active", "residuals", "grf", "ellipsoids")


def _bitwise_equal(a: gait_ocp.GaitSolution, b: gait_ocp.GaitSolution) -> None:
    assert a.stats["objective"] == b.stats["objective"]
    assert a.stats["status"] == b.stats["status"] and a.stats["iterations"] == b.stats["iterations"]
    for f in FRAMES:
        fa, fb = getattr(a, f), getattr(b, f)
        if fa is None:
            assert fb is None
            continue
        assert list(fa.columns) == list(fb.columns), f
        assert fa.to_numpy().tobytes() == fb.to_numpy().tobytes(), f
    for name, ph in a.solution.phases.items():
        pb = b.solution.phases[name]
        for part in ("states", "controls"):
            assert getattr(ph, part).to_numpy().tobytes() == getattr(pb, part).to_numpy().tobytes(), (name, part)
    assert a.solution.parameters == b.solution.parameters


def _check_records(recs: dict, root: Path) -> None:
    assert list(recs) == list(SPECS)  # every run, in the items' order
    for name in ("SK_DT_Slow", "SK_DT_Fast"):
        r = recs[name]
        assert r.ok and r.status == "Solve_Succeeded" and r.error is None, (name, r.status, r.error)
        assert r.value.stats["iterations"] > 0 and r.wall_s > 0
    bad = recs["SK_DT_Free_3it"]
    assert not bad.ok and bad.status == "Maximum_Iterations_Exceeded"
    assert bad.value is not None and bad.value.stats["iterations"] == 3
    # each new solution was stored under the root given (not the workers' environment)
    assert len(list((root / "gait").iterdir())) == len(SPECS)


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    root = tmp_path_factory.mktemp("serial_cache")
    recs = gait_ocp.solve_specs(SPECS, cache_root=root, serial=True, progress=False)
    _check_records(recs, root)
    assert all(r.worker.startswith("serial:") for r in recs.values())
    return recs


def test_localcluster_gives_bitwise_the_serial_results(serial, tmp_path, capfd):
    root = tmp_path / "cache"
    recs = gait_ocp.solve_specs(SPECS, cache_root=root, n_workers=2)
    _check_records(recs, root)
    assert all(r.worker.startswith("tcp://") for r in recs.values())
    for name in SPECS:
        _bitwise_equal(serial[name].value, recs[name].value)
    err = capfd.readouterr().err  # progress: one line per finished run, failures flagged
    lines = [ln for ln in err.splitlines() if ln.startswith("[")]
    assert "LocalCluster(2 workers" in err and len(lines) == len(SPECS)
    assert [ln.split()[1] for ln in lines if ln.endswith("FAILED")] == ["SK_DT_Free_3it"]
    # a second sweep of the same runs reloads them in this process: no cluster, same results
    again = gait_ocp.solve_specs(SPECS, cache_root=root, n_workers=2)
    assert "LocalCluster" not in capfd.readouterr().err
    assert all(r.worker.startswith("cache:") for r in again.values())
    assert [(r.name, r.ok, r.status) for r in again.values()] == [(r.name, r.ok, r.status) for r in recs.values()]
    for name in SPECS:
        _bitwise_equal(recs[name].value, again[name].value)


def test_localcluster_workers_are_single_threaded():
    recs = sw.sweep(os.getenv, {v: v for v in sw.BLAS_ENV}, n_workers=1, progress=False)
    assert [(r.name, r.value) for r in recs] == [(v, os.environ.get(v, sw.blas.SETTINGS[v])) for v in sw.BLAS_ENV]


def test_an_exception_is_a_failed_record_not_a_crash():
    recs = sw.sweep(math.sqrt, [("four", 4.0), ("minus_one", -1.0), ("nine", 9.0)], serial=True, progress=False)
    assert [r.name for r in recs] == ["four", "minus_one", "nine"]
    assert [r.value for r in recs] == [2.0, None, 3.0] and [r.ok for r in recs] == [True, False, True]
    assert recs[1].status == "error" and "ValueError: math domain error" in recs[1].error
    with pytest.raises(ValueError, match="duplicate run names"):
        sw.sweep(math.sqrt, [("a", 1.0), ("a", 2.0)], serial=True)


@pytest.fixture(scope="module")
def dask_cluster(tmp_path_factory):
    """``dask scheduler`` and two ``dask worker`` processes started here; the workers'
    ``GAITLIB_SOLUTIONS`` points to a decoy that must stay empty."""
    from distributed import Client

    tmp = tmp_path_factory.mktemp("dask")
    sched_file, decoy = tmp / "scheduler.json", tmp / "decoy_cache"
    dask_bin = str(Path(sys.executable).parent / "dask")
    env = {**os.environ, "GAITLIB_SOLUTIONS": str(decoy),
           **sw.blas.SETTINGS}
    procs = []
    try:
        procs.append(subprocess.Popen([dask_bin, "scheduler", "--scheduler-file", str(sched_file), "--port", "0",
                                       "--host", "127.0.0.1", "--no-dashboard"], env=env, cwd=tmp,
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        t0 = time.monotonic()
        while not sched_file.exists():
            assert time.monotonic() - t0 < 60, "dask scheduler did not start"
            assert procs[0].poll() is None, "dask scheduler exited"
            time.sleep(0.2)
        for i in range(2):
            procs.append(subprocess.Popen([dask_bin, "worker", "--scheduler-file", str(sched_file), "--nthreads", "1",
                                           "--name", f"w{i}", "--no-dashboard", "--local-directory", str(tmp / f"w{i}")],
                                          env=env, cwd=tmp, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        with Client(scheduler_file=str(sched_file), timeout=60) as c:
            c.wait_for_workers(2, timeout=90)
            address = c.scheduler.address
        yield address, decoy
    finally:
        for group in (procs[1:], procs[:1]):  # the workers first, then the scheduler
            for p in group:
                p.terminate()
            for p in group:
                try:
                    p.wait(timeout=30)
                except subprocess.TimeoutExpired:
                    p.kill()
                    p.wait()


def test_existing_cluster_gives_bitwise_the_serial_results(serial, dask_cluster, tmp_path):
    address, decoy = dask_cluster
    root = tmp_path / "cache"
    recs = gait_ocp.solve_specs(SPECS, cache_root=root, scheduler=address)
    _check_records(recs, root)
    assert not decoy.exists() or not any(decoy.rglob("spec.json"))
    for name in SPECS:
        _bitwise_equal(serial[name].value, recs[name].value)
    # the CLI on the same cluster: served from the cache the first sweep filled (the
    # failure included), one row per run in sweep.csv, exit code 2 because one run failed
    import pandas as pd

    from gaitlib import cli

    out = tmp_path / "out"
    rc = cli.main(["sweep", "--model", "SK", "--costs", "DT", "--speeds", "Slow,Fast", "--intervals", "8",
                   "--degree", "3", "--scheduler", address, "--cache", str(root), "--no-figures", "--out", str(out)])
    table = pd.read_csv(out / "sweep.csv")
    assert rc == 0 and list(table["name"]) == ["SK_DT_Slow", "SK_DT_Fast"]
    assert table["from_cache"].all() and table["ok"].all()
    assert list(table["objective"]) == pytest.approx([recs[n].value.stats["objective"] for n in table["name"]],
                                                     rel=1e-12)
    assert (out / "SK_DT_Slow" / "summary.json").exists()
    rc = cli.main(["sweep", "--model", "SK", "--costs", "DT", "--speeds", "Free", "--intervals", "8", "--degree", "3",
                   "--max-iter", "3", "--scheduler", address, "--cache", str(root), "--no-figures", "--out", str(out),
                   "--overwrite"])
    table = pd.read_csv(out / "sweep.csv")
    assert rc == 2 and list(table["status"]) == ["Maximum_Iterations_Exceeded"] and not table["ok"].any()
    # an exception on a remote worker is reported too; the cluster stays up for the next call
    gen = sw.sweep(math.sqrt, {"ok": 16.0, "bad": -1.0}, scheduler=address, progress=False)
    assert [(r.name, r.ok, r.status, r.value) for r in gen] == [("ok", True, "done", 4.0), ("bad", False, "error", None)]
    assert "math domain error" in gen[1].error
    gen2 = sw.sweep(math.sqrt, {"x": 25.0}, scheduler=address, progress=False)
    assert gen2[0].value == 5.0


def test_dask_scheduler_address_setting_sends_sweeps_to_that_cluster(dask_cluster, monkeypatch):
    """With dask's own ``DASK_SCHEDULER_ADDRESS`` setting (here through dask's config, as the
    environment variable sets it), a sweep without ``scheduler=`` runs on that cluster — its
    workers are the fixture's ``w0``/``w1`` processes, not a LocalCluster's — and
    :func:`sweep.local_cluster` yields that address without starting a cluster."""
    import dask
    from distributed import Client

    address, _ = dask_cluster
    with Client(address) as c:
        workers = set(c.scheduler_info()["workers"])
    with dask.config.set({"scheduler-address": address}):
        recs = sw.sweep(math.sqrt, {"a": 9.0, "b": 4.0}, progress=False)
        with sw.local_cluster() as sched:
            assert sched == address
    assert [r.value for r in recs] == [3.0, 2.0]
    assert {r.worker for r in recs} <= workers
    with sw.local_cluster(serial=True) as sched:
        assert sched is None


def _needs_a_solve(x):
    from gaitlib import cache

    raise cache.NotCached(f"entry {x}: not cached or stored (test)")


def test_a_missing_solution_is_not_a_failed_run():
    """Inside cache.only a run that would have to solve raises NotCached in the caller (a
    missing stored solution must not be reported as a failed run); other errors stay records."""
    from gaitlib import cache

    with pytest.raises(cache.NotCached, match="1 of 2 runs need a solve"):
        sw.sweep(lambda x: _needs_a_solve(x) if x == 1 else x, {"a": 1, "b": 2}, serial=True, progress=False)
    recs = sw.sweep(math.sqrt, {"ok": 4.0, "bad": -1.0}, serial=True, progress=False)
    assert [r.ok for r in recs] == [True, False]
