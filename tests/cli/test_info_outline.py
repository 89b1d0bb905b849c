"""``info`` lists each scenario by its outline (name, photos, points): the same figures as the
full validation for every shipped scenario, and one INVALID line for a file whose outline is
wrong."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml

from stereoplotter.cli import main
from stereoplotter.errors import ConfigError
from stereoplotter.io import paths
from stereoplotter.io.scenario_file import load_scenario, scenario_from_mapping
from stereoplotter.io.scenario_outline import scenario_outline

SHIPPED_SCENARIOS = sorted(Path(paths.data_dir("scenarios")).glob("*.yaml"))
PAIR60 = Path(paths.data_dir("scenarios")) / "pair60.yaml"


@pytest.fixture(autouse=True)
def _clean(monkeypatch, tmp_path):
    monkeypatch.delenv(paths.ENVIRONMENT_VARIABLE, raising=False)
    paths.set_user_folders([])
    monkeypatch.chdir(tmp_path)
    yield
    paths.set_user_folders([])


@pytest.mark.parametrize("path", SHIPPED_SCENARIOS, ids=lambda p: p.stem)
def test_outline_of_a_shipped_scenario_is_what_validation_builds(path):
    outline = scenario_outline(path)
    scenario = load_scenario(path)
    assert (outline.name, outline.photos, outline.points) == (
        scenario.name, len(scenario.photos), len(scenario.points)
    )


@pytest.mark.parametrize(
    ("old", "new"),
    [
        ("name: pair60", "name: ''"),  # an empty name
        ("\npoints:", "\npoints: []\nunused:"),  # no point
        ("\nphotos:", "\nphotos: 3\nunused:"),  # photos not a list
        ("\nphotos:", "\nmodels: []\nphotos:"),  # a block file
    ],
)
def test_outline_refuses_as_the_full_validation_does(tmp_path, old, new):
    text = PAIR60.read_text(encoding="utf-8")
    assert text.count(old) == 1
    bad = tmp_path / "bad.yaml"
    bad.write_text(text.replace(old, new), encoding="utf-8")
    with pytest.raises(ConfigError) as outline_error:
        scenario_outline(bad)
    # the document as the full validation reads it, the key that took the old value set aside
    data = yaml.safe_load(bad.read_text(encoding="utf-8"))
    data.pop("unused", None)
    with pytest.raises(ConfigError) as full_error:
        scenario_from_mapping(data, str(bad))
    assert str(outline_error.value) == str(full_error.value)


def test_info_marks_a_scenario_without_photos_invalid(tmp_path, capsys):
    user = tmp_path / "mine"
    (user / "scenarios").mkdir(parents=True)
    text = PAIR60.read_text(encoding="utf-8").replace("\nphotos:", "\nphotos: 3\nunused:")
    (user / "scenarios" / "broken.yaml").write_text(text, encoding="utf-8")
    assert main(["--data", str(user), "info", "--json"]) == 0
    (entry,) = [e for e in json.loads(capsys.readouterr().out)["scenarios"] if e["key"] == "broken"]
    assert entry["error"] == (
        f"{user / 'scenarios' / 'broken.yaml'}: photos: expected a list of 1 photo or 2 photos "
        "named left and right, found 3"
    )
    assert main(["--data", str(user), "info"]) == 0
    assert "broken.yaml: INVALID: " in capsys.readouterr().out
