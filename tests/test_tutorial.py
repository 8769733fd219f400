"""The docs' "Write your first plugin" (docs/extending/first-plugin.md) runs as written: its
files, its commands, its effect."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from ecs_tentacles.cli import main
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.world import World

PAGE = Path(__file__).resolve().parents[1] / "docs" / "extending" / "first-plugin.md"
HEADING = "# Write your first plugin\n"
BLOCK = re.compile(r"<!-- tutorial: (\S+) -->\n```\w*\n(.*?)```", flags=re.S)


def _tutorial() -> dict[str, str]:
    """The marked code blocks of the tutorial section, by name."""
    text = PAGE.read_text()
    assert text.startswith(HEADING)
    return dict(BLOCK.findall(text))


@pytest.fixture
def folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """The tutorial's files written into an empty folder, which is the current one."""
    blocks = _tutorial()
    assert set(blocks) == {"mywave.py", "wavy.json", "commands"}
    for name in ("mywave.py", "wavy.json"):
        (tmp_path / name).write_text(blocks[name])
    monkeypatch.chdir(tmp_path)
    return tmp_path


pytestmark = pytest.mark.skipif(not PAGE.exists(), reason="needs the source tree")


def test_the_plugin_adds_its_configured_sweep(folder: Path) -> None:
    scene = folder / "wavy.json"
    with World.from_scene(scene, allow_systems=True) as waved:
        assert waved.plugin("mywave").config == {"amplitude": 0.5, "frequency": 1.0}
        names = waved.schedule.names
        assert names.index("motor_targets") < names.index("mywave") < names.index("physics")
        with World.from_scene(scene, allow_systems=True, plugins={"mywave": False}) as plain:
            waved.step(2)
            plain.step(2)
            added = waved.motors.target[:, 1] - plain.motors.target[:, 1]
    # frame 1 runs at t = 1/60 s: 0.5 rad * sin(2 pi * 1 Hz * t) on every link
    np.testing.assert_allclose(added, 0.5 * np.sin(2 * np.pi / 60), rtol=1e-9)


def test_the_refusals_are_the_ones_the_text_quotes(folder: Path) -> None:
    section = " ".join(PAGE.read_text().split())
    scene = folder / "wavy.json"
    untrusted = "plugins.mywave: runs code from 'mywave.py'; allow it with --allow-systems"
    with pytest.raises(SceneError) as refused:
        World.from_scene(scene)
    bad = "plugins.mywave.amplitude: must be in [0, 1], got 2"
    scene.write_text(scene.read_text().replace('"amplitude": 0.5', '"amplitude": 2'))
    with pytest.raises(SceneError) as invalid:
        World.from_scene(scene, allow_systems=True)
    for quoted, error in ((untrusted, refused), (bad, invalid)):
        assert f"(`{quoted}`)" in section
        assert quoted in str(error.value)


def test_the_tutorial_commands_run(folder: Path, capsys: pytest.CaptureFixture[str]) -> None:
    commands = [shlex.split(line) for line in _tutorial()["commands"].splitlines()]
    assert [c[:2] for c in commands] == [
        ["ecs-tentacles", "run"],
        ["ecs-tentacles", "play"],
        ["ecs-tentacles", "systems"],
    ]
    run, play, systems = (argv[1:] for argv in commands)
    assert main([*run, "--quiet"]) == 0
    assert "wavy.json: 120 frames" in capsys.readouterr().out
    # the sandbox, driven headless as in the text: ten frames and a screenshot
    shot = folder / "out.png"
    extra = ["--headless", "--frames", "10", "--screenshot", str(shot), "--quiet"]
    assert main([*play, *extra, "--width", "320", "--height", "180"]) == 0
    with Image.open(shot) as image:
        assert image.size == (320, 180)
        colours = np.unique(np.asarray(image.convert("RGB")).reshape(-1, 3), axis=0)
    assert len(colours) > 100  # a drawn scene, not a blank
    assert main(systems) == 0
    rows = [line.split() for line in capsys.readouterr().out.splitlines()]
    assert ["act", "mywave", "mywave", "motors.target", "motors.target"] in rows
