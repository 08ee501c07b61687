"""The bounded memo behind proposal generation and the labels' completions."""

from __future__ import annotations

from zonegraph.sequence.memo import Memo


def test_the_least_recently_used_entries_go_first_past_the_budget():
    memo: Memo[str] = Memo(budget=3)
    for key in "abc":
        memo[key] = key.upper()
    assert memo["a"] == "A"  # read: now the most recently used
    memo["d"] = "D"
    assert "b" not in memo and all(k in memo for k in "acd")
    assert len(memo) == 3 and memo.total == 3


def test_sizes_add_up_and_the_newest_entry_stays_whatever_its_size():
    memo: Memo[bytes] = Memo(budget=10, size=len)
    memo["small"] = b"1234"
    memo["again"] = b"123456"
    assert memo.total == 10 and len(memo) == 2
    memo["huge"] = b"x" * 50
    assert "huge" in memo and len(memo) == 1 and memo.total == 50
    memo["huge"] = b"x"  # replacing an entry replaces its size
    assert memo.total == 1


def test_a_memoised_none_is_told_apart_from_a_missing_entry():
    memo: Memo[int | None] = Memo(budget=5)
    memo["failed"] = None
    assert "failed" in memo and memo["failed"] is None
    assert "never" not in memo and memo.get("never") is None
