"""A warm ``zonegraph``: one process that has imported the geometry kernel forks a child per call.

Every call of the command line pays to start before it reads a part: the interpreter, numpy,
pyarrow and OCP's one extension module, whose initialisation alone registers every bound class of
OpenCASCADE (docs/results/benchmarks.md, "Where the floor is") and costs more CPU than the original
implementation's whole process on a small part. ``zonegraph server start`` pays that once. While
a server runs, a call of ``build``, ``infer``, ``replay`` or ``convert`` imports none of the kernel:
it connects to the server's socket (`zonegraph.handoff`, the calling side) and hands over its
arguments, working folder, environment, umask and its standard streams (file descriptors, passed
with ``SCM_RIGHTS``); the server forks a child that runs the command as that call's own process
would, writing to the caller's terminal, and the child's exit status becomes the call's.

Why a fork per call rather than a thread: every call starts from the same warm, untouched copy of
the server (copy-on-write), so one call's state, a crash or a hung OpenCASCADE call cannot reach the
next, and the command's own isolation (a killable child per part) works as it does cold. The child
leads its own process group: the caller forwards Ctrl-C and termination to it, and a caller that
dies takes its call down with it.

A server serves only the code it was started with: its socket is named by a fingerprint of the
interpreter, the installed distributions and the package's own files, so after an upgrade or an
edit calls run cold until a server of the new code is started; an old one stops after its idle
time. ``ZONEGRAPH_NO_SERVER=1`` makes a call run cold whatever runs. Only the user who started a
server can reach it: its folder is private (mode 0700) and a peer of another user is refused.
Settings that libraries read when imported (thread counts, say) are the server's, not the call's.
"""

from __future__ import annotations

import os
import selectors
import signal
import socket
import struct
import subprocess
import sys
import time
import traceback
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from zonegraph.handoff import ask, directory, fingerprint, receive, send, socket_path

IDLE_S = 900.0  # a server with no call for this long stops
START_TIMEOUT_S = 120.0
# What the commands import before their first part, imported once by the server.
WARM = (
    "zonegraph.batch",
    "zonegraph.build_job",
    "zonegraph.isolation",
    "zonegraph.jobs",
    "zonegraph.outputs",
    "zonegraph.reconstruction",
    "zonegraph.network.ranker",
    "build123d",
)


class ServerError(Exception):
    """A server cannot be started, reached or stopped; the message says why."""


def private(folder: Path) -> Path:
    """``folder``, created mode 0700 if missing; refused unless this user owns it, alone."""
    folder.mkdir(mode=0o700, parents=True, exist_ok=True)
    info = folder.stat()
    if info.st_uid != os.getuid() or info.st_mode & 0o077:
        raise ServerError(f"{folder}: not a private folder of this user (mode {info.st_mode & 0o777:o})")
    return folder


@dataclass
class _Calls:
    """The server's calls in flight (child pid -> its caller's connection), its tally, and
    whether it is stopping (asked to, or its socket file is gone)."""

    running: dict[int, socket.socket] = field(default_factory=dict)
    served: int = 0
    last: float = field(default_factory=time.monotonic)
    ended: dict[str, Any] | None = None  # the last call's exit status, CPU seconds and peak memory
    started: float = field(default_factory=time.time)
    stopping: bool = False

    def stop(self, *_signal: object) -> None:
        self.stopping = True


def warm() -> None:
    """Import what the forwarded commands import, without the cyclic collector, then freeze it all
    out of later collections (as a cold call does before forking its worker)."""
    import gc
    import importlib

    from zonegraph.lazy import uncollected

    with uncollected():
        for module in (*WARM, "zonegraph.cli"):
            importlib.import_module(module)
        from zonegraph.data.b123d import install_ocp_shims

        install_ocp_shims()
    gc.freeze()


def serve(path: Path, idle_s: float = IDLE_S) -> None:
    """Listen on ``path`` until stopped or idle for ``idle_s`` seconds (run by ``start``)."""
    warm()
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    temporary = path.with_name(f"{path.name}.{os.getpid()}")
    listener.bind(str(temporary))
    listener.listen(16)
    os.replace(temporary, path)  # whole or not at all: a caller never meets a socket not listening
    inode = path.stat().st_ino
    wake_read, wake_write = os.pipe()
    os.set_blocking(wake_read, False)
    os.set_blocking(wake_write, False)
    signal.set_wakeup_fd(wake_write)
    signal.signal(signal.SIGCHLD, lambda *_: None)
    calls = _Calls()
    signal.signal(signal.SIGTERM, calls.stop)
    selector = selectors.DefaultSelector()
    selector.register(listener, selectors.EVENT_READ, "accept")
    selector.register(wake_read, selectors.EVENT_READ, "wake")
    try:
        while calls.running or not (calls.stopping or time.monotonic() - calls.last >= idle_s):
            for key, _ in selector.select(timeout=1.0):
                try:
                    if key.data == "accept":
                        _accept(listener, selector, calls, (wake_read, wake_write))
                    elif key.data == "wake":
                        _drain(wake_read)
                    else:
                        _caller_gone(key.data, selector, calls)
                except Exception:  # one caller's broken connection must not end the others' server
                    traceback.print_exc()
            _reap(selector, calls)
            if not _owns(path, inode):  # removed or replaced: no caller can reach it
                calls.stop()
            if calls.stopping and listener.fileno() in selector.get_map():
                selector.unregister(listener)  # no new call; those running end first
                _unlink_own(path, inode)
    finally:
        for pid in calls.running:
            _kill_group(pid)
        _unlink_own(path, inode)
        listener.close()


