"""Import a script of `tools/` as a module, for the tools' tests."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

import pytest

TOOLS = Path(__file__).resolve().parents[2] / "tools"


def load_tool(name: str) -> ModuleType:
    """`tools/<name>.py` imported as the module `name` (registered, so dataclasses and
    process pools find it), with `tools/` on the import path as when it runs as a script
    (a tool may import another's helpers)."""
    if str(TOOLS) not in sys.path:
        sys.path.append(str(TOOLS))
    spec = importlib.util.spec_from_file_location(name, TOOLS / f"{name}.py")
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def refused(name: str, argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """What `tools/<name>.py` said on stderr when it refused `argv`: it must exit 2."""
    with pytest.raises(SystemExit) as exit_info:
        load_tool(name).main(argv)
    assert exit_info.value.code == 2
    return capsys.readouterr().err
