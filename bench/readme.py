"""The headline results of the README and the site's front page, written from the figure files
the corpus benchmark left.

    python -m bench.readme [--check]

Each page names the figures it quotes in a marker, ``<!-- results: tuning-SHA validation-SHA
-->``, and holds the table drawn from them up to ``<!-- results: end -->``; this command redraws
those tables (``--check``: exits 1 when a page's table is not the one its figures give). The
newest figure of each sample is the one whose commit comes last in the history; a test checks
that the README names those, so a re-run of the benchmark cannot leave an old number on the
front page.
"""

from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
PAGES = (README, ROOT / "docs" / "index.md")
FIGURES = ROOT / "docs" / "figures"
BLOCK = re.compile(r"(<!-- results:((?:\s+[\w.-]+)+)\s*-->\n)(.*?)(<!-- results: end -->)", re.S)
SAMPLES = {
    "tuning": "steered the work",
    "validation": "never tuned on; one design opened at 6a6cb54",
    "fresh": "never tuned on; 5 of its parts opened in earlier diagnoses",
}
LONG = ("06_11to15ops", "07_16to20ops")  # the folders the headline shows beside the total


def _rate(exact: int, of: int) -> str:
    return f"{exact} / {of} ({exact / of:.1%})" if of else "-"


def _seed(command: str) -> str:
    found = re.search(r"--seed (\d+)", command)
    return found.group(1) if found else "0"


def table(names: list[str]) -> str:
    """The headline table of the named corpus figures, one row each."""
    lines = [
        "| sample | converted, of drawn | exact, of converted | 11-15 operations | 16-20 operations |",
        "|---|---|---|---|---|",
    ]
    for name in names:
        record = json.loads((FIGURES / f"{name}.json").read_text())
        figure, sample = record["figure"], name.split("-")[0]
        label = f"{sample} (seed {_seed(record['command'])}, {SAMPLES.get(sample, 'a sample')})"
        folders = [figure["folders"].get(f) for f in LONG]
        every = figure["all"]
        cells = [f"{every['converted']} / {every['drawn']}", _rate(every["exact"], every["converted"])]
        cells += [_rate(g["exact"], g["converted"]) if g else "(none)" for g in folders]
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def render(text: str) -> str:
    """The README with its results table drawn again from the figures its marker names."""
    found = BLOCK.search(text)
    if found is None:
        raise ValueError(f"{README}: no <!-- results: ... --> ... <!-- results: end --> block")
    return text[: found.start(3)] + table(found.group(2).split()) + text[found.start(4) :]


def named(text: str) -> list[str]:
    """The figures the README's marker names."""
    found = BLOCK.search(text)
    return found.group(2).split() if found else []


def newest(sample: str) -> str | None:
    """The figure of ``sample`` (``tuning``, ``validation``, ``fresh``) whose commit is the newest in the
    history, or None where none of their commits is in it."""
    history = subprocess.run(["git", "rev-list", "HEAD"], cwd=ROOT, capture_output=True, text=True)
    order = history.stdout.split()
    rank = {sha[:7]: i for i, sha in enumerate(order)}
    commits = {p.stem: json.loads(p.read_text())["commit"][:7] for p in FIGURES.glob(f"{sample}-*.json")}
    known = {name: rank[c] for name, c in commits.items() if c in rank}
    return min(known, key=lambda n: known[n]) if known else None


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="exit 1 if a page's table is stale")
    args = parser.parse_args()
    stale = False
    for page in PAGES:
        text = page.read_text()
        fresh = render(text)
        stale |= fresh != text
        if not args.check:
            page.write_text(fresh)
            print(f"{page}: results from {', '.join(named(text))}")
    if args.check:
        sys.exit(1 if stale else 0)


if __name__ == "__main__":
    main()