def _owns(path: Path, inode: int) -> bool:
    """``path`` is still this server's socket (not removed, nor replaced by a newer server's)."""
    try:
        return path.stat().st_ino == inode
    except OSError:
        return False


def _unlink_own(path: Path, inode: int) -> None:
    if _owns(path, inode):
        path.unlink(missing_ok=True)


def _accept(
    listener: socket.socket,
    selector: selectors.BaseSelector,
    calls: _Calls,
    wake: tuple[int, int],
) -> None:
    conn, _ = listener.accept()
    conn.settimeout(10.0)
    if not _same_user(conn):
        conn.close()
        return
    request, fds = receive(conn, max_fds=3)
    if request is None:
        conn.close()
        return
    calls.last = time.monotonic()
    if request.get("op") == "run" and len(fds) == 3:
        pid = os.fork()
        if pid == 0:
            _child(request, fds, selector, conn, wake)
        for fd in fds:
            os.close(fd)
        send(conn, {"pid": pid})
        calls.running[pid] = conn
        selector.register(conn, selectors.EVENT_READ, pid)
        return
    for fd in fds:
        os.close(fd)
    if request.get("op") == "stop":
        calls.stop()
    send(conn, _status(calls))
    conn.close()


def _same_user(conn: socket.socket) -> bool:
    """The peer runs as this user (Linux's ``SO_PEERCRED``; elsewhere the private folder decides)."""
    if not hasattr(socket, "SO_PEERCRED"):
        return True
    creds = conn.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED, struct.calcsize("3i"))
    return struct.unpack("3i", creds)[1] == os.getuid()


def _status(calls: _Calls) -> dict[str, Any]:
    import resource

    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return {
        "pid": os.getpid(),
        "uptime_s": time.time() - calls.started,
        "served": calls.served,
        "running": len(calls.running),
        "cpu_s": own.ru_utime + own.ru_stime,
        "children_cpu_s": children.ru_utime + children.ru_stime,
        "peak_mb": own.ru_maxrss / 1024,
        "last_call": calls.ended,
    }


def _drain(fd: int) -> None:
    try:
        while os.read(fd, 4096):
            pass
    except BlockingIOError:
        pass


def _reap(selector: selectors.BaseSelector, calls: _Calls) -> None:
    """Tell each finished call's caller its exit status and its child's resource use."""
    while calls.running:
        try:
            pid, status, use = os.wait4(-1, os.WNOHANG)
        except ChildProcessError:
            return
        if pid == 0:
            return
        conn = calls.running.pop(pid, None)
        if conn is None:
            continue
        calls.served += 1
        calls.last = time.monotonic()
        _forget(selector, conn)
        calls.ended = {
            "rc": os.waitstatus_to_exitcode(status),
            "cpu_s": use.ru_utime + use.ru_stime,  # the call's child and the workers it reaped
            "peak_mb": use.ru_maxrss / 1024,  # resident, the pages it shares with the server included
        }
        try:
            send(conn, calls.ended)
        except OSError:
            pass
        conn.close()


def _caller_gone(pid: int, selector: selectors.BaseSelector, calls: _Calls) -> None:
    """A caller's connection became readable before its call ended: it sends nothing more, so
    it closed (killed, say): the call goes with it."""
    conn = calls.running[pid]
    try:
        data = conn.recv(1, socket.MSG_PEEK)
    except OSError:
        data = b""
    if not data:
        _forget(selector, conn)
        _kill_group(pid)


def _forget(selector: selectors.BaseSelector, conn: socket.socket) -> None:
    """Stop watching a call's connection (once its caller left, or once the call ended)."""
    try:
        selector.unregister(conn)
    except KeyError:
        pass


