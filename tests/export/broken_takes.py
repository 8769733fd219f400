"""Hand-broken takes: each case turns a sound take file into a broken one, as a user might.

`BROKEN_TAKES[name](good, bad)` writes `bad` from the sound take file `good`; every
case must be refused by `ecs-tentacles export` with one line and exit 2.
"""

from __future__ import annotations

import io
import json
import struct
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from ecs_tentacles.take import compact, write_npz

Entries = dict[str, Any]  # name -> ndarray, or bytes for a raw .npy entry
# a plugin's points track as a take header declares it (`ecs_tentacles.take.tracks`)
BEACONS = {
    "key": "beacons",
    "kind": "points",
    "arrays": ["beacon_pos", "beacon_live"],
    "folder": "marks",
    "item": "beacon",
}


def _read(good: Path) -> tuple[dict[str, Any], Entries]:
    """The header and arrays of `good`, in version 1's layout (chunks joined, bodies
    listed in the header): the cases break a whole array; `CHUNK_CASES` break a version
    2 file's chunks."""
    with np.load(good) as npz:
        arrays: Entries = {name: npz[name] for name in npz.files}
    header = compact.unpack(json.loads(arrays["header"].tobytes()))  # bodies listed
    chunked: dict[str, list[Any]] = {}
    steps = header.get("quantised") or {}
    for name in sorted(arrays):
        if "." in name:
            base = name.split(".")[0]
            part = arrays.pop(name)
            if base in steps:  # stored in steps, each frame's change: positions again
                part = (np.cumsum(part, axis=0) * steps[base]).astype(np.float32)
            chunked.setdefault(base, []).append(part)
    arrays.update({name: np.concatenate(parts) for name, parts in chunked.items()})
    if chunked:
        header["version"] = 1
        for key in ("chunk_frames", "chunked", "replay", "quantised"):
            header.pop(key, None)
        for name in [n for n in arrays if n.startswith("replay_")]:
            del arrays[name]
    return header, arrays


def _write(bad: Path, header: dict[str, Any], arrays: Entries) -> None:
    arrays = dict(arrays)
    if not isinstance(arrays["header"], bytes):
        arrays["header"] = np.frombuffer(json.dumps(header).encode(), np.uint8)
    raw = {k: v for k, v in arrays.items() if isinstance(v, bytes)}
    write_npz(bad, {k: v for k, v in arrays.items() if not isinstance(v, bytes)})
    with zipfile.ZipFile(bad, "a") as archive:
        for name, data in raw.items():
            archive.writestr(f"{name}.npy", data)


def edit(change: Callable[[dict[str, Any], Entries], object]) -> Callable[[Path, Path], None]:
    """A case that edits the parsed header and arrays in place, then writes them."""

    def make(good: Path, bad: Path) -> None:
        header, arrays = _read(good)
        change(header, arrays)
        _write(bad, header, arrays)

    return make


def raw(change: Callable[[bytes], bytes]) -> Callable[[Path, Path], None]:
    """A case that edits the file's bytes."""

    def make(good: Path, bad: Path) -> None:
        bad.write_bytes(change(good.read_bytes()))

    return make


def _set(array_name: str, index: tuple[int, ...], value: float) -> Callable[..., None]:
    def change(header: dict[str, Any], arrays: Entries) -> None:
        arrays[array_name] = arrays[array_name].copy()
        arrays[array_name][index] = value

    return change


def _npy(array: np.ndarray, patch: Callable[[bytes], bytes] = lambda b: b) -> bytes:
    out = io.BytesIO()
    np.lib.format.write_array(out, array, allow_pickle=True)
    return patch(out.getvalue())


def _claim_huge(data: bytes) -> bytes:
    """Rewrite the zip directory so pos.npy claims to inflate to 4 GiB (a zip bomb's sign)."""
    out = bytearray(data)
    at = out.find(b"PK\x01\x02")
    while at >= 0:
        name_length = struct.unpack_from("<H", out, at + 28)[0]
        name = bytes(out[at + 46 : at + 46 + name_length])
        if name in (b"pos.npy", b"pos.000000.npy"):
            struct.pack_into("<I", out, at + 24, 0xFFFFFF00)  # about 4 GiB
        at = out.find(b"PK\x01\x02", at + 4)
    return bytes(out)


