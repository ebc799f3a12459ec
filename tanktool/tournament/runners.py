"""Where a tournament's matches run: one after another in this process
(``serial``), on a pool of local processes (``pool``, the default), or on a Ray
cluster (``ray``: ``ray.init(address)``, or a cluster started here for ``local``).

Each runner takes the tasks and yields the results as matches finish, in any
order: the report sorts them by match index, so how they ran never shows in it.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
from typing import Any, Callable, Iterator

from ..errors import TanktoolError
from .play import play_match
from .schedule import MatchTask

RUNNERS = ("serial", "pool", "ray")


def default_workers() -> int:
    """The local cores this process may use."""
    try:
        return max(len(os.sched_getaffinity(0)), 1)
    except AttributeError:      # pragma: no cover - not Linux
        return max(os.cpu_count() or 1, 1)


def run_serial(tasks: list[MatchTask], workers: int = 1) -> Iterator[dict[str, Any]]:
    for task in tasks:
        yield play_match(task)


def run_pool(tasks: list[MatchTask], workers: int) -> Iterator[dict[str, Any]]:
    """A process pool; each worker keeps its arenas and bots loaded between matches."""
    workers = max(1, min(workers, len(tasks)))
    if workers == 1:
        yield from run_serial(tasks)
        return
    # one match at a time per worker: matches are long next to the cost of sending one
    with multiprocessing.get_context().Pool(workers, initializer=_default_sigterm) as pool:
        yield from pool.imap_unordered(play_match, tasks, chunksize=1)
        pool.close()        # all done: the workers leave on their own, not by SIGTERM
        pool.join()


def _default_sigterm() -> None:
    """A forked worker inherits its parent's SIGTERM handler (Ray installs one): a
    handler that does not exit made Pool.terminate wait for ever on a worker blocked on
    the task queue (a hung test run).  The default handler lets terminate end it."""
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _ray() -> Any:
    try:
        import ray
    except ImportError:
        raise TanktoolError("--ray needs Ray: pip install 'tanktool[cluster]'") from None
    return ray


def _reachable(address: str, timeout: float = 5.0) -> None:
    """Refuse a HOST:PORT where nothing listens at once: Ray itself would retry for
    minutes.  Other forms (``auto``, ``ray://...``) are left to Ray."""
    import socket

    host, sep, port = address.rpartition(":")
    if not sep or not port.isdigit() or "/" in address:
        return
    try:
        socket.create_connection((host.strip("[]") or "127.0.0.1", int(port)), timeout=timeout).close()
    except OSError as e:
        raise TanktoolError(f"--ray {address}: no Ray cluster answers there ({e.strerror or e}); start one with "
                            f"'ray start --head' or use --ray local") from None


def ray_connect(address: str, workers: int | None = None) -> Any:
    """Ray, initialised: an existing connection is kept (tests share one cluster);
    ``local`` starts a cluster on this machine with ``workers`` CPUs."""
    ray = _ray()
    if ray.is_initialized():
        return ray
    try:
        if address == "local":
            ray.init(num_cpus=workers or default_workers(), include_dashboard=False, log_to_driver=False,
                     configure_logging=False)
        else:
            _reachable(address)
            ray.init(address=address, log_to_driver=False, configure_logging=False)
    except TanktoolError:
        raise
    except Exception as e:     # Ray's own errors: no cluster there, a version mismatch
        raise TanktoolError(f"--ray {address}: cannot connect to a Ray cluster: {type(e).__name__}: "
                            f"{str(e).splitlines()[0] if str(e) else ''}") from None
    return ray


def run_ray(tasks: list[MatchTask], workers: int, address: str = "local") -> Iterator[dict[str, Any]]:
    """One Ray task per match; results as they finish."""
    ray = ray_connect(address, workers)
    remote = ray.remote(num_cpus=1, max_retries=0)(play_match)
    pending = [remote.remote(t) for t in tasks]
    while pending:
        done, pending = ray.wait(pending, num_returns=1)
        try:
            yield ray.get(done[0])
        except ray.exceptions.RayTaskError as e:
            cause = getattr(e, "cause", None)
            if isinstance(cause, TanktoolError):
                raise cause from None
            raise TanktoolError(f"a match failed on the Ray cluster: {type(cause or e).__name__}: "
                                f"{cause or e}") from None


def runner(name: str) -> Callable[..., Iterator[dict[str, Any]]]:
    if name not in RUNNERS:
        raise TanktoolError(f"runner must be one of {', '.join(RUNNERS)}, got {name!r}")
    return {"serial": run_serial, "pool": run_pool, "ray": run_ray}[name]
