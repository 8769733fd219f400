"""`--validate` of `bake` and `export`: the USD just written, checked by every validator
of the Usd Validation Framework, UsdSkel's included (`ecs_tentacles.export.usd_validation`).

Reads the written file; prints each problem on stderr (`error: ...`, `warning: ...`),
then one line counting them. An error makes the exit status 1; the file stays (it is
whole, and what is wrong with it is named). Warnings alone exit 0.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ecs_tentacles.cli.arguments import counted
from ecs_tentacles.export.kinds import output_kind
from ecs_tentacles.output.progress import status


def add_argument(parser: argparse.ArgumentParser) -> None:
    """`--validate`."""
    parser.add_argument(
        "--validate",
        action="store_true",
        help="check the written USD with every USD validator (UsdSkel's included):"
        " problems on stderr, exit 1 on an error",
    )


def validate_problem(args: argparse.Namespace) -> str | None:
    """The one-line problem when `--validate` is asked for an output that is not USD, or
    for a wedge of `bake` (many outputs)."""
    if not args.validate:
        return None
    if output_kind(args.out) != "usd":
        return f"argument --validate: checks USD output (.usd, .usda, .usdc), not {args.out}"
    if getattr(args, "wedge", None):
        return "argument --validate: not with --wedge (export a variant's take with --validate)"
    return None


def validated(path: Path, progress: bool = True) -> int:
    """Check the USD file at `path`: problems and a count on stderr; 1 on an error, else 0."""
    from ecs_tentacles.export.usd_validation import usd_problems, usd_validators

    with status(f"validate: checking {path}", progress=progress):
        problems = usd_problems(path)
    for line in problems:
        print(line, file=sys.stderr)
    errors = sum(line.startswith("error:") for line in problems)
    warnings = len(problems) - errors
    print(
        f"{path}: USD validation: {counted(errors, 'error')}, {counted(warnings, 'warning')}"
        f" ({len(usd_validators())} validators)",
        file=sys.stderr,
    )
    return 1 if errors else 0
