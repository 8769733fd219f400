"""USD validation (`ecs_tentacles.export.usd_validation`): every validator of the Usd
Validation Framework runs, UsdSkel's and ours included, and each one a skinned export
could break does flag an export broken its way; errors and warnings are told apart."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from ecs_tentacles.export.skinned_usd import build_skinned_stage
from ecs_tentacles.export.usd_validation import JOINT_COUNTS, usd_problems, usd_validators
from ecs_tentacles.take import Take

pytest.importorskip("pxr", reason="USD export needs usd-core (the usd / dev extras)")
from pxr import Usd, UsdGeom, UsdMedia, UsdSkel, UsdValidation, Vt

SKELETON = "/World/octo/octo_skeleton"


def _written(stage: Any, path: Path) -> Path:
    assert stage.GetRootLayer().Export(str(path))
    return path


def test_the_validators_run_are_the_registry_s_usd_skel_s_included_and_ours() -> None:
    names = {validator.GetMetadata().name for validator in usd_validators()}
    registered = UsdValidation.ValidationRegistry().GetOrLoadAllValidators()
    assert names == {validator.GetMetadata().name for validator in registered} | {JOINT_COUNTS}
    assert {
        "usdSkelValidators:SkelBindingApiAppliedValidator",
        "usdSkelValidators:SkelBindingApiValidator",
        "usdGeomValidators:StageMetadataChecker",
        "usdShadeValidators:MaterialBindingApiAppliedValidator",
        JOINT_COUNTS,
    } <= names


def test_a_skeleton_outside_a_skel_root_is_an_error(guided_take: Take, tmp_path: Path) -> None:
    stage, _ = build_skinned_stage(guided_take)
    assert usd_problems(_written(stage, tmp_path / "good.usdc")) == []
    stage.GetPrimAtPath("/World/octo").SetTypeName("Xform")  # was the SkelRoot
    invalid = "error: usdSkelValidators:SkelBindingApiValidator.InvalidSkelBindingAPIApply:"
    assert usd_problems(_written(stage, tmp_path / "bad.usdc")) == [
        f"{invalid} UsdSkelBindingAPI applied on prim: <{prim}>, which is not of type SkelRoot"
        " or is not rooted at a prim of type SkelRoot, as required by the UsdSkel schema."
        for prim in (SKELETON, "/World/octo/octo_skin")
    ]


def test_skel_bindings_without_their_api_are_an_error(guided_take: Take, tmp_path: Path) -> None:
    stage, _ = build_skinned_stage(guided_take)
    stage.GetPrimAtPath("/World/octo/octo_skin").RemoveAPI(UsdSkel.BindingAPI)
    assert usd_problems(_written(stage, tmp_path / "bad.usdc")) == [
        "error: usdSkelValidators:SkelBindingApiAppliedValidator.MissingSkelBindingAPI: Found a"
        " UsdSkelBinding property (primvars:skel:geomBindTransform), but no SkelBindingAPI"
        " applied on the prim </World/octo/octo_skin>."
    ]


def test_an_animation_short_of_a_joint_is_an_error(guided_take: Take, tmp_path: Path) -> None:
    """UsdSkel poses such a skeleton at rest (a warning on stderr, no validator of its
    own): `ecsTentacles:SkelJointCounts` names the prim, the array and the times."""
    stage, _ = build_skinned_stage(guided_take)
    animation = UsdSkel.Animation(stage.GetPrimAtPath(f"{SKELETON}/octo_animation"))
    rotations = animation.GetRotationsAttr()
    for time in (2.0, 3.0, 4.0):
        rotations.Set(Vt.QuatfArray(list(rotations.Get(time))[:-1]), time)
    skeleton = UsdSkel.Skeleton(stage.GetPrimAtPath(SKELETON))
    bind = list(skeleton.GetBindTransformsAttr().Get())
    skeleton.GetBindTransformsAttr().Set(Vt.Matrix4dArray([*bind, bind[0]]))
    assert usd_problems(_written(stage, tmp_path / "bad.usdc")) == [
        f"error: {JOINT_COUNTS}.JointCountMismatch: SkelAnimation <{SKELETON}/octo_animation>:"
        " rotations holds 12 values at time 2 (and 2 more times) for its 13 joints",
        f"error: {JOINT_COUNTS}.JointCountMismatch: Skeleton <{SKELETON}>: bindTransforms"
        " holds 14 values as authored for its 13 joints",
    ]


def test_a_stage_without_units_is_an_error(tmp_path: Path) -> None:
    stage = Usd.Stage.CreateNew(str(tmp_path / "bad.usda"))
    stage.SetDefaultPrim(UsdGeom.Xform.Define(stage, "/World").GetPrim())
    stage.Save()
    problems = usd_problems(tmp_path / "bad.usda")
    assert len(problems) == 2
    assert all(p.startswith("error: usdGeomValidators:StageMetadataChecker.") for p in problems)
    assert "does not specify an upAxis" in " ".join(problems)


def test_warnings_come_after_errors_and_say_so(tmp_path: Path) -> None:
    """An authorship record applied in two layers: UsdMedia's validator warns (only the
    stronger survives composition); a missing upAxis is an error, listed first."""
    weak = Usd.Stage.CreateNew(str(tmp_path / "weak.usda"))
    UsdMedia.AuthorshipAPI.Apply(weak.DefinePrim("/World", "Xform"), "ecs")
    weak.Save()
    stage = Usd.Stage.CreateNew(str(tmp_path / "strong.usda"))
    stage.GetRootLayer().subLayerPaths.append("weak.usda")
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    world = UsdGeom.Xform.Define(stage, "/World").GetPrim()
    stage.SetDefaultPrim(world)
    UsdMedia.AuthorshipAPI.Apply(world, "ecs")
    stage.Save()
    problems = usd_problems(tmp_path / "strong.usda")
    assert [line.split(":", 1)[0] for line in problems] == ["error", "warning"]
    assert problems[1].startswith(
        "warning: usdMediaValidators:ShadowedOrDuplicateAuthorship.DuplicateAuthorshipApplication:"
    )


def test_a_file_usd_cannot_open_is_one_error(tmp_path: Path) -> None:
    (tmp_path / "not.usda").write_text("this is not USD\n")
    assert usd_problems(tmp_path / "not.usda") == [
        f"error: {tmp_path / 'not.usda'}: USD could not open the file"
    ]
