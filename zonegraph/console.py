"""Capture what native code prints: OpenCASCADE writes messages such as ``**** ERR StepFile :
Undefined Parsing: Line 101: Incorrect syntax`` from C++ straight to file descriptor 1, below
Python's ``sys.stdout``, so only redirecting the descriptor keeps them off the user's terminal."""

from __future__ import annotations

import os
import sys
import tempfile
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass


@dataclass
class Captured:
    """The text printed while a `captured` block ran (filled in when it ends)."""

    text: str = ""

    def kernel_errors(self) -> list[str]:
        """OpenCASCADE's error lines, without their ``****`` frame and colour codes."""
        lines = (line.replace("\x1b[31;1m", "").replace("\x1b[0m", "") for line in self.text.splitlines())
        return [" ".join(line.strip("* ").split()) for line in lines if "ERR" in line]


@contextmanager
def captured() -> Iterator[Captured]:
    """File descriptors 1 and 2, and Python's warnings, go to a scratch file for the duration."""
    sys.stdout.flush()
    sys.stderr.flush()
    result = Captured()
    saved = [os.dup(1), os.dup(2)]
    with tempfile.TemporaryFile() as sink, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        os.dup2(sink.fileno(), 1)
        os.dup2(sink.fileno(), 2)
        try:
            yield result
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)
            sink.seek(0)
            result.text = sink.read().decode(errors="replace")
