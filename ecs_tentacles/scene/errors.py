"""The one exception type raised when a scene cannot be read or is invalid."""

from __future__ import annotations

from collections.abc import Iterable


class SceneError(Exception):
    """A scene could not be loaded; ``problems`` holds one human-readable line per problem.

    ``str(err)`` is the problems joined by newlines, so a CLI can print it as is.
    """

    def __init__(self, problems: Iterable[str]) -> None:
        """Store the problems (a single string counts as one problem)."""
        lines = [problems] if isinstance(problems, str) else list(problems)
        self.problems: list[str] = lines
        super().__init__("\n".join(lines))

    def __str__(self) -> str:
        """Return the problems, one per line."""
        return "\n".join(self.problems)
