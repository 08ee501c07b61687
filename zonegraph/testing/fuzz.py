"""The fuzz harness of issue 14: mutated real inputs through the CLI, each run classified.

Shared by ``bench/fuzz_bench.py`` (1,000 inputs), ``tests/test_fuzz.py`` (a fast slice) and the
pipeline's fuzz test (``tests/pipelines/test_fuzz_stages.py``), so that there is one definition
of the inputs and of the contract:

- Inputs: the real design JSON of ``../shared/data/fusion360_samples``, STEP files made by
  replaying them, and one-model batches of the build123d corpus (``zonegraph convert``'s input),
  each with one mutation drawn by a Hypothesis strategy (seeded, derandomized).
- Runner: ``zonegraph.cli.main`` in a forked child of this (fresh) process, its fds 1 and 2
  redirected to files, so that OpenCASCADE's C-level prints are seen too. A fork, not an alarm:
  a hang inside C code (or a dead lock in the CLI parent) never returns to the interpreter, so a
  signal handler in this process could not stop it, while a child's process group can be killed.
- Classification: exactly one outcome per input; ``success``, ``user_error`` and ``timeout`` keep
  the contract, ``VIOLATIONS`` break it.
"""

from __future__ import annotations

import copy
import json
import math
import os
import re
import shutil
import signal
import sys
import tempfile
import time
import traceback
import zlib
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import asdict, dataclass, field
from functools import cache
from pathlib import Path
from typing import Any, TypeVar

from hypothesis import HealthCheck, Phase, given, seed, settings
from hypothesis import strategies as st

from zonegraph.outputs import LISTING
from zonegraph.testing.locations import CORPUS, SAMPLES, SKIP_REASON

__all__ = [
    "GOOD",
    "OUTCOMES",
    "SAMPLES",
    "SKIP_REASON",
    "VIOLATIONS",
    "Case",
    "Row",
    "classify",
    "fuzz",
    "mutated_designs",
]

T = TypeVar("T")

GOOD = ("success", "user_error", "timeout")
VIOLATIONS = ("hang", "traceback", "noise", "partial_output")  # in order of precedence
OUTCOMES = GOOD + VIOLATIONS
HANG_GRACE_S = 30.0  # a run longer than --timeout plus this is a hang
BUDGET_S = 0.5  # infer's search budget: the contract, not the search, is under test

# What a complete success leaves in --out (build's graph files: zonegraph/zones/storage.py, plus
# the zones.ply the CLI asks for).
COMPLETE = {
    "replay": ("summary.json", "final.step"),
    "build": (
        "zones.parquet",
        "faces.parquet",
        "links.parquet",
        "surfaces.parquet",
        "samples.parquet",
        "zones.brep",
        "zones.ply",
    ),
    "infer": ("result.json",),
    "convert": ("summary.json",),
}
# The command's own stdout lines on success; anything else on stdout or stderr is noise.
OWN_LINES = {
    "replay": (r"\S.*: \d+ extrudes?, \d+ bod(y|ies), ", r"  vs the file's properties: "),
    "build": (r"\S.*: status \w+, \d+ zones? ", r"  built in "),
    "infer": (r"\S.*: \w+, (\d+ steps? |no step, )", r"  \d+ zones?, build ", r"  why: "),
    "convert": (r"\S+: \d+/\d+ converted$", r"converted \d+ of \d+ designs -> "),
}
CONVERT_ROW = re.compile(r"zonegraph: \S.*: \w+: (\w+): \S")  # a design's row: batch, id, status, reason
ERROR_PREFIX = "zonegraph: error:"
INTERNAL = re.compile(r"\(\w+\.py:\d+\)")  # an exception's file:line passed off as a user error
KERNEL = re.compile(r"\*\*\*\*|warning", re.IGNORECASE)  # OpenCASCADE's messages, Python's warnings

