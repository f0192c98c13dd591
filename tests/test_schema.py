"""`vest schema`: the JSON Schema editors use agrees with the loader on real and broken trees."""

import json
from pathlib import Path

import jsonschema
import pytest
import yaml

from engine.cli import main
from engine.nodes.registry import default_registry
from engine.nodes.schema import tree_schema

ROOT = Path(__file__).resolve().parents[1]
TREE_FILES = sorted((ROOT / "trees").glob("*.yaml")) + sorted((ROOT / "trees/parts").glob("*.yaml"))


@pytest.fixture(scope="module")
def validator() -> jsonschema.Draft202012Validator:
    schema = tree_schema(default_registry(plugins=False))
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


@pytest.mark.parametrize("path", TREE_FILES, ids=lambda p: p.name)
def test_every_tree_of_the_robot_fits_the_schema(validator, path):
    errors = list(validator.iter_errors(yaml.safe_load(path.read_text())))
    assert errors == []


@pytest.mark.parametrize(
    "root",
    [
        {"Chek": {"key": "/sensors/touch/any", "equals": True}},  # unknown node type
        {"Check": {"key": "/sensors/touch/any", "abve": 3}},  # unknown parameter
        {"Check": {"key": "/sensors/force/left_n", "above": "three"}},  # not a number
        {"Cooldown": {"seconds": 1}},  # a decorator without its child
        {"Say": {"text": "hi", "volume": 2.0}},  # beyond 0..1
    ],
)
def test_mistakes_the_loader_rejects_are_marked_in_the_editor_too(validator, root):
    assert list(validator.iter_errors({"name": "t", "root": root}))


def test_parameters_may_stand_for_any_value(validator):
    tree = {"params": {"n": 3}, "root": {"Check": {"key": "/x", "above": "${n}"}}}
    assert list(validator.iter_errors(tree)) == []


def test_vest_schema_prints_it_as_json(capsys):
    assert main(["schema"]) == 0
    schema = json.loads(capsys.readouterr().out)
    assert schema["title"] == "vest behavior tree"
