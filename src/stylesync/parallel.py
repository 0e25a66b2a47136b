"""Where independent runs go: this process, a local process pool, or Ray (a local Ray or a cluster).

:func:`execute` maps a function over argument tuples and yields each result as it ends (:func:`execute_all`: all of
them, in order); a run whose worker or node dies is submitted again (bounded). ``stylesync batch``
(batch/runner.py), the bench, the development suite and the gain grid of ``experiment tune`` use it.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool

from stylesync.errors import ConfigError

EXECUTORS = ("ray", "processes", "inline")


def _inline(fn: Callable, items: list[tuple]) -> Iterator[tuple[int, object, str]]:
    for k, args in enumerate(items):
        yield k, fn(*args), ""


def _processes(fn: Callable, items: list[tuple], workers: int, max_retries: int) -> Iterator[tuple[int, object, str]]:
    """A local process pool; a pool broken by a dying worker is replaced and its items submitted again."""
    attempts = [0] * len(items)
    queue = list(range(len(items)))
    while queue:
        with ProcessPoolExecutor(max_workers=workers) as pool:
            futures: dict[Future, int] = {pool.submit(fn, *items[k]): k for k in queue}
            queue = []
            while futures:
                finished, _ = wait(list(futures), return_when=FIRST_COMPLETED)
                for fut in finished:
                    k = futures.pop(fut)
                    try:
                        yield k, fut.result(), ""
                    except BrokenProcessPool as exc:
                        attempts[k] += 1
                        if attempts[k] > max_retries:
                            yield k, None, f"worker lost {attempts[k]} times: {exc}"
                        else:
                            yield k, None, "retry"
                            queue.append(k)


def _ray(fn: Callable, items: list[tuple], workers: int, address: str | None, max_retries: int
         ) -> Iterator[tuple[int, object, str]]:
    """Ray tasks, one per item; a task whose worker or node dies is submitted again (bounded)."""
    try:
        import ray
    except ImportError:
        raise ConfigError("the ray executor needs Ray: pip install 'stylesync[batch]'") from None
    started_here = not ray.is_initialized()
    if started_here:
        kwargs: dict = {"include_dashboard": False, "log_to_driver": False, "logging_level": logging.ERROR,
                        "configure_logging": False}
        if address:
            ray.init(address=address, **kwargs)
        else:  # a Ray instance of its own: not a cluster a stale /tmp/ray/ray_current_cluster names
            ray.init(address="local", num_cpus=workers, **kwargs)
    task = ray.remote(num_cpus=1, max_retries=0)(fn)
    # An argument object that many items share (settings) goes to the object store once.
    uses: dict[int, int] = {}
    for args in items:
        for a in args:
            uses[id(a)] = uses.get(id(a), 0) + 1
    shared: dict[int, object] = {}

    def put(args: tuple) -> tuple:
        out = []
        for a in args:
            if uses.get(id(a), 0) > 1 and not isinstance(a, (str, int, float, bool)):
                if id(a) not in shared:
                    shared[id(a)] = ray.put(a)
                out.append(shared[id(a)])
            else:
                out.append(a)
        return tuple(out)

    pending = {task.remote(*put(args)): k for k, args in enumerate(items)}
    attempts = [0] * len(items)
    try:
        while pending:
            ready, _ = ray.wait(list(pending), num_returns=1, timeout=1.0)
            for ref in ready:
                k = pending.pop(ref)
                try:
                    result = ray.get(ref)
                except ray.exceptions.RayTaskError as exc:  # the function raised: its result is the error
                    yield k, None, f"task error: {str(exc).splitlines()[0]}"
                    continue
                except ray.exceptions.RayError as exc:  # the worker or its node died
                    attempts[k] += 1
                    if attempts[k] > max_retries:
                        yield k, None, f"worker lost {attempts[k]} times: {type(exc).__name__}"
                    else:
                        yield k, None, "retry"
                        pending[task.remote(*put(items[k]))] = k
                    continue
                yield k, result, ""
    finally:
        for ref in pending:
            ray.cancel(ref, force=True)
        if started_here:
            ray.shutdown()


def execute(fn: Callable, items: list[tuple], executor: str = "processes", workers: int | None = None,
            ray_address: str | None = None, max_retries: int = 2) -> Iterator[tuple[int, object, str]]:
    """``fn(*item)`` for every item on the executor, yielded as each ends (in any order): (the item's index, its
    result or None, a note: "" done, "retry" its worker died and it was submitted again, else why it has no
    result). ``fn`` must be importable by name (a module's function) for the processes and Ray."""
    if executor not in EXECUTORS:
        raise ConfigError(f"unknown executor '{executor}' (one of {', '.join(EXECUTORS)})")
    workers = workers or os.cpu_count() or 1
    if executor == "inline":
        return _inline(fn, items)
    if executor == "processes":
        return _processes(fn, items, workers, max_retries)
    return _ray(fn, items, workers, ray_address, max_retries)


def execute_all(fn: Callable, items: list[tuple], executor: str = "processes", workers: int | None = None,
                on_result: Callable[[int, object, str], None] | None = None) -> list[tuple[object, str]]:
    """:func:`execute` run to its end: each item's (result or None, note) in the items' order, its resubmissions
    ("retry") left out. ``on_result(index, result, note)`` is called as each item ends (progress lines)."""
    outcome: dict[int, tuple[object, str]] = {}
    for k, result, note in execute(fn, items, executor, workers):
        if note == "retry":
            continue
        outcome[k] = (result, note)
        if on_result is not None:
            on_result(k, result, note)
    return [outcome[k] for k in range(len(items))]