# Replacement values for a JSON value: every kind a schema must reject or survive.
VALUES: dict[str, Any] = {
    "nan": math.nan,
    "inf": math.inf,
    "-inf": -math.inf,
    "huge": 1e12,
    "huger": 1e300,
    "bigint": 10**40,
    "tiny": 1e-12,
    "denormal": 5e-324,
    "negative": -1.0,
    "zero": 0,
    "string": "zonegraph",
    "empty_string": "",
    "null": None,
    "list": [1, 2],
    "empty_list": [],
    "dict": {"a": 1},
    "empty_dict": {},
    "true": True,
    "false": False,
}
TYPE_KEYS = ("type", "operation", "extent_type")
ODD_TYPES = ("FilletFeature", "RevolveFeature", "NewComponentFeatureOperation", "Bogus", "")
EXTENT_KEYS = {"start_extent", "extent_one", "extent_two"}
EXTRUDE_KEYS = {"profiles", "operation", "start_extent", "extent_type", "extent_one", "extent_two", "type"}
IGNORED_KEYS = {"curves", "points", "constraints", "dimensions"}  # sketch data replay does not read
STEP_TOKENS = ("1.E+300", "-1.E+300", "0.", "1.E-300", "NAN", "INF", "1.2.3", "'x'", "$", "*")
UNITS = (
    "SI_UNIT(.KILO.,.METRE.)",
    "SI_UNIT(.NANO.,.METRE.)",
    "SI_UNIT($,.RADIAN.)",
    "SI_UNIT($,.BOGUS.)",
    "",
)
LENGTH_UNIT = re.compile(rb"SI_UNIT\((?:\.\w+\.|\$),\.METRE\.\)")


@dataclass(frozen=True)
class Case:
    """One fuzz input: a command, the real file it starts from and one mutation (plain data)."""

    command: str
    kind: str  # "json" or "step"
    source: str  # the sample's stem
    mutation: dict[str, Any]

    def label(self) -> str:
        m = {k: v for k, v in self.mutation.items() if k != "op"}
        return f"{self.mutation['op']}({', '.join(f'{k}={v!r}' for k, v in m.items())})"


@dataclass
class Row:
    """One run: what was run, how it ended and why it is classified so."""

    index: int
    command: str
    kind: str
    source: str
    mutation: str
    argv: list[str]
    outcome: str = ""
    violations: list[str] = field(default_factory=list)
    exit: int | None = None
    seconds: float = 0.0
    detail: str = ""
    stdout: str = ""
    stderr: str = ""
    left: list[str] = field(default_factory=list)


# ---------------------------------------------------------------- inputs


@cache
def sample_texts() -> dict[str, bytes]:
    """The real design JSON files, by stem (their bytes: truncation and UTF-8 damage act on these)."""
    return {p.stem: p.read_bytes() for p in sorted(SAMPLES.glob("*.json"))}


@cache
def design(name: str) -> Any:
    return json.loads(sample_texts()[name])


def _walk(node: Any, path: tuple) -> Iterator[tuple]:
    yield path
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for key, child in items:
        yield from _walk(child, path + (key,))


@cache
def value_paths(name: str) -> dict[str, tuple[tuple, ...]]:
    """A design's paths by region: ``extent`` (the extrudes' distances, tapers and offsets),
    ``extrude`` (the ExtrudeFeature fields replay reads: extents, operation, profile references),
    ``transform`` (sketch frames), ``profile`` (profile loops and curves),
    ``read`` (all that replay reads: the timeline, entities without the sketch data it ignores) and
    ``any`` (every path, the root last: Hypothesis favours a pool's first item). Regions are drawn
    first, so that the few fields where a bad number hurts most are not drowned by curve points."""
    doc = design(name)
    paths = tuple(_walk(doc, ()))[1:] + ((),)
    read = tuple(
        p for p in paths if p[:1] in (("timeline",), ("entities",)) and not IGNORED_KEYS.intersection(p)
    )
    extrudes = {k for k, e in doc.get("entities", {}).items() if e.get("type") == "ExtrudeFeature"}
    extrude = tuple(p for p in read if len(p) > 2 and p[1] in extrudes and p[2] in EXTRUDE_KEYS)
    return {
        "extent": tuple(p for p in extrude if p[2] in EXTENT_KEYS and p[-1] == "value"),
        "extrude": extrude,
        "transform": tuple(p for p in read if "transform" in p),
        "profile": tuple(p for p in read if "profiles" in p and p[1] not in extrudes),
        "read": read,
        "any": paths,
    }


@cache
def type_paths(name: str) -> tuple[tuple, ...]:
    return tuple(p for p in value_paths(name)["any"] if p and p[-1] in TYPE_KEYS)


