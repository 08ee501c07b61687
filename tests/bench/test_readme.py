"""The headline results (README, the site's front page) are the newest corpus figures."""

import pytest

from bench.readme import PAGES, named, newest, render


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_the_results_table_is_the_one_its_figures_give(page):
    text = page.read_text()
    assert render(text) == text, f"{page.name}'s results are stale: run python -m bench.readme"


@pytest.mark.parametrize("sample", ["tuning", "validation", "fresh"])
@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_the_pages_quote_the_newest_figure_of_each_sample(sample, page):
    latest = newest(sample)
    if latest is None:
        pytest.skip("no figure commit in this history (a shallow clone)")
    assert latest in named(page.read_text())
