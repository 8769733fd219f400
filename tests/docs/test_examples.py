"""Every code block of the docs (docs/**/*.md and README.md) runs as written.

Read with sybil. A page's blocks run in order in a scratch folder of its own (where
`assets/` leads to the repository's): Python blocks share one namespace a page; JSON
blocks parse (a fragment as the inside of an object) and a whole scene validates; TOML
blocks parse (packaging snippets: an entry-point group named is the one plugins are
found in); shell
blocks run each `ecs-tentacles` command in-process and expect exit 0. A shell block
preceded by `<!-- parsed, not run: why -->` is checked without running (tests/docs/parsed.py:
each command parsed by its own parser, the scenes and files it reads found), and so is one
preceded by `<!-- slow: why -->`, which `pytest -m slow tests/docs` runs as written in a
scratch copy, its outputs checked (tests/docs/slow.py); one preceded
by `<!-- not run: why -->` is not run at all (the built page shows why); a block preceded by
`<!-- file: NAME -->` (or the tutorial's `<!-- tutorial: NAME -->`) is also written to the
scratch folder as NAME (its folder made), for the commands after it. `text` blocks are
output, not code.
The tutorial's commands (`<!-- tutorial: commands -->`, which open the sandbox) are run by
tests/test_tutorial.py, the sandbox headless.
"""

from __future__ import annotations

import contextlib
import glob
import json
import re
import shlex
import tomllib
from pathlib import Path
from typing import Any

import pytest
from sybil import Example, Sybil
from sybil.parsers.markdown import CodeBlockParser

from ecs_tentacles.cli import main
from ecs_tentacles.scene.plugins import ENTRY_POINTS
from tests.docs.parsed import OTHER_COMMANDS, chained, check_block, kind
from tests.docs.slow import run_block

ROOT = Path(__file__).resolve().parents[2]
PAGES = sorted((ROOT / "docs").rglob("*.md")) + [ROOT / "README.md"]
LANGUAGES = ("python", "json", "sh", "toml")  # run; `text` is output shown, not run
NOT_RUN = re.compile(r"<!-- not run: .+ -->|<!-- tutorial: commands -->")
PARSED = re.compile(r"<!-- parsed, not run: .+ -->")
SLOW = re.compile(r"<!-- slow: (.+) -->")  # run by `pytest -m slow tests/docs`, parsed by default
FILE = re.compile(r"<!-- (?:file|tutorial): (\S+\.\w+) -->")
FENCE = re.compile(r"^ *```(\w*)$", flags=re.M)


def marker(example: Example) -> str:
    """The line just before the block (a marker comment, or anything else)."""
    before = example.document.text[: example.start].rstrip("\n").splitlines()
    return before[-1].strip() if before else ""


def scratch(example: Example) -> Path:
    folder: Path = example.namespace["__scratch__"]
    return folder


def keep_file(example: Example) -> bool:
    """Write a `file:`-marked block into the scratch folder; False when not run."""
    line = marker(example)
    if NOT_RUN.fullmatch(line):
        return False
    assert not PARSED.fullmatch(line), f"{example.path}:{example.line}: only shell is parsed"
    assert not SLOW.fullmatch(line), f"{example.path}:{example.line}: only shell runs slow"
    named = FILE.fullmatch(line)
    if named:
        path = scratch(example) / named.group(1)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(str(example.parsed))
    return True


def run_python(example: Example) -> None:
    if keep_file(example):
        code = compile(str(example.parsed), f"{example.path}:{example.line}", "exec")
        exec(code, example.namespace)


def run_json(example: Example) -> None:
    if not keep_file(example):
        return
    text = str(example.parsed)
    try:
        data = json.loads(text)
    except json.JSONDecodeError:
        data = json.loads("{" + text + "}")  # a fragment: keys of a scene or a creature
    if isinstance(data, dict) and "version" in data:  # a whole scene: it validates
        name = FILE.fullmatch(marker(example))
        scene = scratch(example) / (name.group(1) if name else "block.json")
        scene.write_text(text)
        with contextlib.chdir(scratch(example)):
            assert main(["validate", str(scene), "--allow-systems"]) == 0, text


def run_toml(example: Example) -> None:
    if keep_file(example):
        groups = tomllib.loads(str(example.parsed)).get("project", {}).get("entry-points", {})
        assert set(groups) <= {ENTRY_POINTS}, groups


def commands(text: str) -> list[list[str]]:
    """The block's commands, continuation lines joined and comments dropped."""
    joined = re.sub(r"\\\n\s*", " ", text)
    split = [shlex.split(line, comments=True) for line in joined.splitlines()]
    return [argv for argv in split if argv]


