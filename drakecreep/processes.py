"""Process pools that stop at once: a Ctrl-C, an error, or the death of the parent ends their workers.

Every pool of the package (a sweep's cases, the diagnoses' replays and candidate fits, the compensation study's
simulations) is a ``concurrent.futures.ProcessPoolExecutor`` of ``spawn`` processes (each imports Drake
once). Left to itself such a pool does not stop well:

* a ``SIGINT`` sent to the parent alone (``kill -INT``, ``timeout -s INT``, a job scheduler) interrupts the
  parent while it waits on the pool, and the executor's shutdown can then wait forever on a worker that never
  receives its stop sentinel (measured: ``drakecreep diagnose`` hung 11 minutes, until the worker was killed);
* a Ctrl-C in a terminal reaches every process of the group, and each worker prints its own
  ``KeyboardInterrupt`` traceback;
* a ``SIGKILL`` of the parent leaves the workers running.

:func:`process_pool` makes the workers ignore ``SIGINT`` (the parent alone decides to stop), watch their parent
(they exit when it is gone), and, when the ``with`` block ends by an exception (``KeyboardInterrupt`` included),
cancels the queued work and terminates the running workers before the exception goes on (:func:`stop_pool`).

A pool never has more processes than the CPUs this process may run on (:func:`usable_cpus`): the work is
CPU-bound, so more processes gain nothing, and each holds its own Drake (``--workers 256`` on two cores
started 256 interpreters and ran the machine out of memory).
"""

import concurrent.futures as cf
import contextlib
import multiprocessing
import os
import signal
import threading
import time

__all__ = ["new_pool", "pool_size", "process_pool", "stop_pool", "usable_cpus", "worker_init"]


def usable_cpus():
    """The CPUs this process may run on (its affinity mask where the OS has one: a container or ``taskset`` limits
    it below ``os.cpu_count()``)."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return os.cpu_count() or 1


def pool_size(workers):
    """Processes of a pool asked for ``workers``: no more than :func:`usable_cpus`."""
    return max(1, min(int(workers), usable_cpus()))


def worker_init(parent_pid, initializer=None, initargs=(), period=1.0):
    """Initializer of a pool worker: ignore ``SIGINT``, exit once the process ``parent_pid`` is gone (checked every
    ``period`` seconds: a ``SIGKILL`` of the parent leaves no one to stop the workers), then run ``initializer``."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)

    def watch():
        while True:
            time.sleep(period)
            if os.getppid() != parent_pid:
                os._exit(1)

    threading.Thread(target=watch, name="drakecreep-parent-watch", daemon=True).start()
    if initializer is not None:
        initializer(*initargs)


def stop_pool(pool, timeout=5.0):
    """Cancel ``pool``'s queued work and end its running workers now (a Ctrl-C must not wait for the work)."""
    processes = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for proc in processes:
        try:
            proc.terminate()
        except Exception:  # noqa: BLE001 - already gone
            pass
    for proc in processes:
        proc.join(timeout=timeout)


def new_pool(workers, initializer=None, initargs=()):
    """A ``spawn`` :class:`concurrent.futures.ProcessPoolExecutor` of ``workers`` processes, at most
    :func:`usable_cpus` (:func:`pool_size`), with :func:`worker_init` (``initializer(*initargs)`` runs in each
    worker after it)."""
    return cf.ProcessPoolExecutor(max_workers=pool_size(workers), mp_context=multiprocessing.get_context("spawn"),
                                  initializer=worker_init, initargs=(os.getpid(), initializer, tuple(initargs)))


@contextlib.contextmanager
def process_pool(workers, initializer=None, initargs=()):
    """``with process_pool(n) as pool:`` a pool of :func:`new_pool`; shut down normally when the block ends, and
    stopped at once (:func:`stop_pool`) when it ends by an exception, which then goes on.

    Parameters
    ----------
    workers : int
        Worker processes (>= 1; at most :func:`usable_cpus` are started).
    initializer : callable, optional
        Run in each worker once it starts (module level, picklable), with ``initargs``.
    """
    pool = new_pool(workers, initializer, initargs)
    try:
        yield pool
    except BaseException:
        stop_pool(pool)
        raise
    pool.shutdown(wait=True)
