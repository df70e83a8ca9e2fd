"""drakecreep.processes: pools whose workers stop with a Ctrl-C or an error of the parent, at once."""

import os
import signal
import time

import pytest

from drakecreep.processes import pool_size, process_pool, usable_cpus


def _ended(workers, timeout=10.0):
    """Whether every worker process has ended within ``timeout`` s. A terminated process closes its sentinel a moment
    before it can be reaped, so ``join`` may return while ``is_alive`` still says yes (a fresh clone's CI saw it)."""
    deadline = time.monotonic() + timeout
    while any(p.is_alive() for p in workers) and time.monotonic() < deadline:
        time.sleep(0.01)
    return not any(p.is_alive() for p in workers)


def test_a_sigint_to_the_parent_alone_ends_a_pool_that_is_working():
    """The hang ``drakecreep diagnose`` had (session 59): a SIGINT to the parent alone (``kill -INT``, ``timeout -s
    INT``) while a worker was busy left the executor waiting for ever on a worker that never got its stop sentinel.
    Now the interrupt goes on at once and the workers are gone."""
    # Python's own handler, whatever the test runner left (a pytest-xdist worker of the whole suite may ignore SIGINT)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    start = time.perf_counter()
    try:
        with pytest.raises(KeyboardInterrupt):
            with process_pool(1) as pool:
                pool.submit(time.sleep, 60.0)
                while not pool._processes:  # the worker has started
                    time.sleep(0.05)
                workers = list(pool._processes.values())
                time.sleep(1.0)  # it is in the task
                signal.raise_signal(signal.SIGINT)
    finally:
        signal.signal(signal.SIGINT, previous)
    assert time.perf_counter() - start < 30.0
    assert _ended(workers)


def test_workers_ignore_sigint_and_run_the_initializer(tmp_path):
    """A Ctrl-C in a terminal reaches every process of the group: the workers ignore it (no traceback of theirs),
    the parent alone stops them. The initializer runs in each worker with its arguments."""
    with process_pool(2, os.chdir, (str(tmp_path),)) as pool:
        handler = pool.submit(signal.getsignal, signal.SIGINT).result()
        cwd = pool.submit(os.getcwd).result()
    assert handler == signal.SIG_IGN
    assert os.path.samefile(cwd, tmp_path)


def test_an_error_in_the_block_stops_the_workers_and_goes_on():
    with pytest.raises(ValueError, match="stop"):
        with process_pool(1) as pool:
            pool.submit(time.sleep, 60.0)
            while not pool._processes:
                time.sleep(0.05)
            workers = list(pool._processes.values())
            raise ValueError("stop")
    assert _ended(workers)


def test_a_pool_never_starts_more_processes_than_the_cpus_it_may_use():
    """``--workers 256`` on two cores started 256 interpreters, each with its own Drake, and ran the machine out of
    memory: the work is CPU-bound, so a pool is no larger than the CPUs this process may use."""
    cpus = usable_cpus()
    assert 1 <= cpus <= (os.cpu_count() or cpus)
    assert pool_size(1) == 1
    assert pool_size(cpus + 5) == cpus
    with process_pool(cpus + 5) as pool:
        futures = [pool.submit(time.sleep, 0.5) for _ in range(cpus + 5)]
        for future in futures:
            future.result()
        pids = {proc.pid for proc in pool._processes.values()}
    assert 1 <= len(pids) <= cpus
