"""A take's creature, body and sucker rows are what their TypedDicts say: exactly their
fields, of their types, in memory and read back from the file; the header's keys are
those `TakeHeader` names (all it requires, none it does not name), so they cannot drift."""

from __future__ import annotations

import typing
from pathlib import Path

from ecs_tentacles.export.bake import BakePlan, bake, bake_to_file
from ecs_tentacles.take import Take
from ecs_tentacles.take.header_entries import (
    HeaderBody,
    HeaderCreature,
    HeaderHealth,
    HeaderReplay,
    HeaderSucker,
    TakeHeader,
)
from ecs_tentacles.take.tracks import STANDARD, tracks_of

SCENE = {
    "version": 1,
    "creatures": [
        {"name": "octo", "position": [0, 0], "tentacles": {"count": 3, "links": 3}},
        {"name": "squid", "position": [1.5, 0],
         "tentacles": {"count": 2, "links": 4, "suckers": "every_link"}},
    ],
}  # fmt: skip


def _strays(rows: list[dict[str, object]], kind: typing.Any) -> list[str]:
    """Where rows differ from `kind`: other keys, or a value not of the field's type."""
    fields = typing.get_type_hints(kind)
    out = []
    for i, row in enumerate(rows):
        if set(row) != set(fields):
            out.append(f"{kind.__name__}[{i}]: keys {sorted(row)}")
            continue
        for key, hint in fields.items():
            origin = typing.get_origin(hint)
            if origin is typing.Literal:
                ok = row[key] in typing.get_args(hint)
            elif origin is list:
                ok = isinstance(row[key], list)
            else:  # an int where a float is declared is a float to JSON and mypy alike
                ok = isinstance(row[key], (int, float) if hint is float else hint)
            if not ok:
                out.append(f"{kind.__name__}[{i}].{key}: {row[key]!r}")
    return out


def test_the_rows_are_their_typed_dicts_in_memory_and_in_the_file(tmp_path: Path) -> None:
    take = bake(BakePlan.make(SCENE, seconds=0.1, fps=30), progress=False)
    path = tmp_path / "t.npz"
    take.save(path)
    for header in (take.header, Take.load(path).header):
        assert len(header["creatures"]) == 2 and len(header["suckers"]) == 3 + 8
        assert _strays(header["creatures"], HeaderCreature) == []
        assert _strays(header["bodies"], HeaderBody) == []
        assert _strays(header["suckers"], HeaderSucker) == []


def test_a_stray_key_or_value_is_found() -> None:
    rows: list[dict[str, object]] = [
        {"name": "a/sucker0", "body": 0, "offset": [0.0, 0.0, 0.0], "extra": 1},
        {"name": "a/sucker1", "body": "0", "offset": [0.0, 0.0, 0.0]},
    ]
    assert _strays(rows, HeaderSucker) == [
        "HeaderSucker[0]: keys ['body', 'extra', 'name', 'offset']",
        "HeaderSucker[1].body: '0'",
    ]


def _key_strays(
    header: dict[str, object], kind: typing.Any, tracks: frozenset[str] = frozenset()
) -> list[str]:
    """Keys of `header` that `kind` does not name (nor are `tracks`' keys), and keys it
    requires that are absent."""
    named, required = set(typing.get_type_hints(kind)) | tracks, set(kind.__required_keys__)
    return sorted({f"not named: {k}" for k in set(header) - named}
                  | {f"absent: {k}" for k in required - set(header)})  # fmt: skip


def test_a_baked_header_has_the_keys_take_header_names(tmp_path: Path, crowd_take: Take) -> None:
    path = tmp_path / "t.npz"
    written = bake_to_file(BakePlan.make(SCENE, seconds=0.1, fps=30), path, progress=False)
    assert written is not None
    headers = {"in memory": crowd_take.header, "written": written,
               "read back": Take.read_header(path)}  # fmt: skip
    for where, header in headers.items():
        tracks = frozenset(t.key for t in tracks_of(header))
        assert {t.key for t in STANDARD} <= tracks
        assert set(header) >= tracks, where  # every track's key is there
        assert _key_strays(header, TakeHeader, tracks) == [], where
        assert _key_strays(header["health"], HeaderHealth) == [], where
    assert {"chunk_frames", "chunked"} <= set(written)  # what a file adds, named too
    assert crowd_take.header["replay"] is not None  # the crowd replays clips
    assert _key_strays(crowd_take.header["replay"], HeaderReplay) == []


def test_a_key_take_header_does_not_name_is_found() -> None:
    header = {k: 0 for k in TakeHeader.__required_keys__ if k != "seed"} | {"extra": 1}
    assert _key_strays(header, TakeHeader) == ["absent: seed", "not named: extra"]
