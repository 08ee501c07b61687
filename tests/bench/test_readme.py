"""The README's headline results are the newest corpus figures, drawn from their files."""

import pytest

from bench.readme import README, named, newest, render


def test_the_readme_results_table_is_the_one_its_figures_give():
    text = README.read_text()
    assert render(text) == text, "README results are stale: run python -m bench.readme"


@pytest.mark.parametrize("sample", ["tuning", "validation"])
def test_the_readme_quotes_the_newest_figure_of_each_sample(sample):
    latest = newest(sample)
    if latest is None:
        pytest.skip("no figure commit in this history (a shallow clone)")
    assert latest in named(README.read_text())
