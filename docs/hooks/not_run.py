"""An mkdocs hook: a code block the docs tests do not run is marked in the page source
with `<!-- not run: why -->` on the line before it (tests/docs/test_examples.py reads the
marker); the built page shows the reason to the reader under the block's heading."""

from __future__ import annotations

import re
from typing import Any

MARK = re.compile(r"^<!-- not run: (.+?) -->$", flags=re.M)


def on_page_markdown(markdown: str, **_: Any) -> str:
    """Each marker becomes a visible line before its block."""
    return MARK.sub(lambda m: f"*Not run by the docs tests: {m.group(1)}.*\n", markdown)
