"""How idiomatic the written build123d scripts are, and that they still rebuild exactly.

    python -m bench.script_bench [--per-folder 10] [--folders 01 02 03 04 05] [--seed 7]
                                 [--samples ../shared/data/fusion360_samples]
                                 [--designs /work/corpus_run/data/designs/json]
                                 [--exclude /work/wt/validation_ids.txt] [--before 9491b5a]
                                 [--show 3] [--out bench_out/script]

Each design's ground-truth program (its extrudes as sketch + extrude steps: profiles on the start
plane, distance along the normal) is written through the exporter exactly as an inferred program
is, with the design's own rebuild of that program as the target, so the writer is measured
without a search. For each design: the script written (its style: idiomatic, without holes, or
literal loops after a fallback), its ``script_iou``, the literal script's ``script_iou`` beside
it, and the loops written as build123d objects. Designs whose program the writer cannot express
(intersect, taper) are counted apart. ``--show`` parts get their script before (the exporter at
``--before``, run from a ``git archive`` of it) and after written side by side under ``--out``.
"""

from __future__ import annotations

import argparse
import inspect
import json
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

import numpy as np
from build123d import Pos, Unit

import zonegraph.geometry.kernel  # noqa: F401 - OCCT's thread pool held before any Boolean
from bench.corpus import write_results
from bench.proposal_bench import DESIGNS, EXCLUDE, draw
from zonegraph.data.design import Design, ExtentType, Extrude, Operation, Sketch, load_design
from zonegraph.data.profiles import profile_faces
from zonegraph.export.snap import REL_TOL
from zonegraph.export.verify import FUZZY_REL, IOU_SLACK, _snapper, run_script, verified_export
from zonegraph.export.writers import LITERAL, profile_counts, program_script, written_steps
from zonegraph.reconstruction import EXACT_IOU
from zonegraph.sequence.program import ProgramStep, brep_iou, execute
from zonegraph.sequence.proposals import Op

SAMPLES = Path(__file__).resolve().parents[1] / ".." / "shared" / "data" / "fusion360_samples"
EXACT = EXACT_IOU
SIDE_WIDTH = 90


def gt_program(design: Design) -> list[ProgramStep] | str:
    """The design's extrudes as program steps (one per sketch an extrude uses), or why not."""
    sketches = {s.id: s for s in design.timeline if isinstance(s, Sketch)}
    steps: list[ProgramStep] = []
    for x in (t for t in design.timeline if isinstance(t, Extrude)):
        if x.operation is Operation.INTERSECT:
            return "intersect"
        if x.extent_one.taper or (
            x.extent_type is ExtentType.TWO_SIDES and x.extent_two and x.extent_two.taper
        ):
            return "taper"
        a, b = x.interval()
        op = Op.SUBTRACT if x.operation is Operation.CUT else Op.UNION
        for sketch_id in dict.fromkeys(r.sketch for r in x.profiles):
            sketch = sketches[sketch_id]
            normal = np.asarray(sketch.frame.z_axis, float)
            normal /= np.linalg.norm(normal)
            faces = [
                Pos(*(normal * a)) * f
                for r in x.profiles
                if r.sketch == sketch_id
                for f in profile_faces(sketch.profiles[r.profile], sketch.frame, design.id)
            ]
            origin = np.asarray(sketch.frame.origin, float) + normal * a
            steps.append(ProgramStep(op, tuple(faces), tuple(origin), tuple(normal), b - a))
    return steps


def measure(path: Path) -> dict:
    """One design's written script: style, exactness of it and of the literal script, objects."""
    started = time.process_time()
    program = gt_program(load_design(path))
    if isinstance(program, str):
        return dict(skipped=program)
    target = execute(program)[-1]
    if target is None:
        return dict(skipped="the program builds nothing")
    export = verified_export(program, path.stem, Unit.CM, target, 1.0, EXACT)
    steps = written_steps(program, _snapper(target, REL_TOL))
    text = program_script(steps, path.stem, Unit.CM, LITERAL)
    literal_iou = brep_iou(run_script(text), target, FUZZY_REL * target.bounding_box().diagonal)
    objects, loops = profile_counts(export.script)
    style = "idiomatic" if export.style.holes else "objects" if export.style.objects else "literal"
    return dict(
        steps=len(program),
        style=style,
        script_iou=export.check.script_iou,
        literal_script_iou=literal_iou,
        json_iou=export.check.json_iou,
        objects=objects,
        loops=loops,
        script=export.script,
        cpu_s=time.process_time() - started,
    )


BEFORE = """
import sys, json
from pathlib import Path
import numpy as np
from build123d import Pos, Unit
from zonegraph.data.design import Design, ExtentType, Extrude, Operation, Sketch, load_design
from zonegraph.data.profiles import profile_faces
from zonegraph.export.snap import REL_TOL
from zonegraph.export.verify import _snapper, export_texts
from zonegraph.sequence.program import ProgramStep, execute
from zonegraph.sequence.proposals import Op
"""
BEFORE_LOOP = """
for path, out in json.loads(sys.argv[1]):
    program = gt_program(load_design(Path(path)))
    target = execute(program)[-1]
    Path(out).write_text(export_texts(program, Path(path).stem, Unit.CM, _snapper(target, REL_TOL))[0])
"""


