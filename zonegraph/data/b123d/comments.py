"""Facts the scripts state only in comments: where each Fusion feature starts, its operation."""

from __future__ import annotations

import re
from dataclasses import dataclass

FEATURE_RE = re.compile(
    r"^\s*#\s*(?P<sketch>.+?)\s*->\s*(?P<name>.+?)\s*\((?P<op>NewBody|Join|Cut|Intersect)\)\s*$"
)
EXTENT_RE = re.compile(r"^\s*#\s*(OneSide|Symmetric|TwoSides)\b.*extrude")
FULL_LENGTH_RE = re.compile(r"full_length\s*=\s*True")


@dataclass(frozen=True)
class FeatureComment:
    """A ``# Sketch2 -> Extrude2 (Join)`` comment: where a Fusion feature starts in the source."""

    line: int
    sketch: str
    name: str
    operation: str  # NewBody / Join / Cut / Intersect
    full_length: bool  # the extent comment says Symmetric with is_full_length=True


def feature_comments(lines: list[str], start: int, end: int) -> list[FeatureComment]:
    """The feature comments of the function spanning 1-based source lines ``start``..``end``."""
    out: list[FeatureComment] = []
    for no in range(start, min(end, len(lines)) + 1):
        m = FEATURE_RE.match(lines[no - 1])
        if m:
            out.append(FeatureComment(no, m["sketch"], m["name"], m["op"], False))
        elif out and EXTENT_RE.match(lines[no - 1]) and FULL_LENGTH_RE.search(lines[no - 1]):
            last = out[-1]
            out[-1] = FeatureComment(last.line, last.sketch, last.name, last.operation, True)
    return out
