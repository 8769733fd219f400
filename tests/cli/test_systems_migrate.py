"""`ecs-tentacles systems` (the frame's data flow) and `ecs-tentacles migrate`."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.scene.load import bundled_scene
from tests.cli.conftest import refused


def test_systems_prints_the_frame_with_stages_plugins_and_fields(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["systems", "hedgehog_octopus"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert (
        lines[0] == "plugins: locomotion (built in), suckers (built in), threats (built in),"
        " fur (built in), clips (built in), terrain (built in)"
    )
    assert lines[1].split() == ["stage", "system", "plugin", "reads", "writes"]
    rows = [line.split()[:3] for line in lines[2:]]
    assert rows[0] == ["decide", "goals", "locomotion"]
    assert ["physics", "physics", "core"] in rows and rows[-1] == ["animate", "rig", "fur"]
    assert main(["systems", "octopus", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["warnings"] == [] and report["systems"][4]["system"] == "motor_targets"


def test_systems_warns_about_unordered_writers(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "twin.py").write_text(
        "from ecs_tentacles.system import System\n"
        "class Twin(System):\n"
        "    name = 'twin'\n"
        "    stage = 'act'\n"
        "    writes = ('motors.target',)\n"
    )
    scene = json.loads(bundled_scene("octopus").read_text())
    scene["plugins"] = {"twin": {"from": "twin.py"}}
    (tmp_path / "s.json").write_text(json.dumps(scene))
    with pytest.warns(UserWarning, match="both write 'motors.target'"):
        assert main(["systems", str(tmp_path / "s.json"), "--allow-systems"]) == 0
    out = capsys.readouterr().out
    assert "warning: motor_targets and twin both write motors.target in stage act" in out


def test_migrate_makes_plugins_explicit_and_folds_the_systems_list(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "mywave.py").write_text(
        "from ecs_tentacles.system import System\nclass Wave(System):\n    name = 'wave'\n"
    )
    scene = json.loads(bundled_scene("octopus").read_text())
    scene["systems"] = ["mywave:Wave"]
    path = tmp_path / "old.json"
    path.write_text(json.dumps(scene))
    assert main(["migrate", str(path), "--allow-systems"]) == 0
    new = json.loads((tmp_path / "old.migrated.json").read_text())
    assert "systems" not in new
    assert new["plugins"] == {
        "locomotion": {}, "suckers": {}, "threats": {}, "fur": {}, "clips": {}, "terrain": {},
        "wave": {"from": "mywave:Wave"},
    }  # fmt: skip
    assert "systems[0] -> plugins.wave (from mywave:Wave)" in capsys.readouterr().out
    assert main(["systems", str(tmp_path / "old.migrated.json"), "--allow-systems"]) == 0
    assert "wave" in capsys.readouterr().out
    assert json.loads(path.read_text()) == scene  # the original is untouched


def test_migrate_writes_a_plugins_former_key_under_its_key_now(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    old = Path(__file__).parents[1] / "data" / "old_lod_plugin_key.json"
    out = tmp_path / "new.json"
    assert main(["migrate", str(old), "--out", str(out)]) == 0
    plugins = json.loads(out.read_text())["plugins"]
    assert plugins["clips"] is False and "lod" not in plugins
    assert "plugins.lod -> plugins.clips (the plugin's key now)" in capsys.readouterr().out
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the migrated scene loads without a warning
        assert main(["systems", str(out)]) == 0
    assert "clips" not in capsys.readouterr().out.splitlines()[0]  # it is off


def test_migrate_refuses_a_bad_scene_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "bad.json"
    path.write_text(json.dumps({"version": 1, "creatures": [{"fur": {"groom": {"count": -1}}}]}))
    assert main(["migrate", str(path)]) == 2
    assert "creatures[0].fur.groom.count" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.json"]


def test_schema_writes_the_assembled_schema_an_editor_can_use(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from jsonschema import Draft202012Validator

    out = tmp_path / "scene.schema.json"
    assert main(["schema", "--out", str(out)]) == 0
    assert capsys.readouterr().out == f"schema: wrote {out}\n"
    schema = json.loads(out.read_text())
    Draft202012Validator.check_schema(schema)
    creature = schema["$defs"]["creature"]["properties"]
    assert {"fur", "goals", "locomotion", "threat"} <= set(creature)
    hedgehog = json.loads(bundled_scene("hedgehog_octopus").read_text())
    assert list(Draft202012Validator(schema).iter_errors(hedgehog)) == []
    assert main(["schema", "follow_leader"]) == 0
    with_example = json.loads(capsys.readouterr().out)
    assert "follow" in with_example["$defs"]["creature"]["properties"]


def test_a_scene_written_before_locomotion_owned_its_tentacle_keys_migrates(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # Before the feature-package refactor the waves and writhing were core keys, so a
    # scene could set them with the locomotion plugin off; now they are locomotion's.
    older = {
        "version": 1,
        "plugins": {"locomotion": False, "suckers": False},
        "creatures": [
            {
                "name": "still",
                "tentacles": {
                    "count": 3, "links": 4, "wave_amplitude_deg": 0, "writhe": 0,
                    "overrides": [{"index": 1, "speed": 2.0, "strength": 30.0}],
                },
            }
        ],
    }  # fmt: skip
    path = tmp_path / "older.json"
    path.write_text(json.dumps(older))
    assert main(["run", str(path), "--frames", "2"]) == 2
    err = capsys.readouterr().err
    assert (
        "creatures[0].tentacles.writhe: unknown key: the locomotion plugin's, which is off"
        " (turn it on, or remove the key: `ecs-tentacles migrate` does)"
    ) in err
    assert "creatures[0].tentacles.overrides[0].speed: unknown key: the locomotion" in err
    assert main(["migrate", str(path)]) == 0
    out = capsys.readouterr().out
    assert (
        "creatures[0].tentacles.wave_amplitude_deg: removed (the locomotion plugin is off)" in out
    )
    assert "creatures[0].tentacles.overrides[0].speed: removed" in out
    migrated = json.loads((tmp_path / "older.migrated.json").read_text())
    tentacles = migrated["creatures"][0]["tentacles"]
    assert tentacles == {
        "count": 3, "links": 4, "overrides": [{"index": 1, "strength": 30.0}]
    }  # fmt: skip
    assert main(["run", str(tmp_path / "older.migrated.json"), "--frames", "2"]) == 0


def test_migrate_never_writes_into_the_installed_package(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    bundled = bundled_scene("octopus")
    before = bundled.read_bytes()
    siblings = sorted(p.name for p in bundled.parent.iterdir())
    monkeypatch.chdir(tmp_path)
    try:
        _refuses_and_copies(bundled, tmp_path, capsys)
    finally:  # if the guard ever fails, the checkout gets its scene back
        if bundled.read_bytes() != before:
            bundled.write_bytes(before)
            pytest.fail("migrate wrote into the bundled scene")
    assert sorted(p.name for p in bundled.parent.iterdir()) == siblings


def _refuses_and_copies(bundled: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["migrate", "octopus", "--in-place"]) == 2
    assert capsys.readouterr().err == (
        "error: octopus: a bundled scene is read-only; write a copy with --out FILE\n"
    )
    err = refused(["migrate", "octopus", "--out", str(bundled.with_name("x.json"))], capsys)
    assert err.startswith("error: argument --out: ") and "bundled files are read-only" in err
    assert main(["migrate", "octopus"]) == 0
    captured = capsys.readouterr()
    assert captured.err == (
        "migrate: octopus is a bundled scene: writing the copy to ./octopus.migrated.json\n"
    )
    assert json.loads((tmp_path / "octopus.migrated.json").read_text())["plugins"]


def test_migrate_in_place_through_a_symlink_keeps_the_link(tmp_path: Path) -> None:
    real = tmp_path / "real.json"
    real.write_text(json.dumps({"version": 1, "systems": []}))
    link = tmp_path / "link.json"
    link.symlink_to(real)
    assert main(["migrate", str(link), "--in-place"]) == 0
    assert link.is_symlink() and link.resolve() == real
    assert "plugins" in json.loads(real.read_text())


def test_schema_refuses_an_output_that_is_not_json_or_a_terminal(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    assert refused(["schema", "--out", str(tmp_path / "x.py")], capsys) == (
        f"error: argument --out: must end in .json, got '{tmp_path / 'x.py'}'"
        " (see ecs-tentacles schema --help)\n"
    )
    monkeypatch.setattr("sys.stdout.isatty", lambda: True)
    assert main(["schema"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.startswith("error: schema: ") and "--out FILE.json" in captured.err
    assert list(tmp_path.iterdir()) == []
