"""Bodies and suckers stored once per body plan (take format version 3)."""

from __future__ import annotations

import io
import json
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.take import Take, TakeError, compact


@pytest.fixture(scope="module")
def crowd_take(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Six creatures of two body plans (one differs), baked for a few frames."""
    folder = tmp_path_factory.mktemp("compact")
    scene = crowd_scene(6, uniform=True, seed=3)
    scene["creatures"][4]["mantle"]["radius"] *= 1.25
    (folder / "crowd.json").write_text(json.dumps(scene))
    out = folder / "crowd.npz"
    assert main(["bake", str(folder / "crowd.json"), "--seconds", "0.1", "--fps", "30",
                 "--out", str(out), "--quiet"]) == 0  # fmt: skip
    return out


def _stored(path: Path) -> dict[str, Any]:
    with np.load(path) as take:
        return json.loads(bytes(take["header"]))  # type: ignore[no-any-return]


def _rewrite_header(path: Path, target: Path, header: dict[str, Any]) -> None:
    text = json.dumps(header, separators=(",", ":")).encode()
    with zipfile.ZipFile(path) as src, zipfile.ZipFile(target, "w") as dst:
        for info in src.infolist():
            if info.filename != "header.npy":
                dst.writestr(info, src.read(info))
        buffer = io.BytesIO()
        np.save(buffer, np.frombuffer(text, dtype=np.uint8))
        dst.writestr("header.npy", buffer.getvalue())


def test_a_crowd_stores_each_body_plan_once_and_reads_every_body(crowd_take: Path) -> None:
    stored = _stored(crowd_take)
    assert "bodies" not in stored and "suckers" not in stored
    plans = stored[compact.KEY]
    assert len(plans["plans"]) == 2 and plans["creatures"] == [0, 0, 0, 0, 1, 0]
    take = Take.load(crowd_take)
    names = [body["name"] for body in take.header["bodies"]]
    assert len(names) == 6 * 81 and len(set(names)) == len(names)
    assert names[81] == f"{take.header['creatures'][1]['name']}/mantle"
    mantles = [take.header["bodies"][c["mantle"]]["radius"] for c in take.header["creatures"]]
    assert mantles[4] == pytest.approx(1.25 * mantles[0])
    owners = {s["body"] // 81 for s in take.header["suckers"]}
    assert owners == set(range(6))


def test_packing_gives_back_exactly_the_header(crowd_take: Path) -> None:
    header = Take.load(crowd_take).header
    assert compact.unpack(compact.pack(header)) == header
    assert len(compact.header_text(header)) < len(json.dumps(header)) / 3


def test_bodies_out_of_creature_order_are_listed_in_full() -> None:
    def link(creature: int, name: str) -> dict[str, Any]:
        stem = f"{name}/tentacles/t0/link0"
        return {"axis": "X", "creature": creature, "length": 1.0, "name": stem,
                "radius": 0.1, "shape": "capsule"}  # fmt: skip

    header = {
        "version": 3,
        "creatures": [{"name": "a", "mantle": 1, "tentacles": [[0]]},
                      {"name": "b", "mantle": 3, "tentacles": [[2]]}],
        "bodies": [link(1, "b"), link(0, "a")],
        "suckers": [],
    }  # fmt: skip
    assert compact.pack(header) is header
    assert "bodies" in json.loads(compact.header_text(header))


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda h: h[compact.KEY].update(creatures=[0]), "must give a plan for each"),
        (lambda h: h[compact.KEY].update(creatures=[9] * 6), "must be plan indices below 2"),
        (lambda h: h[compact.KEY].update(creatures=[True] * 6), "must be plan indices"),
        (lambda h: h[compact.KEY]["plans"].append(3), "each must hold bodies and suckers"),
        (lambda h: h.update(bodies=[]), "given with bodies or suckers listed too"),
        (lambda h: h.update(version=2), "only version 3 takes store bodies per plan"),
        (lambda h: h[compact.KEY]["plans"][0]["suckers"][0].update(body=-1), "body must be"),
        (lambda h: h[compact.KEY]["plans"][0]["bodies"][0].update(name=7), "is not a string"),
    ],
)
def test_an_unsound_plan_table_is_refused_in_one_line(
    crowd_take: Path, tmp_path: Path, change: Any, message: str
) -> None:
    header = _stored(crowd_take)
    change(header)
    bad = tmp_path / "bad.npz"
    _rewrite_header(crowd_take, bad, header)
    with pytest.raises(TakeError, match=message) as caught:
        Take.load(bad)
    assert "\n" not in str(caught.value)


def test_a_plan_table_that_would_list_too_many_bodies_is_refused_before_listing(
    crowd_take: Path, tmp_path: Path
) -> None:
    header = _stored(crowd_take)
    names = [f"x{i}" for i in range(25_000)]
    header["creatures"] = [{"name": n, "mantle": 0, "tentacles": [[1]]} for n in names]
    header[compact.KEY]["creatures"] = [0] * len(names)  # 2,025,000 bodies claimed
    bad = tmp_path / "bad.npz"
    _rewrite_header(crowd_take, bad, header)
    with pytest.raises(TakeError, match="lists more than"):
        Take.load(bad)


def test_the_header_of_a_crowd_that_listed_too_many_bodies_fits() -> None:
    """The bake's size check counts each body plan once: 6,000 uniform creatures fit
    (refused before: 486,000 bodies listed one by one were a 72 MiB header; 10,000, 121)."""
    from ecs_tentacles.export.bake import BakePlan

    plan = BakePlan.make(crowd_scene(6_000, uniform=True, seed=3), seconds=1.0, fps=24.0)
    assert plan.size_problem() is None
