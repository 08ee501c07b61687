"""A trained checkpoint folded to numpy, for the network guide to run without torch.

    python -m training.fold models/scorer.pt [--out models/scorer.npz]
    python -m training.fold seed0/scorer.pt seed1/scorer.pt --out ensemble.npz

Writes the late-fusion scorer's weights with every BatchNorm folded in, its samples per zone and
its search defaults (`zonegraph.network.folded`) beside the checkpoint, or to ``--out``. Several
checkpoints of one architecture fold to one ensemble, ranking by their mean log-odds
(`zonegraph.network.ensemble`).
The shipped ``zonegraph/network/checkpoints/scorer.npz`` is this command's output for the
shipped ``scorer.pt``; a test keeps the two equal.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from zonegraph.network.checkpoint import fold_checkpoint, read_checkpoint
from zonegraph.network.ensemble import side_by_side
from zonegraph.network.folded import FoldedScorer


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m training.fold", description=__doc__.splitlines()[0])
    parser.add_argument("checkpoint", type=Path, nargs="+", help="one, or the members of an ensemble")
    parser.add_argument("--out", type=Path, default=None, help="default: the checkpoint's path with .npz")
    args = parser.parse_args(argv)
    if len(args.checkpoint) > 1 and args.out is None:
        raise SystemExit("training.fold: an ensemble of checkpoints needs --out")
    out = args.out or args.checkpoint[0].with_suffix(".npz")
    members = [_folded(path) for path in args.checkpoint]
    try:
        folded = members[0] if len(members) == 1 else side_by_side(members)
    except ValueError as exc:
        raise SystemExit(f"training.fold: {exc}") from None
    out.parent.mkdir(parents=True, exist_ok=True)
    folded.save(out)
    names = " + ".join(str(path) for path in args.checkpoint)
    print(f"{names} -> {out} ({out.stat().st_size / 1e6:.2f} MB)")


def _folded(path: Path) -> FoldedScorer:
    if not path.is_file():
        raise SystemExit(f"{path}: no such checkpoint")
    try:
        return fold_checkpoint(read_checkpoint(path))
    except ValueError as exc:
        raise SystemExit(f"{path}: {exc}") from None


if __name__ == "__main__":
    main()
