"""A trained checkpoint folded to numpy, for the network guide to run without torch.

    python -m training.fold models/scorer.pt [--out models/scorer.npz]

Writes the late-fusion scorer's weights with every BatchNorm folded in, its samples per zone and
its search defaults (`zonegraph.network.folded`) beside the checkpoint, or to ``--out``.
The shipped ``zonegraph/network/checkpoints/scorer.npz`` is this command's output for the
shipped ``scorer.pt``; a test keeps the two equal.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from zonegraph.network.checkpoint import fold_checkpoint, read_checkpoint


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m training.fold", description=__doc__.splitlines()[0])
    parser.add_argument("checkpoint", type=Path)
    parser.add_argument("--out", type=Path, default=None, help="default: the checkpoint's path with .npz")
    args = parser.parse_args(argv)
    if not args.checkpoint.is_file():
        raise SystemExit(f"{args.checkpoint}: no such checkpoint")
    out = args.out or args.checkpoint.with_suffix(".npz")
    try:
        folded = fold_checkpoint(read_checkpoint(args.checkpoint))
    except ValueError as exc:
        raise SystemExit(f"{args.checkpoint}: {exc}") from None
    folded.save(out)
    print(f"{args.checkpoint} -> {out} ({out.stat().st_size / 1e6:.2f} MB)")


if __name__ == "__main__":
    main()