@cache
def known_types() -> tuple[str, ...]:
    """Every string the samples hold under a type key, and a few they do not."""
    found = {_get(design(n), p) for n in sample_texts() for p in type_paths(n)}
    return tuple(sorted(v for v in found if isinstance(v, str))) + ODD_TYPES


def _get(node: Any, path: tuple) -> Any:
    for key in path:
        node = node[key]
    return node


def spread(items: Sequence[T], salt: str = "") -> st.SearchStrategy[T]:
    """One of ``items``, close to uniformly. ``sampled_from`` draws its first item far more often
    (Hypothesis's simplest choice; ``docs/results/evidence.md`` has a run where it dominated), so
    the index is a wide integer, offset by a hash of ``salt`` (the design), modulo the length."""
    offset = zlib.crc32(salt.encode())
    return st.integers(0, 2**20).map(lambda i: items[(i + offset) % len(items)])


@st.composite
def json_mutations(draw: st.DrawFn) -> dict[str, Any]:
    """One mutation of a design: a value replaced or deleted, the timeline edited, a type changed,
    the text truncated or its UTF-8 broken."""
    name = draw(st.sampled_from(sorted(sample_texts())))
    op = draw(
        st.sampled_from(("replace", "replace", "replace", "delete", "timeline", "type", "truncate", "utf8"))
    )
    if op in ("replace", "delete"):
        regions = value_paths(name)
        pool = regions[draw(spread(("extent", "extrude", "transform", "profile", "read", "any"), name))]
        if op == "delete":
            pool = tuple(p for p in pool if p) or pool
        path = draw(spread(pool, name))
        if op == "delete":
            return {"op": op, "design": name, "path": list(path)}
        return {
            "op": op,
            "design": name,
            "path": list(path),
            "value": draw(spread(tuple(VALUES), f"{name}{path}")),
        }
    if op == "timeline":
        n = len(design(name)["timeline"])
        edit = draw(spread(("drop", "duplicate", "reorder", "empty"), name))
        if edit == "reorder":
            return {"op": op, "design": name, "edit": edit, "order": draw(st.permutations(range(n)))}
        return {"op": op, "design": name, "edit": edit, "item": draw(st.integers(0, n - 1))}
    if op == "type":
        path = draw(spread(type_paths(name), name))
        return {
            "op": op,
            "design": name,
            "path": list(path),
            "value": draw(spread(known_types(), f"{name}{path}")),
        }
    size = len(sample_texts()[name])
    at = draw(st.integers(0, size - 1))
    if op == "truncate":
        return {"op": op, "design": name, "at": at}
    return {
        "op": op,
        "design": name,
        "at": at,
        "bytes": draw(spread(("ff", "c328", "e9", "fffe", "80"), name)),
    }


def _set(doc: Any, path: list, value: Any) -> Any:
    if not path:
        return value
    _get(doc, tuple(path[:-1]))[path[-1]] = value
    return doc


def _negated(old: Any) -> Any:
    return -old if isinstance(old, int | float) and not isinstance(old, bool) and old else -1.0


def apply_json(m: dict[str, Any]) -> bytes:
    """The mutated design file's bytes (json.dump writes NaN and Infinity as tokens, which
    Python's json reads back: what a careless exporter would write)."""
    op, text = m["op"], sample_texts()[m["design"]]
    if op == "truncate":
        return text[: m["at"]]
    if op == "utf8":
        return text[: m["at"]] + bytes.fromhex(m["bytes"]) + text[m["at"] :]
    doc = copy.deepcopy(design(m["design"]))
    if op == "replace":
        value = _negated(_get(doc, tuple(m["path"]))) if m["value"] == "negative" else VALUES[m["value"]]
        doc = _set(doc, m["path"], copy.deepcopy(value))
    elif op == "delete":
        del _get(doc, tuple(m["path"][:-1]))[m["path"][-1]]
    elif op == "type":
        doc = _set(doc, m["path"], m["value"])
    else:
        doc["timeline"] = _edit_timeline(doc["timeline"], m)
    return json.dumps(doc).encode()


def _edit_timeline(items: list, m: dict[str, Any]) -> list:
    if m["edit"] == "empty":
        return []
    if m["edit"] == "reorder":
        return [items[i] for i in m["order"]]
    i = m["item"]
    return items[:i] + items[i + 1 :] if m["edit"] == "drop" else items[: i + 1] + items[i:]