def _kill_group(pid: int) -> None:
    try:
        os.killpg(pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass


def _child(
    request: dict[str, Any],
    fds: list[int],
    selector: selectors.BaseSelector,
    conn: socket.socket,
    wake: tuple[int, int],
) -> None:
    """The forked call: the caller's streams, folder, environment and umask, then the command."""
    status = 1
    try:
        os.setpgid(0, 0)
        signal.set_wakeup_fd(-1)
        for s in (signal.SIGCHLD, signal.SIGTERM, signal.SIGHUP):
            signal.signal(s, signal.SIG_DFL)
        signal.signal(signal.SIGINT, signal.default_int_handler)
        _close_server_side(selector, conn, wake)
        for target, fd in enumerate(fds):
            os.dup2(fd, target)
            os.close(fd)
        sys.stdin, sys.stdout, sys.stderr = (_stream(i) for i in range(3))
        os.chdir(request["cwd"])
        os.environ.clear()
        os.environ.update(request["env"])
        os.umask(int(request["umask"]))
        from zonegraph.cli import main

        status = main(request["argv"], own_process=True)
    except SystemExit as exc:  # argparse's own exits
        status = exc.code if isinstance(exc.code, int) else 2
    except KeyboardInterrupt:
        status = 130
    except BaseException:
        traceback.print_exc()
    finally:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except Exception:
                pass
        os._exit(status)


def _close_server_side(selector: selectors.BaseSelector, conn: socket.socket, wake: tuple[int, int]) -> None:
    """Close, in a call's child, what belongs to the server: its listener, the connections of
    other calls and this one, the wake-up pipe and the selector."""
    sockets = [k.fileobj for k in selector.get_map().values() if isinstance(k.fileobj, socket.socket)]
    for sock in [*sockets, conn]:
        sock.close()
    selector.close()
    for fd in wake:
        os.close(fd)


def _stream(fd: int) -> Any:
    mode = "r" if fd == 0 else "w"
    line = 1 if fd and os.isatty(fd) else -1
    return os.fdopen(fd, mode, buffering=line, encoding="utf-8", errors="replace", closefd=False)


def start(idle_s: float = IDLE_S) -> dict[str, Any]:
    """A server of this code, started unless one runs; its status once it answers."""
    path = private(Path(directory())) / f"{fingerprint()}.sock"
    running = ask("status", str(path))
    if running is not None:
        return {**running, "socket": str(path), "already": True}
    log = path.with_suffix(".log")
    cmd = [sys.executable, "-m", "zonegraph.server", str(path), str(idle_s)]
    with open(log, "w") as out:
        proc = subprocess.Popen(
            cmd, stdin=subprocess.DEVNULL, stdout=out, stderr=subprocess.STDOUT, start_new_session=True
        )
    for _ in _until(START_TIMEOUT_S):
        answer = ask("status", str(path))
        if answer is not None:
            return {**answer, "socket": str(path), "already": False}
        if proc.poll() is not None:
            tail = log.read_text(errors="replace").strip().splitlines()[-1:] or [f"exit {proc.returncode}"]
            raise ServerError(f"the server did not start ({tail[0]}; log {log})")
    proc.kill()
    raise ServerError(f"the server did not answer within {START_TIMEOUT_S:.0f} s (log {log})")


def _until(seconds: float) -> Iterator[None]:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        yield
        time.sleep(0.05)


def status() -> dict[str, Any] | None:
    """The status of the server of this code, or None where none runs."""
    return ask("status")


def others() -> list[str]:
    """The sockets of this user's servers of other code (an older install, say) that answer."""
    folder, own = directory(), socket_path()
    names = sorted(os.listdir(folder)) if os.path.isdir(folder) else []
    paths = [os.path.join(folder, n) for n in names if n.endswith(".sock")]
    return [p for p in paths if p != own and ask("status", p) is not None]


def describe(action: str, state: dict[str, Any] | None, other: int = 0) -> str:
    """What ``zonegraph server ACTION`` prints; ``other``: servers of other code running (status)
    or stopped (stop)."""
    if action == "stop" and other:
        tail = f"; {other} of other code stopped"
    elif other:
        tail = f"; {other} of other code still running (zonegraph server stop stops them)"
    else:
        tail = ""
    if state is None:
        nothing = " (nothing to stop)" if action == "stop" and not other else ""
        return f"zonegraph server: none of this code runs{nothing}{tail}"
    what = {"start": "already running" if state.get("already") else "started", "stop": "stopped"}
    head = f"zonegraph server: {what.get(action, 'running')}, pid {state['pid']}"
    if action == "start":
        return f"{head}, socket {state['socket']}; calls now skip the start-up (zonegraph server stop)"
    return (
        f"{head}, up {state['uptime_s']:.0f} s, {state['served']} calls served "
        f"({state['children_cpu_s']:.2f} CPU s), {state['running']} running, {state['peak_mb']:.0f} MB{tail}"
    )


def stop() -> tuple[dict[str, Any] | None, int]:
    """Stop this user's servers: this code's (its last status, or None where none ran) and any of
    other code (how many), which would otherwise idle until their time is up."""
    stopped = [answer for path in others() if (answer := _stop_one(path)) is not None]
    return _stop_one(socket_path()), len(stopped)


def _stop_one(path: str) -> dict[str, Any] | None:
    answer = ask("stop", path)
    if answer is None:
        return None
    for _ in _until(30.0):
        if not os.path.exists(path):
            break
    return answer


if __name__ == "__main__":
    serve(Path(sys.argv[1]), float(sys.argv[2]))
