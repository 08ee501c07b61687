"""Bad input gives a typed error naming the file and the reason, and a one-line CLI message."""

from __future__ import annotations

import pytest

from zonegraph.cli import main
from zonegraph.data.design import load_design
from zonegraph.data.replay import replay
from zonegraph.errors import DesignError, InputError, UnsupportedFeatureError
from zonegraph.testing import fusion_json as fj


def replay_file(path):
    return replay(load_design(path))


def square_design():
    return fj.design(fj.sketch([(True, fj.rect(0, 0, 1, 1))]), fj.extrude("s0"))


def test_missing_file(tmp_path):
    with pytest.raises(InputError, match="no such file") as err:
        replay_file(tmp_path / "absent.json")
    assert "absent.json" in str(err.value)


def test_invalid_json(tmp_path):
    path = tmp_path / "broken.json"
    path.write_text('{"timeline": [')
    with pytest.raises(InputError, match="invalid JSON"):
        replay_file(path)


def test_not_a_design(tmp_path):
    path = tmp_path / "other.json"
    path.write_text('{"hello": 1}')
    with pytest.raises(InputError, match="not a Fusion 360 Gallery design"):
        replay_file(path)


def test_missing_entity_reference(tmp_path):
    data = square_design()
    data["entities"]["e1"]["profiles"][0]["sketch"] = "nowhere"
    with pytest.raises(DesignError, match="missing sketch nowhere") as err:
        replay_file(fj.write(tmp_path, data))
    assert err.value.entity == "e1"


def test_missing_profile_reference(tmp_path):
    data = square_design()
    data["entities"]["e1"]["profiles"][0]["profile"] = "ghost"
    with pytest.raises(DesignError, match="missing profile ghost"):
        replay_file(fj.write(tmp_path, data))


def test_timeline_entity_missing(tmp_path):
    data = square_design()
    data["timeline"].append({"index": 9, "entity": "lost"})
    with pytest.raises(DesignError, match="does not exist"):
        replay_file(fj.write(tmp_path, data))


@pytest.mark.parametrize(
    "field, value, message",
    [
        ("extent_type", "AllExtentType", "unsupported extent type"),
        ("operation", "NewComponentFeatureOperation", "unsupported operation"),
    ],
)
def test_unsupported_feature(tmp_path, field, value, message):
    data = square_design()
    data["entities"]["e1"][field] = value
    with pytest.raises(UnsupportedFeatureError, match=message) as err:
        replay_file(fj.write(tmp_path, data))
    assert err.value.entity == "e1" and "fixture.json" in err.value.design


def test_non_distance_extent(tmp_path):
    data = square_design()
    data["entities"]["e1"]["extent_one"] = {"type": "ToEntityExtentDefinition"}
    with pytest.raises(UnsupportedFeatureError, match="only distances"):
        replay_file(fj.write(tmp_path, data))


def test_unknown_curve_type(tmp_path):
    data = square_design()
    data["entities"]["s0"]["profiles"]["p"]["loops"][0]["profile_curves"][0]["type"] = "Conic3D"
    with pytest.raises(UnsupportedFeatureError, match="Conic3D"):
        replay_file(fj.write(tmp_path, data))


def test_empty_profile(tmp_path):
    data = square_design()
    data["entities"]["s0"]["profiles"]["p"]["loops"] = []
    with pytest.raises(DesignError, match=r"\[s0\]: profiles.p.loops: list should have at least 1 item"):
        replay_file(fj.write(tmp_path, data))


def test_open_loop(tmp_path):
    data = square_design()
    data["entities"]["s0"]["profiles"]["p"]["loops"][0]["profile_curves"].pop()
    with pytest.raises(DesignError, match="does not close"):
        replay_file(fj.write(tmp_path, data))


def test_zero_length_extrude(tmp_path):
    data = square_design()
    data["entities"]["e1"]["extent_one"] = fj.extent(0.0)
    with pytest.raises(DesignError, match="zero length"):
        replay_file(fj.write(tmp_path, data))


def test_profile_area_mismatch_is_not_silent(tmp_path):
    data = square_design()
    data["entities"]["s0"]["profiles"]["p"]["properties"] = {"area": 2.0}
    with pytest.raises(DesignError, match="differs from Fusion"):
        replay_file(fj.write(tmp_path, data))


@pytest.mark.parametrize("content", [None, "", "{not json"], ids=["missing", "empty", "corrupt"])
def test_cli_one_line_error(tmp_path, capsys, content):
    path = tmp_path / "bad.json"
    if content is not None:
        path.write_text(content)
    assert main(["replay", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("zonegraph: error: ") and str(path) in err
    assert "\n" not in err and "Traceback" not in err
