"""Run one OpenCASCADE job in a forked child so a hang or a crash cannot take the caller down.

OpenCASCADE's STEP reader, Booleans and general fuse occasionally loop forever or segfault on bad
geometry. Threads cannot be stopped, so each job runs in a forked process (cheap: the parent has
already imported OCP) that is killed at its deadline. The outcome is a status, never an exception.

A child must not outlive the process that waits for it (a killed ``infer`` or a lost Dask worker
left its design computing for minutes, outside every timeout): on Linux it asks the kernel for
SIGKILL when its parent dies (``PR_SET_PDEATHSIG``). It may also run under an address-space limit
(``RLIMIT_AS``), since a worker's memory monitor does not see its forked children; an allocation
past the limit is the ``out_of_memory`` status.
"""

from __future__ import annotations

import ctypes
import errno
import gc
import multiprocessing as mp
import os
import resource
import signal
import sys
import time
import traceback
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from multiprocessing.connection import Connection
from multiprocessing.process import BaseProcess
from typing import Any

from zonegraph.console import captured
from zonegraph.errors import ZoneGraphError, is_kernel_error
from zonegraph.status import Status


@dataclass(frozen=True)
class Outcome:
    status: Status  # ok, timeout, crash, bug (its traceback in ``detail``), kernel_error or an error's
    value: Any = None
    reason: str = ""  # one line
    seconds: float = 0.0
    detail: str = ""  # a bug's traceback

    @property
    def ok(self) -> bool:
        return self.status == Status.OK


def classify(exc: BaseException) -> tuple[Status, str, str]:
    """``(status, one-line reason, traceback)`` of an exception raised by a job.

    OpenCASCADE's exceptions (`zonegraph.errors.is_kernel_error`) are failures of the kernel
    on this input's geometry: a status like any unbuildable input. Every other exception is a bug
    of ours and keeps its traceback."""
    if isinstance(exc, ZoneGraphError):
        return exc.status, exc.explain(), ""
    if _out_of_memory(exc):
        return Status.OUT_OF_MEMORY, f"out of memory ({type(exc).__name__}) under the job's memory limit", ""
    last = traceback.extract_tb(exc.__traceback__)[-1] if exc.__traceback__ else None
    where = f" ({os.path.basename(last.filename)}:{last.lineno} {last.name})" if last else ""
    name = type(exc).__name__
    message = " ".join(str(exc).split()) or "no message"
    if is_kernel_error(exc):
        return Status.KERNEL_ERROR, f"OpenCASCADE {name}: {message}{where}", ""
    return Status.BUG, f"{name}: {message}{where}", "".join(traceback.format_exception(exc))


def _out_of_memory(exc: BaseException) -> bool:
    """An allocation refused: Python's or OpenCASCADE's, or a mapping the address-space limit
    denied (a shared library imported in the child: ``failed to map segment``; ``ENOMEM``)."""
    if isinstance(exc, MemoryError) or "OutOfMemory" in type(exc).__name__:
        return True
    if isinstance(exc, OSError) and exc.errno == errno.ENOMEM:
        return True
    return isinstance(exc, ImportError) and "failed to map segment" in str(exc)


PR_SET_PDEATHSIG = 1  # linux/prctl.h


def _die_with_parent(parent: int) -> None:
    """Ask for SIGKILL when the parent dies; if it died before the request took effect, die now."""
    if not sys.platform.startswith("linux"):
        return
    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent:
        os._exit(1)


def _limit_memory(memory_mb: int | None) -> None:
    """Allow ``memory_mb`` MiB of address space beyond what the child inherited: a parent that
    imported torch maps many GiB it never touches, which an absolute limit would count."""
    if memory_mb:
        with open("/proc/self/statm") as f:
            inherited = int(f.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
        limit = inherited + (int(memory_mb) << 20)
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))


def default_memory_mb() -> int | None:
    """The memory limit of children when the caller names none: ``$ZONEGRAPH_MEMORY_MB`` (MiB)."""
    value = os.environ.get("ZONEGRAPH_MEMORY_MB", "")
    return int(value) if value.isdigit() and int(value) > 0 else None


