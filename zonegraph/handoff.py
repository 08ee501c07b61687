"""Handing a call to a warm ``zonegraph server`` (`zonegraph.server`): the calling side.

A handed-over call's own process costs starting the interpreter, this module and the wait, so
this module imports only the smallest parts of the standard library (no pathlib, no argparse, none
of the package): the call's arguments are parsed, and refused, by the child that runs it.

The wire: each message is 4 bytes of length and that much JSON, over a Unix stream socket. A call
sends ``{"op": "run", "argv", "cwd", "env", "umask"}`` with its three standard streams attached
(``SCM_RIGHTS``) and reads ``{"pid"}`` (the call's child, which leads its own process group),
then ``{"rc", "cpu_s", "peak_mb"}`` when the child ends. ``{"op": "status"}`` and ``{"op":
"stop"}`` are answered with the server's status.
"""

from __future__ import annotations

import hashlib
import json
import os
import signal
import socket
import struct
import sys
from collections.abc import Sequence
from typing import Any

FORWARDED = frozenset({"build", "infer", "replay", "convert"})  # the commands that import the kernel
OFF = "ZONEGRAPH_NO_SERVER"
DIRECTORY = "ZONEGRAPH_SERVER_DIR"
_HEADER = struct.Struct("!I")


def directory() -> str:
    """The private folder of this user's servers: ``$ZONEGRAPH_SERVER_DIR``, else
    ``$XDG_RUNTIME_DIR/zonegraph``, else ``zonegraph-<uid>`` in ``$TMPDIR`` or ``/tmp``."""
    chosen = os.environ.get(DIRECTORY)
    if chosen:
        return chosen
    runtime = os.environ.get("XDG_RUNTIME_DIR")
    if runtime:
        return os.path.join(runtime, "zonegraph")
    return os.path.join(os.environ.get("TMPDIR") or "/tmp", f"zonegraph-{os.getuid()}")


def fingerprint() -> str:
    """What a server's code is: the interpreter, the distributions installed beside it (their
    folders' names carry their versions) and this package's files (path, size, modification)."""
    digest = hashlib.sha256(sys.executable.encode())
    for entry in sys.path:
        if entry.endswith("-packages") and os.path.isdir(entry):
            digest.update(" ".join(sorted(n for n in os.listdir(entry) if n.endswith("-info"))).encode())
    files = []
    for folder, _, names in os.walk(os.path.dirname(os.path.abspath(__file__))):
        files += [os.path.join(folder, n) for n in names if n.endswith(".py")]
    for path in sorted(files):
        info = os.stat(path)
        digest.update(f"{path}:{info.st_size}:{info.st_mtime_ns}".encode())
    return digest.hexdigest()[:16]


def socket_path() -> str:
    """Where the server of this code listens, if one runs."""
    return os.path.join(directory(), f"{fingerprint()}.sock")


def send(sock: socket.socket, message: dict[str, Any], fds: Sequence[int] = ()) -> None:
    """One framed message, with ``fds`` attached to its first bytes."""
    data = json.dumps(message).encode()
    framed = _HEADER.pack(len(data)) + data
    if fds:
        framed = framed[socket.send_fds(sock, [framed], list(fds)) :]
    if framed:  # an empty send to a peer that has read and closed would fail
        sock.sendall(framed)


def receive(sock: socket.socket, max_fds: int = 0) -> tuple[dict[str, Any] | None, list[int]]:
    """One framed message and the descriptors sent with it; None when the peer closed first."""
    data, fds = b"", list[int]()
    while len(data) < _HEADER.size or len(data) < _HEADER.size + _HEADER.unpack_from(data)[0]:
        if max_fds and not fds:
            chunk, got, _, _ = socket.recv_fds(sock, 65536, max_fds)
            fds = list(got)
        else:
            chunk = sock.recv(65536)
        if not chunk:
            for fd in fds:
                os.close(fd)
            return None, []
        data += chunk
    return json.loads(data[_HEADER.size :]), fds


def connect(path: str, timeout: float | None = None) -> socket.socket | None:
    """A connection to the server at ``path``, or None where none listens (or a stale file)."""
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    sock.settimeout(timeout)
    try:
        sock.connect(path)
    except OSError:
        sock.close()
        return None
    return sock


def ask(op: str, path: str | None = None, timeout: float = 10.0) -> dict[str, Any] | None:
    """The server's answer to ``status`` or ``stop``; None when no server of this code runs."""
    sock = connect(path or socket_path(), timeout)
    if sock is None:
        return None
    with sock:
        send(sock, {"op": op})
        answer, _ = receive(sock)
    return answer


def forward(argv: Sequence[str]) -> int | None:
    """Run ``zonegraph ARGV`` in the warm server and return its exit status; None when no server
    of this code runs (or ``ZONEGRAPH_NO_SERVER`` is set): the caller then runs it itself."""
    if os.environ.get(OFF):
        return None
    path = socket_path()
    sock = connect(path) if os.path.exists(path) else None
    if sock is None:
        return None
    with sock:
        umask = os.umask(0o022)
        os.umask(umask)
        call = {"op": "run", "argv": list(argv), "cwd": os.getcwd(), "env": dict(os.environ), "umask": umask}
        send(sock, call, (0, 1, 2))
        started, _ = receive(sock)
        if started is None or "pid" not in started:
            return None
        with _ForwardingSignals(started["pid"]):
            ended, _ = receive(sock)
    if ended is None:
        print(f"zonegraph: error: the server ({path}) ended during the call (a bug)", file=sys.stderr)
        return 1
    return int(ended["rc"])


class _ForwardingSignals:
    """Ctrl-C, hang-up and termination of the caller go to the call's process group instead."""

    SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)

    def __init__(self, pid: int) -> None:
        self.pid = pid
        self.saved: dict[int, Any] = {}

    def _pass_on(self, signum: int, _frame: object) -> None:
        try:
            os.killpg(self.pid, signum)
        except ProcessLookupError:
            pass

    def __enter__(self) -> None:
        self.saved = {s: signal.signal(s, self._pass_on) for s in self.SIGNALS}

    def __exit__(self, *_exc: object) -> None:
        for s, handler in self.saved.items():
            signal.signal(s, handler)
