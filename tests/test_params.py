"""``params.yaml`` against the configs its sections feed: every key a field, every field set.

A key that is no field of its section's config (a typo, or a setting renamed in the code but not
in the file) would leave the setting at its default without a word; the stages read their
sections strictly, and this test catches it before a run does.
"""

from __future__ import annotations

from dataclasses import fields
from pathlib import Path

import pytest

from pipelines.params import SECTIONS, LabelsParams
from zonegraph.configs import Config, ConfigError, InferConfig, load_params, load_section

PARAMS = Path(__file__).parents[1] / "params.yaml"

# Fields a section may leave to their defaults: paths the stage scripts pass themselves, the
# guide the reconstruct stage sets from its ``guides``, the search's work bound, report options.
UNSET = {
    "reconstruct": {"guide"},
    "train": {"labels_dir", "graphs_dir", "out_dir", "experiment"},
    "evaluate": {"strips", "timeout_s", "project", "labels", "graphs", "out", "metrics", "plot_csv"},
}


def section_configs() -> dict[str, type[Config]]:
    """Every section of ``params.yaml`` with the config it feeds (train and evaluate need torch)."""
    pytest.importorskip("torch")
    from eval.report import EvalConfig
    from training.train import TrainConfig

    return {**SECTIONS, "train": TrainConfig, "evaluate": EvalConfig}


def test_every_section_has_a_config():
    assert set(load_params(PARAMS)) == set(section_configs())


@pytest.mark.parametrize("name", sorted(load_params(PARAMS)))
def test_every_key_is_a_field_and_every_field_a_key(name):
    cls = section_configs()[name]
    keys = set(load_params(PARAMS)[name])
    names = {f.name for f in fields(cls)}  # type: ignore[arg-type]
    assert keys <= names, f"{name}: keys that are no field of {cls.__name__}: {sorted(keys - names)}"
    missing = names - keys - UNSET.get(name, set())
    assert not missing, f"{name}: fields of {cls.__name__} params.yaml does not set: {sorted(missing)}"
    load_section(cls, name, PARAMS)  # and every value converts to its field's type


def test_the_train_defaults_are_the_params():
    """One set of training defaults: ``TrainConfig()`` is what ``make run`` trains."""
    train = section_configs()["train"]
    assert load_section(train, "train", PARAMS) == train()


def test_a_typo_in_a_section_fails_naming_the_file_and_the_key(tmp_path):
    params = load_params(PARAMS)
    params["labels"]["multipler"] = params["labels"].pop("multiplier")
    path = tmp_path / "params.yaml"
    yaml = pytest.importorskip("yaml")
    path.write_text(yaml.safe_dump(params))
    with pytest.raises(ConfigError, match=r"params\.yaml: labels: unknown key\(s\) multipler"):
        load_section(LabelsParams, "labels", path)


def test_values_convert_to_the_annotated_types():
    params = LabelsParams.from_mapping({"splits": ["train"], "limit": None, "multiplier": 2, "slack": 3.0})
    assert params.splits == ("train",) and params.limit is None
    assert isinstance(params.multiplier, float) and params.slack == 3 and isinstance(params.slack, int)
    assert InferConfig.from_mapping({"model": None, "budget_s": 2}).budget_s == 2.0
    for bad in ({"slack": 2.5}, {"splits": "train"}, {"seed": True}):
        with pytest.raises(ConfigError):
            LabelsParams.from_mapping(bad)