@st.composite
def step_mutations(draw: st.DrawFn, steps: dict[str, bytes]) -> dict[str, Any]:
    """One mutation of a STEP file: bytes or lines damaged, the units line swapped, a number made
    absurd, the data section dropped, or no file content at all."""
    name = draw(st.sampled_from(sorted(steps)))
    text = steps[name]
    lines = text.count(b"\n") + 1
    op = draw(
        st.sampled_from(
            (
                "truncate",
                "flip",
                "insert",
                "delete",
                "drop_line",
                "dup_line",
                "swap_lines",
                "units",
                "number",
                "header_only",
                "empty",
                "garbage",
            )
        )
    )
    m: dict[str, Any] = {"op": op, "part": name}
    if op in ("truncate", "flip", "insert", "delete"):
        m["at"] = draw(st.integers(0, len(text) - 1))
    if op == "flip":
        m["xor"] = draw(st.integers(1, 255))
    if op == "insert":
        m["bytes"] = draw(st.binary(min_size=1, max_size=16)).hex()
    if op == "delete":
        m["count"] = draw(st.integers(1, 64))
    if op in ("drop_line", "dup_line", "swap_lines"):
        m["line"] = draw(st.integers(0, lines - 1))
    if op == "swap_lines":
        m["other"] = draw(st.integers(0, lines - 1))
    if op == "units":
        m["unit"] = draw(spread(UNITS, name))
    if op == "number":
        m["nth"] = draw(st.integers(0, 500))
        m["token"] = draw(spread(STEP_TOKENS, name))
    if op == "garbage":
        m["bytes"] = draw(st.binary(min_size=1, max_size=200)).hex()
    return m


NUMBER = re.compile(rb"(?<![\w.#])-?\d+\.\d*(?:E[+-]?\d+)?")


def apply_step(m: dict[str, Any], text: bytes) -> bytes:
    """The mutated STEP file's bytes."""
    op = m["op"]
    at = m.get("at", 0)
    if op in ("empty", "garbage"):
        return bytes.fromhex(m.get("bytes", ""))
    if op == "truncate":
        return text[:at]
    if op == "flip":
        return text[:at] + bytes([text[at] ^ m["xor"]]) + text[at + 1 :]
    if op == "insert":
        return text[:at] + bytes.fromhex(m["bytes"]) + text[at:]
    if op == "delete":
        return text[:at] + text[at + m["count"] :]
    if op == "header_only":
        return text[: text.find(b"DATA;")] + b"DATA;\nENDSEC;\nEND-ISO-10303-21;\n"
    if op == "units":
        return LENGTH_UNIT.sub(m["unit"].encode(), text)
    if op == "number":
        found = list(NUMBER.finditer(text))
        hit = found[m["nth"] % len(found)]
        return text[: hit.start()] + m["token"].encode() + text[hit.end() :]
    lines = text.split(b"\n")
    i = m["line"]
    if op == "drop_line":
        del lines[i]
    elif op == "dup_line":
        lines.insert(i, lines[i])
    else:
        j = m["other"]
        lines[i], lines[j] = lines[j], lines[i]
    return b"\n".join(lines)


# Small designs of the corpus's first batch (none of them in a held-out sample), each cut out as
# a batch of its own: ``convert`` of a whole 166-model batch would cost minutes per input.
CORPUS_MODELS = (
    "100243_9fb796fe_0005",
    "100243_9fb796fe_0006",
    "100877_ac1e5a17_0001",
    "100877_ac1e5a17_0017",
    "101427_a9bcb09c_0002",
)
# Statements put first in a model's body: what a hostile or broken script does.
HOSTILE = (
    "while True: pass",
    "import os; os._exit(0)",
    "import sys; sys.exit(3)",
    "raise SystemExit",
    "import os, signal; os.kill(os.getpid(), signal.SIGSEGV)",
    "hoard = [bytes(64 << 20) for _ in iter(int, 1)]",
    "return None",
    "return 42",
    "1 / 0",
    "raise KeyboardInterrupt",
    "import sys; sys.setrecursionlimit(10**6); f = lambda: f(); f()",
)
SCRIPT_TOKENS = ("1e300", "-1e300", "0", "1e-300", "float('nan')", "float('inf')", "-1", "'x'", "None")
CONVERT_MEMORY_MB = 1024  # a model that allocates without bound stops here (out_of_memory)


