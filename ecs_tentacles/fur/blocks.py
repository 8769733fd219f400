"""The rig's bind pose in blocks of guides, kept up to date as creatures come and go.

The rig evaluates guides block by block (at most `BLOCK` guides each, so temporaries
stay in cache). `BindBlocks` holds those blocks and the Transform rows of the guides'
bodies. When a creature spawns, only its guides are bound (`make_bind` of its rows) and
appended, to the last block while it has room. When one is despawned, its guides are
cut out of the blocks that hold them and every other block only renumbers its controls
and bodies (integer gathers; the float arrays are shared). Either way the blocks hold
what binding every guide anew gives, bit for bit (`tests/fur/test_blocks.py`), at a cost
that follows the creature's guides instead of the crowd's: binding 128,000 guides anew
took 20 ms, a whole despawn has a budget of 5.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ecs_tentacles.fur.bind import make_bind
from ecs_tentacles.fur.rig import PER_GUIDE, Bind
from ecs_tentacles.fur.stores import FurData

BLOCK = 16384  # guides per block
Block = tuple[slice, Bind]  # the guide rows a block holds, and their bind


def renumbered(bind: Bind, control: np.ndarray, body: np.ndarray) -> Bind:
    """`bind`'s guides with control and body indices mapped (old -> new) by `control`
    and `body`; the float arrays are shared, not copied."""
    return dataclasses.replace(bind, control=control[bind.control], body=body[bind.body])


def joined(parts: list[Bind]) -> Bind:
    """The guides of `parts`, one after the other (indices kept as they are)."""
    if len(parts) == 1:
        return parts[0]
    per_guide = {k: np.concatenate([getattr(p, k) for p in parts]) for k in PER_GUIDE}
    return Bind(
        root=np.concatenate([p.root for p in parts], axis=1),
        basis=np.concatenate([p.basis for p in parts], axis=2),
        shape_h=np.concatenate([p.shape_h for p in parts]),
        **per_guide,
    )


def _split(bind: Bind, start: int) -> list[Block]:
    """`bind` (guide rows from `start`) cut into blocks of `BLOCK` guides."""
    n = len(bind)
    if n <= BLOCK:
        return [(slice(start, start + n), bind)]
    cuts = range(0, n, BLOCK)
    return [
        (slice(start + a, start + min(a + BLOCK, n)), bind.part(slice(a, a + BLOCK))) for a in cuts
    ]


class BindBlocks:
    """Every guide's bind pose, as consecutive blocks, and the Transform rows of their bodies."""

    def __init__(self, blocks: list[Block], bodies: np.ndarray):
        self.blocks = blocks
        self.bodies = bodies  # sorted Transform rows; `Bind.body` indexes them

    @classmethod
    def of(cls, fur: FurData) -> BindBlocks:
        """Bind every guide of `fur`."""
        bind, bodies = make_bind(fur)
        return cls(_split(bind, 0), bodies)

    def __len__(self) -> int:
        return self.blocks[-1][0].stop if self.blocks else 0

    @property
    def whole(self) -> Bind:
        """Every guide's bind as one `Bind`, joined when asked (a copy, not kept: asked
        when binding, it was a second bind pose beside the blocks, 25 MB at 10,000
        creatures)."""
        return joined([bind for _, bind in self.blocks]) if self.blocks else _empty()

    def added(self, fur: FurData, rows: np.ndarray) -> bool:
        """A spawn appended guide rows `rows` to `fur`: bind them and append them.

        False (nothing changed) when they are not the last rows or their bodies are not
        new ones after every known body; then bind everything anew instead.
        """
        n = len(self)
        if not len(rows):
            return True
        if (
            int(rows[0]) != n
            or int(rows[-1]) != len(fur.guides) - 1
            or len(rows) != len(fur.guides) - n
        ):
            return False
        bind, bodies = make_bind(fur, slice(n, None))
        if len(self.bodies) and bodies[0] <= self.bodies[-1]:
            return False
        bind = renumbered(
            bind, np.arange(len(fur.controls)), np.arange(len(bodies)) + len(self.bodies)
        )
        self.bodies = np.concatenate([self.bodies, bodies])
        if self.blocks and len(self.blocks[-1][1]) + len(bind) <= BLOCK:
            rows_before, last = self.blocks.pop()
            bind, n = joined([last, bind]), rows_before.start
        self.blocks += _split(bind, n)
        return True

    def removed(
        self, guides: np.ndarray, controls: np.ndarray | None, transforms: np.ndarray | None
    ) -> None:
        """A despawn took rows out of the stores: `guides`, `controls` and `transforms`
        map every old row to its new row (-1 removed; None: that store lost no row).

        Blocks that lost guides are cut; the others keep their floats and renumber.
        """
        bodies = self.bodies if transforms is None else transforms[self.bodies]
        alive = bodies >= 0
        body = np.cumsum(alive) - 1  # old body index -> new
        control = np.arange(int(max((b.controls_needed for _, b in self.blocks), default=0)))
        if controls is not None:
            control = controls
        # blocks before the first row that goes keep everything (rows before it stay)
        same_controls, same_bodies = _first_gone(control), _first_gone(body, alive)
        blocks: list[Block] = []
        for rows, bind in self.blocks:
            now = guides[rows]
            kept = now >= 0
            if not kept.any():
                continue
            unchanged = bind.controls_needed <= same_controls and bind.bodies_needed <= same_bodies
            if kept.all() and unchanged and now[0] == rows.start:
                part = bind
            elif kept.all():
                part = renumbered(bind, control, body)
            else:
                part = renumbered(bind.part(kept), control, body)
            first = int(now[kept][0])
            part_rows = slice(first, first + len(part))
            if (
                blocks
                and len(blocks[-1][1]) + len(part) <= BLOCK
                and min(len(blocks[-1][1]), len(part)) < BLOCK // 4
            ):
                before, last = blocks.pop()
                part, part_rows = joined([last, part]), slice(before.start, part_rows.stop)
            blocks.append((part_rows, part))
        self.blocks = blocks
        self.bodies = bodies[alive]


def _first_gone(new: np.ndarray, alive: np.ndarray | None = None) -> int:
    """The first old index whose entry moved or went (`new`: old -> new index)."""
    moved = new != np.arange(len(new)) if alive is None else (new != np.arange(len(new))) | ~alive
    found = np.flatnonzero(moved)
    return int(found[0]) if len(found) else len(new)


def _empty() -> Bind:
    f = np.zeros(0, dtype=np.float32)
    return Bind(
        root=np.zeros((3, 0)),
        basis=np.zeros((3, 3, 0)),
        rest_cos=f,
        rest_sin=f,
        tan_min=f,
        multiplier=f,
        control=np.zeros(0, dtype=np.int64),
        body=np.zeros(0, dtype=np.int64),
        shape_h=np.zeros((0, 0, 4)),
    )
