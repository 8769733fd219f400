"""`bake --validate` and `export --validate`: the written USD checked by every USD
validator (`ecs_tentacles.cli.usd_validate`), problems on stderr, exit 1 on an error."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.cli.usd_validate import validated
from ecs_tentacles.export.usd_validation import usd_validators

pytest.importorskip("pxr", reason="USD export needs usd-core (the usd / dev extras)")
from pxr import Usd, UsdSkel


def test_bake_and_export_validate_what_they_wrote(
    scene: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    count = len(usd_validators())
    baked, exported = tmp_path / "baked.usdc", tmp_path / "exported.usda"
    bake = ["bake", str(scene), "--seconds", "0.1", "--quiet", "--validate"]
    assert main([*bake, "--out", str(baked)]) == 0
    err = capsys.readouterr().err
    assert err.endswith(f"\n{baked}: USD validation: 0 errors, 0 warnings ({count} validators)\n")
    assert (
        main(["bake", str(scene), "--seconds", "0.1", "--quiet", "--out", str(tmp_path / "t.npz")])
        == 0
    )
    capsys.readouterr()
    export = ["export", str(tmp_path / "t.npz"), "--out", str(exported), "--rigid", "--quiet"]
    assert main([*export, "--validate", "--json"]) == 0
    captured = capsys.readouterr()
    assert json.loads(captured.out)["out"] == str(exported)  # stdout stays the summary
    assert (
        captured.err == f"{exported}: USD validation: 0 errors, 0 warnings ({count} validators)\n"
    )


def test_an_error_is_printed_and_exits_1(
    scene: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "small.usda"
    assert main(["bake", str(scene), "--seconds", "0.1", "--quiet", "--out", str(path)]) == 0
    stage = Usd.Stage.Open(str(path))
    stage.GetPrimAtPath("/World/octo/octo_skin").RemoveAPI(UsdSkel.BindingAPI)
    stage.Save()
    capsys.readouterr()
    assert validated(path, progress=False) == 1
    lines = capsys.readouterr().err.splitlines()
    assert lines[0].startswith(
        "error: usdSkelValidators:SkelBindingApiAppliedValidator.MissingSkelBindingAPI: "
    )
    assert lines[1:] == [
        f"{path}: USD validation: 1 error, 0 warnings ({len(usd_validators())} validators)"
    ]


@pytest.mark.parametrize(
    ("extra", "problem"),
    [
        (["--out", "x.glb"], "checks USD output (.usd, .usda, .usdc), not {folder}/x.glb"),
        (
            ["--out", "x_{name}.usdc", "--wedge", "seed=1,2"],
            "not with --wedge (export a variant's take with --validate)",
        ),
    ],
)
def test_validate_refuses_what_it_cannot_check(
    scene: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    extra: list[str],
    problem: str,
) -> None:
    extra = [str(tmp_path / word) if word.startswith("x") else word for word in extra]
    assert main(["bake", str(scene), "--seconds", "0.1", "--validate", *extra]) == 2
    assert capsys.readouterr().err == (
        f"error: argument --validate: {problem.format(folder=tmp_path)}\n"
    )
    assert list(tmp_path.iterdir()) == [scene]
