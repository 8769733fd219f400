"""A key written twice in a scene is refused, naming the key and its line, before anything
is built; JSON without repeated keys reads as the standard library reads it."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from ecs_tentacles.untrusted.strict_json import DuplicateKey, strict_loads

TWICE = """{
  "version": 1,
  "creatures": [{"name": "a", "position": [0, 0]}],
  "name": "two lists",
  "creatures": [{"name": "b", "position": [0, 0]}, {"name": "c", "position": [3, 0]}]
}
"""


def test_the_second_occurrence_of_a_key_is_named_with_its_line_and_column() -> None:
    with pytest.raises(DuplicateKey) as caught:
        strict_loads(TWICE)
    assert (caught.value.key, caught.value.line, caught.value.column) == ("creatures", 5, 3)
    assert str(caught.value) == '"creatures" twice (line 5, column 3)'


def test_a_key_twice_deep_inside_is_found_where_it_is_not_where_the_name_first_repeats() -> None:
    # `name` is in every creature (legal); the second creature has `tentacles` twice
    text = (
        '{"creatures": [\n'
        '  {"name": "a", "tentacles": {"count": 8}},\n'
        '  {"name": "b",\n'
        '   "tentacles": {"count": 6}, "tentacles": {"count": 4}}\n'
        "]}"
    )
    with pytest.raises(DuplicateKey) as caught:
        strict_loads(text)
    assert (caught.value.key, caught.value.line, caught.value.column) == ("tentacles", 4, 31)


def test_escaped_and_unicode_keys_are_compared_as_read() -> None:
    # "\u0061" is "a": the same key written two ways
    with pytest.raises(DuplicateKey) as caught:
        strict_loads('{"a": 1,\n "\\u0061": 2}')
    assert (caught.value.key, caught.value.line, caught.value.column) == ("a", 2, 2)
    with pytest.raises(DuplicateKey, match='"ü" twice'):
        strict_loads('{"ü": [], "x": {}, "ü": {}}')


@pytest.mark.parametrize(
    "text",
    [
        TWICE.replace('"creatures": [{"name": "b"', '"creature": [{"name": "b"'),
        '{"a": {"b": 1}, "b": {"a": 2}, "c": [{"a": 1}, {"a": 2}]}',
        '[1, 2.5, -3e-2, true, false, null, "x", {}, []]',
        '  {"a" : [ ] , "b" : { } }  ',
    ],
)
def test_json_without_repeated_keys_reads_as_the_standard_library_reads_it(text: str) -> None:
    assert strict_loads(text) == json.loads(text)


@pytest.mark.parametrize("text", ['{"a": 1e400}', '{"a": NaN}', '{"a": -Infinity}'])
def test_numbers_are_finite(text: str) -> None:
    with pytest.raises(ValueError, match=r"too large|not valid JSON"):
        strict_loads(text)


@pytest.mark.parametrize(
    "argv",
    [
        ("validate", "SCENE"),
        ("run", "SCENE", "--frames", "2"),
        ("bake", "SCENE", "--seconds", "0.05", "--out", "OUT", "--quiet"),
    ],
    ids=["validate", "run", "bake"],
)
def test_a_scene_with_a_key_twice_is_refused_in_one_line_and_nothing_is_built(
    tmp_path: Path, argv: tuple[str, ...]
) -> None:
    scene, out = tmp_path / "twice.json", tmp_path / "take.npz"
    scene.write_text(TWICE)
    args = [str(scene) if a == "SCENE" else str(out) if a == "OUT" else a for a in argv]
    done = subprocess.run(
        [sys.executable, "-P", "-m", "ecs_tentacles", *args],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=120,
    )
    assert done.returncode == 2, done.stderr
    assert done.stderr == f'error: {scene}:5:3: invalid JSON: key "creatures" written twice\n'
    assert sorted(p.name for p in tmp_path.iterdir()) == ["twice.json"]  # no take, no partial