def _flip_middle(data: bytes) -> bytes:
    at = data.find(b"pos.npy") + 200  # inside pos.npy's compressed data
    return data[:at] + bytes([data[at] ^ 0xFF]) + data[at + 1 :]


def _trillion_empty_frames(header: dict[str, Any], arrays: Entries) -> None:
    """A take that lies about its size: 10^12 frames of nothing, 0 bytes of arrays."""
    from ecs_tentacles.take.read import array_dtypes, expected_shapes

    header.update(frames=10**12, creatures=[], bodies=[], suckers=[], guides=None)
    for key in ("goals",):
        header[key] = []
    dtypes = array_dtypes(header)
    shapes = expected_shapes(header)
    arrays.clear()
    arrays["header"] = np.frombuffer(json.dumps(header).encode(), np.uint8)
    for name, shape in shapes.items():
        arrays[name] = np.zeros(shape, dtypes[name])


def _newline_in_creature_name(header: dict[str, Any], arrays: Entries) -> None:
    """Creature 0 renamed `name + "\\n"`, everything it owns renamed to match."""
    old = header["creatures"][0]["name"]
    header["creatures"][0]["name"] = f"{old}\n"
    items = [item for value in header.values() if isinstance(value, list) for item in value]
    for item in items:
        if isinstance(item, dict) and str(item.get("name", "")).startswith(f"{old}/"):
            item["name"] = f"{old}\n{item['name'][len(old) :]}"


def _roster(visible: Callable[[int, int], np.ndarray]) -> Callable[[dict[str, Any], Entries], None]:
    """A roster header with a `creature_visible` array made by `visible(frames, creatures)`."""

    def change(header: dict[str, Any], arrays: Entries) -> None:
        header["roster"] = {"changes": 1}
        arrays["creature_visible"] = visible(header["frames"], len(header["creatures"]))

    return change


