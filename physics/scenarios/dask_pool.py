"""Run a scenario's (case, member) jobs on a Dask cluster instead of the
local process pool: ``ice-scenarios run NAME --dask-local N`` starts a
``distributed.LocalCluster`` of N single-threaded worker processes on this
machine (and closes it at the end); ``--scheduler ADDRESS`` sends the jobs to
the workers of a running scheduler, e.g. one started with ``dask scheduler``
and ``dask worker ADDRESS --nthreads 1`` on other machines. Both need the
``distributed`` package: ``pip install 'seaice-gym[dask]'``.

Each job runs :func:`physics.scenarios.jobs.run_job` in a task with Numba
limited to one thread, as in the local pool, so an ensemble gives the same
results bit for bit whichever way it is run.

**The workers must see the run directory at the same path** (a shared
filesystem): each job writes its NetCDF file and its checkpoints into
``RUN_DIR/jobs`` itself, and the runner gathers them from there. After
Ctrl-C the tasks are cancelled and a LocalCluster is shut down; Dask cannot
stop a task that is already running, so the workers of a scheduler finish
the runs they had begun (their files count as finished for ``--resume``).
"""
from __future__ import annotations

import logging
import signal
import time
import uuid

from . import jobs

INSTALL_HINT = "pip install 'seaice-gym[dask]'"
CONNECT_TIMEOUT = 10.0        # seconds to reach a scheduler


def check_options(dask) -> dict | None:
    """``dask`` (``None``, ``{"scheduler": ADDRESS}`` or ``{"local": N}``,
    optionally with ``"timeout"``: seconds to reach the scheduler) checked,
    and ``distributed`` importable; a ValueError says what is wrong."""
    if not dask:
        return None
    options = dict(dask)
    unknown = set(options) - {"scheduler", "local", "timeout"}
    if unknown:
        raise ValueError(f"unknown Dask option(s) {', '.join(sorted(unknown))}; valid: "
                         f"scheduler, local, timeout")
    if ("scheduler" in options) == ("local" in options):
        raise ValueError("give either a Dask scheduler address (--scheduler) or a number of "
                         "local Dask workers (--dask-local), not both")
    if "local" in options:
        n = options["local"]
        if isinstance(n, bool) or not isinstance(n, int) or n < 1:
            raise ValueError(f"--dask-local needs a positive number of workers, got {n!r}")
    elif not isinstance(options["scheduler"], str) or not options["scheduler"].strip():
        raise ValueError(f"--scheduler needs a scheduler address such as tcp://host:8786, got "
                         f"{options['scheduler']!r}")
    _distributed()
    return options


def describe(options: dict) -> str:
    """Where the jobs of ``options`` run, for the runner's first line."""
    if "local" in options:
        return f", on a local Dask cluster of {options['local']} worker process(es)"
    return f", on the workers of the Dask scheduler at {options['scheduler'].strip()}"


def _distributed():
    try:
        import distributed
    except ImportError as exc:
        raise ValueError(f"running on Dask needs the 'distributed' package: "
                         f"{INSTALL_HINT}") from exc
    return distributed


def _connect(distributed, options: dict, log):
    """(client, the LocalCluster made here or None)."""
    timeout = float(options.get("timeout", CONNECT_TIMEOUT))
    if "local" in options:
        cluster = distributed.LocalCluster(n_workers=options["local"], threads_per_worker=1,
                                           processes=True, dashboard_address=None,
                                           silence_logs=logging.ERROR)
        try:
            client = distributed.Client(cluster, timeout=timeout)
            # Ctrl-C reaches the whole process group: leave it to this process
            # (which cancels the tasks and closes the cluster), as the local
            # pool's workers do
            client.run(_ignore_sigint)
        except BaseException:
            cluster.close()
            raise
        return client, cluster
    address = options["scheduler"].strip()
    try:
        client = distributed.Client(address, timeout=timeout)
    except (OSError, TimeoutError) as exc:
        raise ValueError(f"cannot reach the Dask scheduler at {address} within {timeout:g} s "
                         f"({exc}); is it running, and is the address right?") from exc
    if not client.scheduler_info().get("workers"):
        log(f"\nthe Dask scheduler at {address} has no workers yet: the runs wait for them")
    return client, None


def _ignore_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)


class _Reporter:
    """A job's progress sent to the client as Dask events, at most twice a
    second (and always at the end)."""

    def __init__(self, topic: str, job_id: int):
        from distributed import get_worker
        self.worker, self.topic, self.job_id, self.sent = get_worker(), topic, job_id, 0.0

    def __call__(self, fraction: float) -> None:
        now = time.monotonic()
        if fraction < 1.0 and now - self.sent <= 0.5:
            return
        self.sent = now
        try:
            self.worker.log_event(self.topic, [self.job_id, float(fraction)])
        except Exception:  # noqa: BLE001  (the progress bar is not worth a failed run)
            pass


def _run_task(topic: str, *args) -> str:
    """One job in a Dask task: one Numba thread (as the local pool's workers
    have), progress sent under ``topic``; ``args`` are those of
    :func:`~physics.scenarios.jobs.run_job`."""
    import numba

    numba.set_num_threads(1)
    return jobs.run_job(*args, on_progress=_Reporter(topic, args[-1]))


def run_on_dask(args: list, update, dask: dict, log=print) -> None:
    """Run the jobs ``args`` (argument tuples of ``run_job``, the last item
    the job's index) on Dask; ``update(index, fraction)`` receives their
    progress. A failed job's exception is raised here; on that or on Ctrl-C
    the remaining tasks are cancelled."""
    options = check_options(dask)
    distributed = _distributed()
    client, cluster = _connect(distributed, options, log)
    topic = f"seaice-scenarios-progress-{uuid.uuid4().hex}"
    futures = []
    try:
        client.subscribe_topic(topic, lambda event: update(*event[1]))
        futures = [client.submit(_run_task, topic, *a, pure=False) for a in args]
        index = {f.key: a[-1] for f, a in zip(futures, args)}
        for fut in distributed.as_completed(futures):
            fut.result()
            update(index[fut.key], 1.0)
    except BaseException:
        try:
            client.cancel(futures)
        except Exception:  # noqa: BLE001  (the error being raised matters, not this one)
            pass
        raise
    finally:
        try:
            client.unsubscribe_topic(topic)
            client.close()
        finally:
            if cluster is not None:
                cluster.close()
