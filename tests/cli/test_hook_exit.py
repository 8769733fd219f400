"""A plugin hook that calls sys.exit (or raises a BaseException of its own) is a failure:
one line naming the plugin and the hook, exit 1, nothing written; never exit 0 with no
output, never a traceback without --debug. Real processes: the exit code is the point."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

QUITTER = """
import sys

from ecs_tentacles.plugin import Plugin


class Quit(Plugin):
    name = "quitter"
    hook = ""

    def resources(self, world):
        if self.hook == "resources":
            sys.exit(0)
        return []

    def problems(self, scene):
        if self.hook == "problems":
            sys.exit(0)
        return []

    def build_creature(self, world, creature, spec):
        if self.hook == "build_creature":
            sys.exit(0)

    def systems(self):
        if self.hook == "systems":
            sys.exit(0)
        return []


class Odd(BaseException):
    pass


class Strange(Quit):
    def resources(self, world):
        raise Odd("not an Exception")
"""


def _scene(folder: Path, hook: str, target: str = "quitter.py:Quit") -> Path:
    (folder / "quitter.py").write_text(QUITTER.replace('hook = ""', f'hook = "{hook}"'))
    scene = {
        "version": 1,
        "plugins": {"quitter": {"from": target}},
        "creatures": [{"name": "octo", "tentacles": {"count": 3, "links": 2}}],
    }
    path = folder / "scene.json"
    path.write_text(json.dumps(scene))
    return path


def _cli(folder: Path, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "ecs_tentacles", *args],
        cwd=folder,
        capture_output=True,
        text=True,
        timeout=120,
    )


@pytest.mark.parametrize("hook", ["resources", "problems", "build_creature", "systems"])
def test_sys_exit_in_a_hook_fails_bake_run_and_validate_with_one_line(
    tmp_path: Path, hook: str
) -> None:
    scene = _scene(tmp_path, hook)
    line = f"error: plugins.quitter: its {hook}() hook called sys.exit(0)"
    out = tmp_path / "take.npz"
    bake = _cli(
        tmp_path,
        "bake",
        str(scene),
        "--seconds",
        "0.2",
        "--out",
        str(out),
        "--allow-systems",
        "--quiet",
    )
    assert (bake.returncode, bake.stderr.splitlines()[-1:]) == (1, [line]), bake.stderr
    assert "Traceback" not in bake.stderr and not out.exists()
    run = _cli(tmp_path, "run", str(scene), "--frames", "5", "--allow-systems", "--json")
    assert (run.returncode, run.stdout, run.stderr.splitlines()) == (1, "", [line])
    if hook == "problems":  # the only hook validate calls
        checked = _cli(tmp_path, "validate", str(scene), "--allow-systems")
        assert (checked.returncode, checked.stderr.splitlines()) == (1, [line])


def test_a_base_exception_of_the_users_own_is_one_line_without_debug(tmp_path: Path) -> None:
    scene = _scene(tmp_path, "", "quitter.py:Strange")
    run = _cli(tmp_path, "run", str(scene), "--frames", "5", "--allow-systems")
    assert run.returncode == 1
    assert run.stderr.splitlines() == ["error: run: Odd: not an Exception (--debug shows where)"]
    debug = _cli(tmp_path, "--debug", "run", str(scene), "--frames", "5", "--allow-systems")
    assert "Traceback" in debug.stderr and debug.returncode == 1


def test_sys_exit_in_build_while_planning_shards_is_one_line() -> None:
    """The shard planner builds the scene's plugins without a world; a `build` that calls
    sys.exit there fails as it does in a world: one line naming the plugin."""
    import pytest

    from ecs_tentacles.distributed.shards import entries
    from ecs_tentacles.plugin import HookFailure, Plugin

    class Quits(Plugin):
        name = "quits"

        def build(self, app: object) -> None:
            raise SystemExit(3)

    with pytest.raises(
        HookFailure, match=r"^plugins\.quits: its build\(\) hook called sys\.exit\(3\)$"
    ):
        entries([Quits()])
