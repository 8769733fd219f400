"""USD files checked by the Usd Validation Framework (`pxr.UsdValidation`): one line a problem.

    usd_problems("take.usdc")   # [] for a clean file; else lines such as
    # error: usdSkelValidators:SkelBindingApiValidator.InvalidSkelBindingAPIApply: ...
    # warning: ...

Reads a USD file (or an open `Usd.Stage`); writes nothing. Every validator the installed
usd-core registers runs (`ValidationRegistry().GetOrLoadAllValidators()`: core, UsdGeom,
UsdShade, UsdSkel, UsdPhysics, UsdLux, UsdMedia, UsdUtils' packaging), plus
`ecsTentacles:SkelJointCounts` below. Errors and warnings are told apart by the line's
first word; informational notes are left out. `usd_validators()` names them all.

UsdSkel's own validators check where `SkelBindingAPI` is applied and that it is; none
checks that a SkelAnimation holds one value per joint, and UsdSkel meets a mismatch by
posing the skeleton at rest with only a warning on stderr (usd-core 26.11: the
creature stands still). `ecsTentacles:SkelJointCounts` makes that an error: a
Skeleton's bind and rest transforms and joint names, and a SkelAnimation's
translations, rotations and scales at every time sample, hold as many values as the
prim has joints.
"""

from __future__ import annotations

import importlib
import os
from collections.abc import Sized
from types import ModuleType
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from pxr import Usd, UsdValidation

JOINT_COUNTS = "ecsTentacles:SkelJointCounts"

# the arrays UsdSkel reads one value a joint from, by schema (the prim's own `joints`)
_JOINT_ARRAYS = {
    "Skeleton": ("bindTransforms", "restTransforms", "jointNames"),
    "SkelAnimation": ("translations", "rotations", "scales"),
}


def _validation() -> tuple[ModuleType, ModuleType]:
    """`pxr.UsdValidation`, with `pxr.Usd` loaded (UsdUnavailable without usd-core)."""
    from ecs_tentacles.export.usd import _pxr

    pxr = _pxr()
    importlib.import_module("pxr.Tf")  # its ErrorException: a file USD cannot open
    return importlib.import_module("pxr.UsdValidation"), pxr


def usd_validators() -> list[UsdValidation.Validator]:
    """Every validator `usd_problems` runs: the registry's and `ecsTentacles:SkelJointCounts`."""
    validation, _ = _validation()
    registry = validation.ValidationRegistry()
    if not registry.HasValidator(JOINT_COUNTS):
        metadata = validation.ValidatorMetadata(
            name=JOINT_COUNTS,
            doc="Skeleton and SkelAnimation arrays hold one value per joint of the prim.",
            keywords=["EcsTentaclesValidators"],
            schemaTypes=["UsdSkelSkeleton", "UsdSkelAnimation"],
            isTimeDependent=True,
        )
        registry.RegisterPrimValidator(metadata, _joint_counts)
    return list(registry.GetOrLoadAllValidators())


def usd_problems(source: str | os.PathLike[str] | Usd.Stage) -> list[str]:
    """The problems of the USD file (or `Usd.Stage`) `source`: errors, then warnings, each
    sorted, one line each (`error: <validator>.<problem>: <message>`). A file USD cannot open is
    one error naming it."""
    validation, pxr = _validation()
    stage = source
    if isinstance(source, str | os.PathLike):
        try:
            stage = pxr.Usd.Stage.Open(os.fspath(source))
        except pxr.Tf.ErrorException:
            return [f"error: {os.fspath(source)}: USD could not open the file"]
    kinds = validation.ValidationErrorType
    found = validation.ValidationContext(usd_validators()).Validate(stage)
    lines: dict[str, list[str]] = {"error": [], "warning": []}
    for problem in found:
        kind = {kinds.Error: "error", kinds.Warn: "warning"}.get(problem.GetType())
        if kind is not None:
            lines[kind].append(f"{kind}: {problem.GetIdentifier()}: {problem.GetMessage()}")
    return [*sorted(lines["error"]), *sorted(lines["warning"])]  # validators run in parallel


def _joint_counts(
    prim: Usd.Prim, time_range: UsdValidation.ValidationTimeRange
) -> list[UsdValidation.ValidationError]:
    """`ecsTentacles:SkelJointCounts` on one Skeleton or SkelAnimation prim."""
    validation, pxr = _validation()
    joints = prim.GetAttribute("joints").Get()
    count = 0 if joints is None else len(joints)
    errors = []
    for name in _JOINT_ARRAYS.get(prim.GetTypeName(), ()):
        attribute = prim.GetAttribute(name)
        if not attribute.HasAuthoredValue():
            continue
        interval = time_range.GetInterval()
        samples = attribute.GetTimeSamplesInInterval(interval)
        sizes = [(f"at time {time:g}", _size(attribute.Get(time))) for time in samples]
        if time_range.IncludesTimeCodeDefault():
            sizes.insert(0, ("as authored", _size(attribute.Get(pxr.Usd.TimeCode.Default()))))
        wrong = [(when, size) for when, size in sizes if size not in (None, count)]
        if not wrong:
            continue
        when, size = wrong[0]
        more = f" (and {len(wrong) - 1} more times)" if len(wrong) > 1 else ""
        site = validation.ValidationErrorSite(prim.GetStage(), attribute.GetPath())
        errors.append(
            validation.ValidationError(
                "JointCountMismatch",
                validation.ValidationErrorType.Error,
                [site],
                f"{prim.GetTypeName()} <{prim.GetPath()}>: {name} holds {size} values"
                f" {when}{more} for its {count} joints",
            )
        )
    return errors


def _size(value: Sized | None) -> int | None:
    """The length of an authored array value; None where nothing is authored."""
    return None if value is None else len(value)