@cache
def script_texts() -> dict[str, bytes]:
    """One batch file per `CORPUS_MODELS` design: the batch's imports, the model's function
    and its ``MODELS`` entry (Fusion's volume and area); empty without the corpus."""
    batch = CORPUS / "01_2ops" / "batch_001.py"
    if not batch.is_file():
        return {}
    text = batch.read_text(encoding="utf-8")
    header = text[: text.index("\ndef model_")]
    out = {}
    for design_id in CORPUS_MODELS:
        start = text.index(f"\ndef model_{design_id}()")
        end = re.compile(r"\n(# Description|def |MODELS)").search(text, start + 1)
        entry = next(line for line in text.splitlines() if line.lstrip().startswith(f'"model_{design_id}"'))
        body = text[start : end.start() if end else len(text)]
        out[design_id] = f"{header}\n{body}\n\nMODELS = {{\n{entry}\n}}\n".encode()
    return out


@st.composite
def script_mutations(draw: st.DrawFn) -> dict[str, Any]:
    """One mutation of a one-model batch: bytes or lines damaged, a number made absurd, a hostile
    statement first in the model, random bytes, or nothing at all."""
    name = draw(st.sampled_from(sorted(script_texts())))
    text = script_texts()[name]
    op = draw(
        st.sampled_from(
            (
                "hostile",
                "hostile",
                "truncate",
                "flip",
                "insert",
                "drop_line",
                "dup_line",
                "number",
                "garbage",
                "empty",
            )
        )
    )
    m: dict[str, Any] = {"op": op, "model": name}
    if op in ("truncate", "flip", "insert"):
        m["at"] = draw(st.integers(0, len(text) - 1))
    if op == "flip":
        m["xor"] = draw(st.integers(1, 255))
    if op == "insert":
        m["bytes"] = draw(st.binary(min_size=1, max_size=16)).hex()
    if op in ("drop_line", "dup_line"):
        m["line"] = draw(st.integers(0, text.count(b"\n")))
    if op == "number":
        m["nth"] = draw(st.integers(0, 200))
        m["token"] = draw(spread(SCRIPT_TOKENS, name))
    if op == "hostile":
        m["statement"] = draw(spread(HOSTILE, name))
    if op == "garbage":
        m["bytes"] = draw(st.binary(min_size=1, max_size=200)).hex()
    return m


SCRIPT_NUMBER = re.compile(rb"(?<![\w.])-?\d+(?:\.\d+)?")


def apply_script(m: dict[str, Any]) -> bytes:
    """The mutated batch file's bytes."""
    op, text = m["op"], script_texts()[m["model"]]
    if op in ("empty", "garbage"):
        return bytes.fromhex(m.get("bytes", ""))
    if op == "hostile":
        head = f"def model_{m['model']}():\n".encode()
        at = text.index(head) + len(head)
        return text[:at] + f"    {m['statement']}\n".encode() + text[at:]
    if op == "number":
        found = list(SCRIPT_NUMBER.finditer(text))
        hit = found[m["nth"] % len(found)]
        return text[: hit.start()] + m["token"].encode() + text[hit.end() :]
    return apply_step(m, text)  # the byte and line edits are the STEP file's


@st.composite
def fuzz_cases(draw: st.DrawFn, steps: dict[str, bytes], scripts: bool = False) -> Case:
    """A command on a mutated design JSON (replay, build, infer; two draws in three) or on a mutated
    STEP file (build, infer); with ``scripts``, ``convert`` of a mutated batch when an integer in
    0..4 draws 0 (more often than one in five: Hypothesis favours 0)."""
    if scripts and script_texts() and not draw(st.integers(0, 4)):
        m = draw(script_mutations())
        return Case("convert", "script", m["model"], m)
    if not steps or draw(st.integers(0, 2)):
        m = draw(json_mutations())
        return Case(draw(st.sampled_from(("replay", "build", "infer"))), "json", m["design"], m)
    m = draw(step_mutations(steps))
    return Case(draw(st.sampled_from(("build", "infer"))), "step", m["part"], m)