def write_before(rev: str, jobs: list[tuple[Path, Path]]) -> None:
    """The scripts the exporter at ``rev`` writes for ``jobs`` (design path, script path)."""
    root = Path(__file__).resolve().parents[1]
    with tempfile.TemporaryDirectory() as tmp:
        archive = subprocess.run(
            ["git", "archive", rev, "zonegraph"], cwd=root, capture_output=True, check=True
        )
        Path(tmp, "tree.tar").write_bytes(archive.stdout)
        with tarfile.open(Path(tmp, "tree.tar")) as tar:
            tar.extractall(tmp, filter="data")
        code = BEFORE + inspect.getsource(gt_program) + BEFORE_LOOP
        pairs = json.dumps([[str(p), str(o)] for p, o in jobs])
        subprocess.run([sys.executable, "-c", code, pairs], cwd=tmp, env={"PYTHONPATH": tmp}, check=True)


def side_by_side(before: str, after: str) -> str:
    left, right = before.splitlines(), after.splitlines()
    rows = [f"{'before':<{SIDE_WIDTH}} | after", "-" * (2 * SIDE_WIDTH)]
    for i in range(max(len(left), len(right))):
        a = left[i] if i < len(left) else ""
        b = right[i] if i < len(right) else ""
        rows.append(f"{a[:SIDE_WIDTH]:<{SIDE_WIDTH}} | {b}")
    return "\n".join(rows) + "\n"


def table(rows: list[dict]) -> str:
    lines = [
        "| set | designs | skipped | idiomatic / objects / literal | script exact | literal exact "
        "| loops as objects | CPU s |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for group in ("samples", "corpus", "all"):
        rs = [r for r in rows if group in (r["set"], "all")]
        done = [r for r in rs if "style" in r]
        styles = " / ".join(
            str(sum(r["style"] == s for r in done)) for s in ("idiomatic", "objects", "literal")
        )
        exact = sum(r["script_iou"] >= EXACT for r in done)
        lit_exact = sum(r["literal_script_iou"] >= EXACT for r in done)
        objects, loops = sum(r["objects"] for r in done), sum(r["loops"] for r in done)
        share = f"{objects} / {loops} ({100 * objects / loops:.1f}%)" if loops else "0 / 0"
        cpu = sum(r["cpu_s"] for r in done)
        lines.append(
            f"| {group} | {len(done)} | {len(rs) - len(done)} | {styles} | {exact} / {len(done)} "
            f"| {lit_exact} / {len(done)} | {share} | {cpu:.0f} |"
        )
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--per-folder", type=int, default=10)
    ap.add_argument("--folders", nargs="*", default=["01", "02", "03", "04", "05"])
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--samples", type=Path, default=SAMPLES)
    ap.add_argument("--designs", type=Path, default=DESIGNS)
    ap.add_argument("--exclude", type=Path, default=EXCLUDE)
    ap.add_argument("--before", default="9491b5a", help="the git revision whose exporter wrote 'before'")
    ap.add_argument("--show", type=int, default=3, help="parts shown before and after")
    ap.add_argument("--out", type=Path, default=Path("bench_out/script"))
    args = ap.parse_args()
    jobs = [(p, "samples") for p in sorted(args.samples.glob("*.json"))]
    drawn = [
        (i, f)
        for i, f in draw(args.designs, args.exclude, args.per_folder, args.seed)
        if f[:2] in args.folders
    ]
    jobs += [(args.designs / f"{i}.json", "corpus") for i, _ in drawn]
    rows = []
    for n, (path, group) in enumerate(jobs, 1):
        row: dict = dict(design_id=path.stem, set=group)
        try:
            row |= measure(path)
        except Exception as exc:  # a design the reader refuses or the kernel fails on: counted apart
            row["skipped"] = f"{type(exc).__name__}: {exc}"[:200]
        rows.append(row)
        print(f"  {n}/{len(jobs)} {path.stem}: {row.get('style', row.get('skipped'))}", flush=True)
    scripts = {r["design_id"]: r.pop("script") for r in rows if "script" in r}
    write_results(rows, table(rows), args.out)
    with_objects = [r for r in rows if r.get("objects")]
    shown = (with_objects[:1] + sorted(with_objects[1:], key=lambda r: -r["objects"]))[: args.show]
    paths = {r["design_id"]: p for p, _ in jobs for r in shown if p.stem == r["design_id"]}
    before = {i: args.out.resolve() / f"{i}.before.py" for i in paths}
    write_before(args.before, [(paths[i], before[i]) for i in paths])
    for i in paths:
        pair = args.out / f"{i}.side_by_side.txt"
        (args.out / f"{i}.after.py").write_text(scripts[i])
        pair.write_text(side_by_side(before[i].read_text(), scripts[i]))
        print(f"before/after: {pair}")
    bad = [
        r["design_id"] for r in rows if "style" in r and r["script_iou"] < r["literal_script_iou"] - IOU_SLACK
    ]
    worst = min((r["script_iou"] for r in rows if "style" in r), default=float("nan"))
    print(f"least script_iou: {worst:.9f}")
    print(f"scripts less exact than their literal twin: {bad or 'none'}")


if __name__ == "__main__":
    main()