def run_sh(example: Example) -> None:
    where = f"{example.path}:{example.line}"
    if PARSED.fullmatch(marker(example)) or SLOW.fullmatch(marker(example)):
        made: set[str] = example.namespace.setdefault("__made__", set())
        check_block(commands(str(example.parsed)), scratch(example), made, where)
        return
    if not keep_file(example):
        return
    for argv in commands(str(example.parsed)):
        assert argv[0] == "ecs-tentacles", (
            f"{where}: `{shlex.join(argv)}` is not an ecs-tentacles command: mark the"
            " block `<!-- parsed, not run: why -->`"
        )
        with contextlib.chdir(scratch(example)):
            expanded = [found for arg in argv[1:] for found in (sorted(glob.glob(arg)) or [arg])]
            assert main([*expanded, "--quiet"] if takes_quiet(argv) else expanded) == 0, argv


def takes_quiet(argv: list[str]) -> bool:
    """Commands with a progress bar take --quiet (the docs leave it out)."""
    return argv[1] in {"run", "bake", "export", "play", "bench"} and "--json" not in argv


SYBIL = Sybil(
    parsers=[
        CodeBlockParser(language, evaluator)
        for language, evaluator in (
            ("python", run_python),
            ("json", run_json),
            ("sh", run_sh),
            ("toml", run_toml),
        )
    ],
)


def page_id(path: Path) -> str:
    return path.relative_to(ROOT).as_posix()


@pytest.mark.parametrize("page", PAGES, ids=page_id)
def test_every_block_has_a_language_the_tests_know(page: Path) -> None:
    languages = FENCE.findall(page.read_text())[::2]  # opening fences
    assert set(languages) <= {*LANGUAGES, "text"}, (page, languages)


@pytest.mark.parametrize("page", PAGES, ids=page_id)
def test_the_page_s_code_runs(page: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "assets").symlink_to(ROOT / "assets")
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    monkeypatch.setenv("ECS_TENTACLES_DATA", str(tmp_path / "data"))
    document = SYBIL.parse(page)
    document.namespace["__scratch__"] = tmp_path
    examples = list(document)
    fences = FENCE.findall(page.read_text())[::2]
    assert len(examples) == sum(language in LANGUAGES for language in fences)
    try:
        with contextlib.chdir(tmp_path):
            for example in examples:
                example.evaluate()
    finally:
        for value in list(document.namespace.values()):
            close: Any = getattr(value, "close", None)
            if type(value).__name__ == "World" and callable(close):
                close()


def test_each_kind_of_command_left_unchecked_is_one_the_docs_show() -> None:
    """The kinds of command parsed blocks hold that are not this project's (pip, Ray,
    Blender, ...) are named in tests/docs/parsed.py, each with what checks it instead, and
    that list names no kind the docs no longer show."""
    shown = set()
    for page in PAGES:
        for example in SYBIL.parse(page):
            checked = PARSED.fullmatch(marker(example)) or SLOW.fullmatch(marker(example))
            if example.region.evaluator is run_sh and checked:
                lines = commands(str(example.parsed))
                shown |= {kind(command) for argv in lines for command in chained(argv)}
    assert shown - {None} == set(OTHER_COMMANDS)


def slow_blocks() -> list[Any]:
    """(page, line, the marker's reason, the block's lines) of every `slow:` block; a
    block whose lines another page already shows (the README's and the handbook's test
    command) is run once, where it is first found."""
    found, seen = [], set()
    for page in PAGES:
        for example in SYBIL.parse(page):
            said = SLOW.fullmatch(marker(example))
            if example.region.evaluator is run_sh and said:
                text = re.sub(r"\\\n\s*", " ", str(example.parsed))
                lines = [line for line in text.splitlines() if shlex.split(line, comments=True)]
                where = f"{page_id(page)}:{example.line}"
                if tuple(lines) not in seen:
                    seen.add(tuple(lines))
                    found.append(pytest.param(where, said.group(1), lines, id=where))
    return found


@pytest.mark.slow  # minutes a block: `pytest -m slow tests/docs`
@pytest.mark.parametrize(("where", "reason", "lines"), slow_blocks())
def test_the_slow_block_runs(where: str, reason: str, lines: list[str], tmp_path: Path) -> None:
    """A `<!-- slow: why -->` block runs as written in a scratch copy (tests/docs/slow.py):
    every line exits 0, and what it writes is there and of its kind."""
    run_block(lines, reason, where, tmp_path)