@contextmanager
def seed_only() -> Iterator[None]:
    """Draws that depend on the seed alone. Hypothesis (6.131 on) takes a share of its integers,
    strings and bytes from the literals in the source of every local module loaded, so any edit of
    a literal anywhere in the project would shift the harness's inputs and a before/after pair of
    runs could not be compared input by input. The pool is emptied while cases are drawn (an
    internal of Hypothesis: left alone where a version lacks it)."""
    from hypothesis.internal.conjecture import providers

    original = getattr(providers, "_get_local_constants", None)
    if original is None or not hasattr(providers, "Constants"):
        yield
        return
    providers._get_local_constants = providers.Constants
    providers.CONSTANTS_CACHE.cache.clear()
    try:
        yield
    finally:
        providers._get_local_constants = original
        providers.CONSTANTS_CACHE.cache.clear()


def draw_cases(count: int, seed_value: int, strategy: st.SearchStrategy[Case]) -> list[Case]:
    """``count`` distinct cases, the same for the same seed: Hypothesis's generate phase only
    (no database, no shrinking), derandomized, seeded and blind to the project's source
    (`seed_only`)."""
    found: dict[str, Case] = {}

    @seed(seed_value)
    @settings(
        max_examples=4 * count + 50,
        derandomize=True,
        database=None,
        phases=[Phase.generate],
        deadline=None,
        suppress_health_check=list(HealthCheck),
        print_blob=False,
    )
    @given(strategy)
    def collect(case: Case) -> None:
        if len(found) < count:
            found.setdefault(json.dumps(asdict(case), sort_keys=True, default=str), case)

    with seed_only():
        collect()
    return list(found.values())


# ---------------------------------------------------------------- running


def warm_up() -> None:
    """Import what the commands import lazily, once, here: every forked child inherits it instead
    of importing the kernel again. Nothing here runs geometry (this process must never run an
    OpenCASCADE Boolean: forking after a threaded Boolean can hang a child)."""
    import build123d  # noqa: F401 - convert's parent imports it for its children

    import zonegraph.batch  # noqa: F401
    import zonegraph.isolation  # noqa: F401
    import zonegraph.jobs  # noqa: F401
    import zonegraph.reconstruction  # noqa: F401
    from zonegraph.plugins import guide_factory

    guide_factory("heuristic")


def argv_for(command: str, target: Path, out: Path, timeout: float) -> list[str]:
    argv = [command, str(target), "--out", str(out), "--timeout", f"{timeout:g}"]
    if command == "convert":
        return argv + ["--memory", str(CONVERT_MEMORY_MB)]
    return argv + ["--budget", f"{BUDGET_S:g}"] if command == "infer" else argv


