"""``zonegraph`` and ``python -m zonegraph``: a command that imports the geometry kernel is handed
to a warm server of this code where one runs (`zonegraph.handoff`); anything else, or with no
server, runs here (`zonegraph.cli`)."""

from __future__ import annotations

import sys

from zonegraph.handoff import FORWARDED, forward


def main() -> int:
    argv = sys.argv[1:]
    if argv and argv[0] in FORWARDED:
        status = forward(argv)
        if status is not None:
            return status
    from zonegraph.cli import main as command_line

    return command_line()


if __name__ == "__main__":
    sys.exit(main())