def _child(
    conn: Connection, fn: Callable[..., Any], args: tuple[Any, ...], parent: int, memory_mb: int | None
) -> None:
    """Run the job with its console output captured: OpenCASCADE prints messages such as
    ``**** ERR StepFile`` from C++ straight to file descriptor 1, and numpy's warnings go to 2;
    neither belongs on the user's terminal. ``sys.exit`` inside the job is an outcome like any
    exception (``SystemExit`` is caught below); ``os._exit`` and signals end the child without a
    message, which the parent reports as a crash."""
    _die_with_parent(parent)
    try:
        _limit_memory(memory_mb)
        with captured():
            conn.send((Status.OK, fn(*args), "", ""))
    except BaseException as exc:  # noqa: BLE001 - every outcome, bugs included, goes to the parent
        status, reason, detail = classify(exc)
        if status == Status.OUT_OF_MEMORY and memory_mb:
            reason = f"out of memory ({type(exc).__name__}) past the {memory_mb} MiB memory limit"
        conn.send((status, None, reason, detail))
    finally:
        conn.close()
        os._exit(0)


def run_isolated(
    fn: Callable, args: tuple = (), timeout: float | None = 60.0, memory_mb: int | None = None
) -> Outcome:
    """``fn(*args)`` in a forked child allowed ``memory_mb`` more MiB of address space (None:
    `default_memory_mb`);
    its return value must be picklable (keep it small). ``timeout`` None runs in-process (no limit
    of either kind)."""
    memory_mb = memory_mb or default_memory_mb()
    if timeout is None and not memory_mb:
        return _run_inline(fn, args)
    ctx = mp.get_context("fork")
    recv, send = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child, args=(send, fn, args, os.getpid(), memory_mb))
    t0 = time.perf_counter()
    _fork(proc)
    send.close()
    try:
        if not recv.poll(timeout):
            proc.kill()
            return Outcome(
                Status.TIMEOUT, reason=f"no result after {timeout:g} s", seconds=time.perf_counter() - t0
            )
        status, value, reason, detail = recv.recv()
    except EOFError:
        proc.join()
        return _died(proc.exitcode, memory_mb, time.perf_counter() - t0)
    finally:
        recv.close()
        proc.join(5)
        if proc.is_alive():
            proc.kill()
            proc.join()
    return Outcome(status, value, reason, time.perf_counter() - t0, detail)


def _died(exitcode: int | None, memory_mb: int | None, seconds: float) -> Outcome:
    """A child that ended without a result: by a signal, ``os._exit`` or a failed C++ allocation
    (which aborts, SIGABRT, when an address-space limit refused it)."""
    if memory_mb and exitcode == -signal.SIGABRT:
        return Outcome(
            Status.OUT_OF_MEMORY, reason=f"aborted past the {memory_mb} MiB memory limit", seconds=seconds
        )
    if exitcode is not None and exitcode < 0:
        name = signal.Signals(-exitcode).name if -exitcode in signal.valid_signals() else str(-exitcode)
        reason = f"worker died (exit code {exitcode}, {name})"
    else:
        reason = f"worker exited without a result (exit code {exitcode})"
    return Outcome(Status.CRASH, reason=reason, seconds=seconds)


def _warn_if_pool_started() -> None:
    """Warn, once, when the kernel's thread pool has a worker thread a child would wait for (a
    parallel Boolean ran before `zonegraph.geometry.kernel` was imported)."""
    global _POOL_CHECKED
    if _POOL_CHECKED or "OCP" not in sys.modules:
        return
    _POOL_CHECKED = True
    from zonegraph.geometry.kernel import fork_safe

    if not fork_safe():
        warnings.warn(
            "OpenCASCADE's thread pool started before zonegraph was imported: forked jobs may hang "
            "until their timeout; import zonegraph.geometry.kernel before any build123d Boolean",
            RuntimeWarning,
            stacklevel=3,
        )


_POOL_CHECKED = False


def _fork(proc: BaseProcess) -> None:
    """Start the child with every object inherited from the parent frozen (``gc.freeze``).

    Otherwise the child's first full collection walks the parent's millions of objects (build123d,
    OCP, scipy), writing to each one's header and so copying its page: measured on ``zonegraph
    infer`` of a one-extrude part, 0.2 s of collection and 0.5 s per part instead of 0.13 s. The
    parent unfreezes at once, so its own garbage is still collected."""
    _warn_if_pool_started()
    gc.freeze()
    try:
        proc.start()
    finally:
        gc.unfreeze()


def _run_inline(fn: Callable, args: tuple) -> Outcome:
    """No timeout asked for: run in-process, with the same outcomes, except that a bug raises here
    (debuggable where it happened) and the console is not captured."""
    t0 = time.perf_counter()
    try:
        return Outcome(Status.OK, fn(*args), "", time.perf_counter() - t0)
    except Exception as exc:
        status, reason, _ = classify(exc)
        if status == Status.BUG:
            raise
        return Outcome(status, None, reason, time.perf_counter() - t0)