def _child(argv: list[str], io: Path) -> None:
    """The forked child: fds 1 and 2 to files, ``main`` in-process, its exit code or escaped
    exception to ``io/exit.json``; never returns."""
    code = 70
    try:
        os.setpgid(0, 0)  # its own process group: the watchdog kills the CLI's children with it
        for fd, name in ((1, "stdout"), (2, "stderr")):
            f = os.open(io / name, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
            os.dup2(f, fd)
            os.close(f)
        from zonegraph.cli import main

        try:
            result: dict[str, Any] = {"rc": main(argv)}
        except BaseException as exc:  # the contract says none escapes main: record which did
            traceback.print_exc()
            result = {"exception": f"{type(exc).__name__}: {exc}"[:500]}
        sys.stdout.flush()
        sys.stderr.flush()
        (io / "exit.json").write_text(json.dumps(result))
        code = 0
    finally:
        os._exit(code)


def run_argv(argv: list[str], io: Path, limit_s: float) -> tuple[dict[str, Any] | None, float]:
    """``main(argv)`` in a forked child killed (its whole process group) after ``limit_s``;
    returns what it wrote to exit.json (None after a kill or a crash) and the seconds it took."""
    sys.stdout.flush()
    sys.stderr.flush()  # else the child inherits unwritten buffers and prints them again
    t0 = time.perf_counter()
    pid = os.fork()
    if pid == 0:
        _child(argv, io)
    hung = not _wait(pid, t0 + limit_s)
    seconds = time.perf_counter() - t0
    _kill_group(pid)
    if hung:
        os.waitpid(pid, 0)
        return {"hang": True}, seconds
    exit_file = io / "exit.json"
    return (json.loads(exit_file.read_text()) if exit_file.is_file() else None), seconds


def _wait(pid: int, deadline: float) -> bool:
    """Reap ``pid``; False if it is still running at ``deadline``."""
    pause = 0.002
    while time.perf_counter() < deadline:
        done, _ = os.waitpid(pid, os.WNOHANG)
        if done:
            return True
        time.sleep(pause)
        pause = min(2 * pause, 0.05)
    return False


def _kill_group(pid: int) -> None:
    """Kill whatever is left in the child's process group (a CLI child it left behind)."""
    try:
        os.killpg(pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass


def run_case(
    case: Case, index: int, steps: dict[str, bytes], timeout: float, keep: Path | None = None
) -> Row:
    """Write the mutated input, run its command on a fresh ``--out`` in a fresh parent folder, and
    classify it; ``keep`` receives the input file of a violation (to reproduce it)."""
    if case.kind == "script":
        data = apply_script(case.mutation)
    elif case.kind == "json":
        data = apply_json(case.mutation)
    else:
        data = apply_step(case.mutation, steps[case.source])
    work = Path(tempfile.mkdtemp(prefix="zg-fuzz-"))
    try:
        io, parent = work / "io", work / "parent"
        io.mkdir()
        parent.mkdir()
        target = io / {"json": "design.json", "step": "part.step", "script": "batch_001.py"}[case.kind]
        target.write_bytes(data)
        out = parent / "out"
        row = Row(
            index,
            case.command,
            case.kind,
            case.source,
            case.label(),
            argv_for(case.command, target, out, timeout),
        )
        result, row.seconds = run_argv(row.argv, io, timeout + HANG_GRACE_S)
        row.stdout, row.stderr = _text(io / "stdout"), _text(io / "stderr")
        classify(row, result, parent, out)
        if keep is not None and row.outcome in VIOLATIONS:
            keep.mkdir(parents=True, exist_ok=True)
            shutil.copy(target, keep / f"{index:04d}{target.suffix}")
        return row
    finally:
        shutil.rmtree(work, ignore_errors=True)


def _text(path: Path, limit: int = 4000) -> str:
    return path.read_bytes()[:limit].decode(errors="replace") if path.is_file() else ""


# ---------------------------------------------------------------- classification


def classify(row: Row, result: dict[str, Any] | None, parent: Path, out: Path) -> None:
    """Every violation the run shows, and its outcome: the first violation by precedence, else
    success, timeout or user error."""
    row.exit = result.get("rc") if result else None
    err = row.stderr.splitlines()
    errors = [line for line in err if line.startswith(ERROR_PREFIX)]
    if row.command == "convert":  # its one line per failed design stands for the error line
        errors = errors or [f"{ERROR_PREFIX} {line[11:]}" for line in err if CONVERT_ROW.match(line)][:1]
        err = [line for line in err if not CONVERT_ROW.match(line) or INTERNAL.search(line)]
        if errors and not any(line.startswith(ERROR_PREFIX) for line in err):
            err.append(errors[0])
    found: dict[str, str] = {}
    broken = _broken(row, result, err, errors)
    if broken:
        found["hang" if result and result.get("hang") else "traceback"] = broken
    noise = _noise(row, err, errors, bool(broken))
    if noise:
        found["noise"] = noise
    partial = _leftovers(row, parent, out)
    if partial:
        found["partial_output"] = partial
    row.violations = [v for v in VIOLATIONS if v in found]
    if row.violations:
        row.outcome, row.detail = row.violations[0], found[row.violations[0]]
    elif row.exit == 0:
        row.outcome = "success"
    else:
        row.outcome = "timeout" if "timeout" in errors[0][len(ERROR_PREFIX) :] else "user_error"
        row.detail = errors[0]


def _broken(row: Row, result: dict[str, Any] | None, err: list[str], errors: list[str]) -> str:
    """Why the run is a hang or a traceback: it did not end, an exception escaped ``main``, the
    exit status is neither 0 nor 2, a traceback was printed, exit 2 came without exactly one error
    line, or that line passes off an internal exception (its ``file.py:line``) as a user error."""
    if result and result.get("hang"):
        return f"still running after {row.seconds:.0f} s"
    if result is None:
        return "the process running main died"
    if "exception" in result:
        return f"escaped main: {result['exception']}"
    if row.exit not in (0, 2):
        return f"exit {row.exit}"
    if any(line.startswith("Traceback") for line in err):
        return f"exit {row.exit} with a traceback on stderr"
    if row.exit == 2 and len(errors) != 1:
        return f"exit 2 with {len(errors)} '{ERROR_PREFIX}' lines"
    if row.exit == 2 and INTERNAL.search(errors[0]):
        return f"an internal exception reported as a user error: {errors[0][:300]}"
    return ""


def _noise(row: Row, err: list[str], errors: list[str], broken: bool) -> str:
    """The first line that is not the command's own: its summary lines on success, its one error
    line on failure (after a traceback, only the lines that look like kernel or warning output)."""
    out = row.stdout.splitlines()
    own = [re.compile(p) for p in OWN_LINES[row.command]]
    if row.command == "convert":  # its progress and summary lines come whatever the outcome
        out = [line for line in out if not any(p.match(line) for p in own)]
    if row.exit == 0 and not broken:
        stray = [line for line in out if not any(p.match(line) for p in own)] + err
    elif broken:
        stray = out + [line for line in err if KERNEL.search(line)]
    else:
        stray = out + [line for line in err if line is not errors[0]]
    return next((f"{line[:200]!r}" for line in stray), "")


def _leftovers(row: Row, parent: Path, out: Path) -> str:
    """What a run left that it should not: anything beside ``--out``; after a failure any file in
    it; after a success a missing output."""
    beside = sorted(p.name for p in parent.iterdir() if p != out)
    inside = sorted(str(p.relative_to(out)) for p in out.rglob("*") if p.is_file()) if out.is_dir() else []
    if beside:
        row.left = beside
        return f"left beside --out: {', '.join(beside[:5])}"
    if row.exit != 0:
        if row.command == "convert":  # a failed convert's summary says why each design failed
            inside = [name for name in inside if name not in ("summary.json", LISTING)]
        row.left = inside
        return f"a failed run left in --out: {', '.join(inside[:5])}" if inside else ""
    if row.command == "convert" and not any(p.name != "summary.json" for p in out.glob("*.json")):
        return "success without a converted design's JSON"
    missing = [f for f in COMPLETE[row.command] if not (out / f).is_file() or not (out / f).stat().st_size]
    return f"success without {', '.join(missing)}" if missing else ""


# ---------------------------------------------------------------- a whole run


def make_steps(folder: Path, timeout: float) -> dict[str, bytes]:
    """STEP files to mutate: every sample that replays (its final.step, made by ``zonegraph
    replay`` in a forked child like any input) and the STEP files already in the samples folder."""
    steps = {p.stem + "_step": p.read_bytes() for p in sorted(SAMPLES.glob("*.step"))}
    for name in sorted(sample_texts()):
        out, io = folder / name, folder / f"{name}.io"
        io.mkdir(parents=True)
        argv = argv_for("replay", SAMPLES / f"{name}.json", out, timeout)
        result, _ = run_argv(argv, io, timeout + HANG_GRACE_S)
        if result and result.get("rc") == 0 and (out / "final.step").is_file():
            steps[name] = (out / "final.step").read_bytes()
    return steps


def fuzz(
    count: int,
    seed_value: int,
    timeout: float,
    keep: Path | None = None,
    progress: Callable[[int, int, list[Row]], None] | None = None,
) -> list[Row]:
    """Draw ``count`` cases and run each; ``progress`` is called after every run."""
    warm_up()
    with tempfile.TemporaryDirectory(prefix="zg-fuzz-steps-") as folder:
        steps = make_steps(Path(folder), timeout)
    cases = draw_cases(count, seed_value, fuzz_cases(steps, scripts=True))
    rows: list[Row] = []
    for i, case in enumerate(cases):
        rows.append(run_case(case, i, steps, timeout, keep))
        if progress:
            progress(i + 1, len(cases), rows)
    return rows


def mutated_designs(count: int, seed_value: int) -> list[tuple[str, bytes]]:
    """``count`` mutated design files (label, bytes): the pipeline's fuzz inputs."""
    strategy = st.builds(lambda m: Case("replay", "json", m["design"], m), json_mutations())
    return [(c.label(), apply_json(c.mutation)) for c in draw_cases(count, seed_value, strategy)]