BROKEN_TAKES: dict[str, Callable[[Path, Path], None]] = {
    "nan_position": edit(_set("pos", (1, 2, 0), np.nan)),
    "inf_quaternion": edit(_set("quat", (0, 0, 1), np.inf)),
    "zero_quaternion": edit(lambda h, a: a.update(quat=a["quat"] * 0)),
    "nan_goal": edit(_set("goal_pos", (0, 1), np.nan)),
    "nan_sucker_anchor": edit(_set("sucker_anchor", (0, 0, 2), -np.inf)),
    "nan_guide_point": edit(_set("guide_points", (0, 0, 0, 0), np.nan)),
    "negative_guide_width": edit(_set("guide_widths", (0, 0, 0), -1.0)),
    "pos_float64": edit(lambda h, a: a.update(pos=a["pos"].astype(np.float64))),
    "quat_int32": edit(lambda h, a: a.update(quat=a["quat"].astype(np.int32))),
    "attached_uint8": edit(lambda h, a: a.update(sucker_attached=a["sucker_attached"] * 1)),
    "pos_big_endian": edit(lambda h, a: a.update(pos=a["pos"].astype(">f4"))),
    "pos_one_frame_more": edit(lambda h, a: a.update(pos=np.concatenate([a["pos"]] * 2))),
    "quat_three_numbers": edit(lambda h, a: a.update(quat=a["quat"][..., :3].copy())),
    "goal_active_transposed": edit(lambda h, a: a.update(goal_active=a["goal_active"].T.copy())),
    "extra_array": edit(lambda h, a: a.update(evil=np.zeros(3))),
    "missing_quat": edit(lambda h, a: a.pop("quat")),
    "missing_guide_widths": edit(lambda h, a: a.pop("guide_widths")),
    "guides_without_header": edit(lambda h, a: h.update(guides=None)),
    "object_array": edit(lambda h, a: a.update(pos=_npy(np.array([None, 1], dtype=object)))),
    "not_an_npy_entry": edit(lambda h, a: a.update(goal_pos=b"hello, not numpy")),
    "npy_data_cut_short": edit(lambda h, a: a.update(pos=_npy(a["pos"], lambda b: b[:-40]))),
    "fps_zero": edit(lambda h, a: h.update(fps=0)),
    "fps_huge_negative": edit(lambda h, a: h.update(fps=-1e308)),
    "fps_huge": edit(lambda h, a: h.update(fps=1e308)),
    "position_far_out": edit(_set("pos", (1, 2, 0), 3e38)),
    "fps_string": edit(lambda h, a: h.update(fps="30")),
    "fps_nan": edit(lambda h, a: h.update(fps=float("nan"))),
    "frames_zero": edit(lambda h, a: h.update(frames=0)),
    "frames_float": edit(lambda h, a: h.update(frames=float(h["frames"]))),
    "frames_billions": edit(lambda h, a: h.update(frames=10**9)),
    "frames_trillion_without_bodies": edit(_trillion_empty_frames),
    "version_3": edit(lambda h, a: h.update(version=3)),
    "no_format": edit(lambda h, a: h.pop("format")),
    "header_not_json": edit(lambda h, a: a.update(header=_npy(np.frombuffer(b"{oops", np.uint8)))),
    "body_index_out_of_range": edit(lambda h, a: h["creatures"][0]["tentacles"][0].append(999)),
    "creature_without_tentacles": edit(lambda h, a: h["creatures"][0].update(tentacles=[])),
    "tentacle_without_links": edit(lambda h, a: h["creatures"][0]["tentacles"].__setitem__(2, [])),
    "body_used_twice": edit(lambda h, a: h["creatures"][0]["tentacles"][1].__setitem__(0, 0)),
    "body_name_with_spaces": edit(lambda h, a: h["bodies"][1].update(name="octo/link 1")),
    "body_name_without_folder": edit(lambda h, a: h["bodies"][0].update(name="mantle")),
    "creature_name_trailing_newline": edit(_newline_in_creature_name),
    "creature_name_slash": edit(lambda h, a: h["creatures"][0].update(name="a/b")),
    "body_radius_nan": edit(lambda h, a: h["bodies"][2].update(radius=float("nan"))),
    "body_shape_sphere": edit(lambda h, a: h["bodies"][2].update(shape="sphere")),
    "body_axis_number": edit(lambda h, a: h["bodies"][2].update(axis=5)),
    "duplicate_sucker_names": edit(
        lambda h, a: h["suckers"][1].update(
            name=h["suckers"][0]["name"], body=h["suckers"][0]["body"]
        )
    ),
    "sucker_offset_two_numbers": edit(lambda h, a: h["suckers"][0].update(offset=[0, 0])),
    "declared_track_without_arrays": edit(
        lambda h, a: h.update(tracks=[dict(BEACONS)], beacons=[])
    ),
    "declared_track_of_unknown_kind": edit(
        lambda h, a: h.update(tracks=[{**BEACONS, "kind": "voxels"}], beacons=[])
    ),
    "declared_track_reusing_goal_arrays": edit(
        lambda h, a: h.update(tracks=[{**BEACONS, "arrays": ["goal_pos", "x"]}], beacons=[])
    ),
    "goal_of_no_creature": edit(lambda h, a: h["goals"][0].update(creature=7)),
    "guide_owner_out_of_range": edit(lambda h, a: h["guides"].update(creatures=[5, 0, 0])),
    "bodies_not_a_list": edit(lambda h, a: h.update(bodies={"0": 1})),
    "guides_of_one_point": edit(
        lambda h, a: a.update(
            guide_points=a["guide_points"][:, :, :1].copy(),
            guide_widths=a["guide_widths"][:, :, :1].copy(),
        )
    ),
    # the roster (`ecs_tentacles.take.roster`): a take that says creatures came and went
    "roster_without_visible_array": edit(lambda h, a: h.update(roster={"changes": 1})),
    "roster_changes_zero": edit(lambda h, a: h.update(roster={"changes": 0})),
    "roster_not_an_object": edit(lambda h, a: h.update(roster=[1])),
    "roster_visible_one_frame_short": edit(
        _roster(lambda frames, n: np.ones((frames - 1, n), bool))
    ),
    "roster_visible_as_numbers": edit(_roster(lambda frames, n: np.ones((frames, n), np.int32))),
    "roster_visible_without_header": edit(
        lambda h, a: a.update(creature_visible=np.ones((h["frames"], len(h["creatures"])), bool))
    ),
    "zip_bomb_directory": raw(_claim_huge),
    "corrupt_compressed_data": raw(_flip_middle),
    "truncated_file": raw(lambda data: data[: len(data) // 2]),
    "empty_file": raw(lambda data: b""),
    "not_a_zip": raw(lambda data: b"\x93NUMPY" + data[:100]),
}
