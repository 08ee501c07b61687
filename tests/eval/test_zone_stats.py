"""Zone-graph statistics: graphs built by timeline folder, every design of the stage counted."""

from __future__ import annotations

import pandas as pd
import pytest

from eval.zone_stats import built_by_folder


def test_built_share_counts_every_design_of_the_stage_per_folder():
    manifest = pd.DataFrame(
        {"design_id": ["a", "b", "c", "d"], "status": ["ok", "fuse_failed", "ok", "timeout"]}
    )
    index = pd.DataFrame(
        {"design_id": ["a", "b", "c", "d"], "folder": ["01_2ops", "01_2ops", "02_3ops", "02_3ops"]}
    )
    table = built_by_folder(manifest, index)
    assert table["01_2ops"] == {"designs": 2, "built": 1, "share": 0.5}
    assert table["all"]["designs"] == 4 and table["all"]["share"] == pytest.approx(0.5)
