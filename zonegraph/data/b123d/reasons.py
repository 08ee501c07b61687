"""One-line reasons: what a failed design's row says about an exception."""

from __future__ import annotations


def one_line(exc: BaseException, limit: int = 200) -> str:
    """The exception's message on one line, cut to ``limit`` characters."""
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= limit else text[: limit - 3] + "..."
