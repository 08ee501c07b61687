"""The benchmark samples: the validation sample never overlaps the tuning sample, and the
regression list holds tuning designs only, so no figure on the validation sample was steered."""

from __future__ import annotations

from functools import cache

from bench.corpus_bench import sample
from bench.regressions import LIST, read_list
from zonegraph.testing import CORPUS, requires_corpus

TUNING_SEED, VALIDATION_SEED = 0, 2023


@cache
def tuning() -> dict[str, str]:
    """The tuning sample's design ids and folders (listing the corpus takes seconds)."""
    return {e.design_id: e.folder for e in sample(CORPUS, 25, TUNING_SEED)}


@requires_corpus
def test_the_validation_sample_is_disjoint_from_the_tuning_sample() -> None:
    validation = sample(CORPUS, 25, VALIDATION_SEED, fresh_from=(TUNING_SEED,))
    assert len(tuning()) == 190 and 150 <= len(validation) <= 200
    assert not tuning().keys() & {e.design_id for e in validation}


@requires_corpus
def test_the_regression_list_names_tuning_designs_only() -> None:
    listed = read_list(LIST)
    assert {e.expected for e in listed} <= {"exact", "partial"}
    assert all(tuning().get(e.design_id) == e.folder for e in listed)
    assert len({e.folder for e in listed if e.expected == "exact"}) == 8


@requires_corpus
def test_a_larger_diagnosis_sample_of_chosen_folders_leaves_out_both_samples() -> None:
    validation = {e.design_id for e in sample(CORPUS, 25, VALIDATION_SEED, fresh_from=(TUNING_SEED,))}
    drawn = sample(CORPUS, 70, 7373, None, (TUNING_SEED, VALIDATION_SEED), 25, ("05", "06"))
    ids = {e.design_id for e in drawn}
    assert {e.folder for e in drawn} == {"05_8to10ops", "06_11to15ops"} and len(ids) == 140
    assert not ids & (validation | tuning().keys())
