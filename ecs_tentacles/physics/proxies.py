"""Contact between creatures: proxies of nearby creatures' bodies.

Each creature's model holds a pool of kinematic (mocap) capsules and cylinders
(`ecs_tentacles.physics.model`). Before each frame's step, every creature near
another gets proxies (a replayed, KINEMATIC, creature is not stepped and gets none),
sized and posed like the other creature's bodies as they were at the end of the last
frame (poses into its state row, sizes into its batch's
overlay); MuJoCo then pushes the creature out of them. Both creatures see each other
this way, so they push each other apart. Far from everyone, a creature's proxies stay
parked out of reach.

All the per-frame work is array math over the bodies of creatures that are near
someone: bounding spheres per creature, candidate bodies inside a neighbour's sphere,
and the nearest ones kept when more are near than the pool holds. A replayed creature's
reach sphere is found by the replay as it writes its poses (`posed_spheres`): the
frame's `sense` reads no replayed body for it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from ecs_tentacles.numeric.optional_kernels import OptionalKernels
from ecs_tentacles.numeric.untouched import untouched_zeros
from ecs_tentacles.physics.model import PROXY_CAPSULES, PROXY_CYLINDERS, PROXY_PARKED
from ecs_tentacles.physics.pairs import NearPairCache
from ecs_tentacles.physics.posed_spheres import PosedSpheres
from ecs_tentacles.physics.tiers import KINEMATIC

if TYPE_CHECKING:
    from ecs_tentacles.physics.batch import Batch
    from ecs_tentacles.physics.roster import Roster
    from ecs_tentacles.physics.rounds import Ready
    from ecs_tentacles.store import TransformStore

S = mujoco.mjtState
MARGIN = 0.05  # metres: a body this close to a neighbour's sphere gets a proxy
POOL = np.array([PROXY_CAPSULES, PROXY_CYLINDERS])
CAPSULE, CYLINDER = 0, 1
KIND, OWNER = np.int8, np.int32  # a body's kind and creature (numpy's work only)
_NONE = np.zeros(0, dtype=np.int64)
ALL = slice(None)
Sensed = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]  # pos, quat, centre, radius
# creatures from which the frame's reach spheres are found on all cores (before the step,
# while the stepping threads wait): at 10,000 one core took about 4 ms
PARALLEL_REACH = 4096
# From this many bodies a frame's sensed poses go in tables resident only where gathered
# (`numeric.untouched`); fewer take ordinary arrays: a mapping made and dropped every
# frame cost 16 creatures with lod off 1.5 % of their frame (overhead 1.085 -> 1.103).
UNTOUCHED_BODIES = 32_768
KERNELS = OptionalKernels("ecs_tentacles.physics.kernels", "ECS_TENTACLES_SENSE")


class ContactProxies:
    """Places every creature's proxies from the Transform store, once per frame."""

    def __init__(self, roster: Roster):
        self.roster = roster
        self._pairs = NearPairCache()  # the frame's pairs, asked for several times
        self.reindex()

    def reindex(self) -> None:
        """Every creature's bodies in roster order, from the batches (after a spawn or
        despawn changed them)."""
        roster = self.roster
        rows, owner, kind, size = [], [], [], []
        count = len(roster)
        for batch in roster.batches:  # per batch, then scattered into creature order
            m = batch.model
            geoms = m.body_geomadr[batch.body_ids]
            cylinder = m.geom_type[geoms] == mujoco.mjtGeom.mjGEOM_CYLINDER
            n, nb = batch.body_rows.shape
            rows.append(batch.body_rows)
            owner.append(np.repeat(batch.members[:, None], nb, axis=1))
            kind.append(np.broadcast_to(np.where(cylinder, CYLINDER, CAPSULE), (n, nb)))
            size.append(np.broadcast_to(m.geom_size[geoms, :2], (n, nb, 2)))
        owner_all = np.concatenate([o.reshape(-1) for o in owner]) if owner else np.zeros(0, int)
        order = np.argsort(owner_all, kind="stable")  # creature by creature, bodies in order
        self.rows = np.concatenate([r.reshape(-1) for r in rows])[order] if rows else owner_all
        self.owner = owner_all[order].astype(OWNER)  # (a table a body: 810,000 at 10,000)
        kinds = np.concatenate([k.reshape(-1) for k in kind])[order] if kind else owner_all
        self.kind = kinds.astype(KIND)
        self.size = (
            np.concatenate([z.reshape(-1, 2) for z in size])[order] if size else np.zeros((0, 2))
        )
        self.rbound = _bounds(self.kind, self.size)
        self._counted(np.bincount(self.owner, minlength=count).astype(np.int64))

    def _counted(self, counts: np.ndarray) -> None:
        """Where each creature's bodies start from their counts, and each batch row's."""
        self.count = counts
        self.start = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
        self.mantle = self.start  # a creature's first body is its mantle
        self._sensed: tuple[int, Sensed] | None = None  # (frame, sense())
        self._within: Sensed | None = None  # the poses refresh() moves within a frame
        self._lazy: _Lazy | None = None  # the frame's sensed bodies, gathered as asked
        self._every = np.arange(len(self.rows))  # body i at pos[i] (pair_gaps' kernel)
        self._posed = PosedSpheres.empty(self.start, self.rbound)
        self._index: list[np.ndarray] | None = None  # (`index`)

    @property
    def index(self) -> list[np.ndarray]:
        """Each batch's rows' bodies in this class's order, (rows, bodies) a batch: for
        numpy's `refresh` (made when first asked: 6.5 MB at 10,000 the kernels never read)."""
        if self._index is None:
            self._index = [
                self.start[batch.members][:, None] + np.arange(len(batch.body_ids))
                for batch in self.roster.batches
            ]
        return self._index

    def append(self, batch: Batch, row: int) -> None:
        """Creature `batch.members[row]` joined the roster last: its bodies at the end of
        the tables (what `reindex` would make, without the sort)."""
        m = batch.model
        geoms = m.body_geomadr[batch.body_ids]
        cylinder = m.geom_type[geoms] == mujoco.mjtGeom.mjGEOM_CYLINDER
        kind = np.where(cylinder, CYLINDER, CAPSULE)
        size = m.geom_size[geoms, :2]
        self.rows = np.concatenate([self.rows, batch.body_rows[row]])
        owner = np.full(len(geoms), int(batch.members[row]), dtype=OWNER)
        self.owner = np.concatenate([self.owner, owner])
        self.kind = np.concatenate([self.kind, kind.astype(KIND)])
        self.size = np.concatenate([self.size, size])
        self.rbound = np.concatenate([self.rbound, _bounds(kind, size)])
        self._counted(np.append(self.count, len(geoms)))

    def remove(self, index: int, moved: np.ndarray) -> None:
        """Creature `index` left the roster (already out of its batch); `moved`: every old
        Transform row's new row. The same tables `reindex` would make, without the sort."""
        keep = self.owner != index
        self.rows = moved[self.rows[keep]]
        self.owner = self.owner[keep]
        self.owner[self.owner > index] -= 1
        self.kind, self.size, self.rbound = self.kind[keep], self.size[keep], self.rbound[keep]
        self._counted(np.delete(self.count, index))

    def sense(self, transforms: TransformStore, frame: int | None = None) -> Sensed:
        """Body poses in this class's order and every creature's reach sphere: (pos, quat,
        centre, radius). With `frame`, computed once per frame (the level of detail and
        the proxies both ask, before anything moves), and the body poses are filled only
        for the creatures `gather` is asked for (the pairs' and the proxies' users ask:
        copying every body of 10,000 creatures took 8 ms a frame), in tables resident
        where written in a big crowd (`numeric.untouched`; heap blocks kept 12 MiB more
        at 10,000)."""
        if frame is not None and self._sensed is not None and self._sensed[0] == frame:
            return self._sensed[1]
        fast = KERNELS.get()
        if frame is not None and fast is not None:  # (pages of the gathered rows only)
            table = untouched_zeros if len(self.rows) >= UNTOUCHED_BODIES else np.empty
            pos, quat = table((len(self.rows), 3)), table((len(self.rows), 4))
            posed, self._posed = self._posed, PosedSpheres.empty(self.start, self.rbound)
            centre, radius = posed.centre, posed.radius  # the replayed ones' are there
            todo = np.flatnonzero(~posed.known)
            spheres = fast.reach_parallel if len(todo) >= PARALLEL_REACH else fast.reach
            spheres(transforms.pos, self.rows, self.start, self.count, self.rbound, todo,
                    centre, radius)  # fmt: skip
            self._lazy = _Lazy(pos, quat, np.zeros(len(self.start), dtype=bool), transforms)
            sensed = (pos, quat, centre, radius)
            self._sensed = (frame, sensed)
            return sensed
        if fast is None:
            pos, quat = transforms.pos[self.rows], transforms.quat[self.rows]
            centre, radius = self.spheres(pos)
        else:  # the same numbers in one pass
            pos, quat = np.empty((len(self.rows), 3)), np.empty((len(self.rows), 4))
            centre, radius = np.empty((len(self.start), 3)), np.empty(len(self.start))
            fast.sense(transforms.pos, transforms.quat, self.rows, self.start, self.count,
                       self.rbound, pos, quat, centre, radius)  # fmt: skip
        sensed = (pos, quat, centre, radius)
        self._sensed = None if frame is None else (frame, sensed)
        return sensed

    def posed_spheres(self) -> PosedSpheres:
        """Where a writer of poses puts the reach spheres of the creatures it poses, for
        the next frame's `sense` (`clips.replay`: a replayed creature's, as its clip
        poses are written into the Transform store). Their numbers must be `spheres`'
        of what the store holds when that `sense` runs: one that writes a creature's
        bodies after its sphere marks it unknown again (`forget_posed`)."""
        return self._posed

    def forget_posed(self, creatures: np.ndarray | slice = ALL) -> None:
        """The spheres `posed_spheres` holds for `creatures` (all: every one) no longer
        stand for the store: the next `sense` finds them from the bodies."""
        self._posed.known[creatures] = False

    def gather(self, pos: np.ndarray, creatures: np.ndarray) -> None:
        """The bodies of `creatures` (roster indices) into `pos` and its quaternions, if
        `pos` is the frame's `sense` and they are not there yet (from the store, as the
        frame started: it is written only after the step)."""
        lazy = self._lazy
        if lazy is None or lazy.pos is not pos or not len(creatures):
            return
        quat, gathered, transforms = lazy.quat, lazy.gathered, lazy.transforms
        fast = KERNELS.get()
        if fast is not None:  # the same copies, creature by creature, no index arrays
            fast.gather(transforms.pos, transforms.quat, self.rows, self.start, self.count,
                        np.asarray(creatures, np.int64), gathered, pos, quat)  # fmt: skip
            return
        need = np.unique(creatures)
        need = need[~gathered[need]]
        if not len(need):
            return
        per = self.count[need]
        body = np.arange(per.sum()) - np.repeat(np.cumsum(per) - per, per)
        body += np.repeat(self.start[need], per)
        rows = self.rows[body]
        pos[body] = transforms.pos[rows]
        quat[body] = transforms.quat[rows]
        gathered[need] = True

    def update(self, transforms: TransformStore, frame: int | None = None) -> None:
        """Give every creature proxies of the other creatures' bodies near it."""
        self._within = None
        if len(self.roster) < 2:
            return
        self._place(*self.sense(transforms, frame))

    @property
    def in_use(self) -> bool:
        """Some creature is near another (its proxies are placed)."""
        return bool(self.roster.proxies_used.any())

    def refresh(self, transforms: TransformStore, ready: Ready | None = None) -> None:
        """Move the proxies to where the bodies are now, within the frame.

        Bodies of creatures near someone are read from their last step (as of their
        last substep); every other body is as the frame started. Only the near
        creatures' poses and reach spheres are recomputed: the frame's `sense` (or the
        last refresh's) holds everyone else's, and is taken over (it is not the frame
        start's any more, so `sense` computes afresh after this). `ready(creatures)`
        is called before the rows of `creatures` are read or written (other threads
        may still be stepping other creatures, `physics.rounds`).
        """
        if self._sensed is not None:
            self._within, self._sensed = self._sensed[1], None
        if self._within is None:
            self._within = self.sense(transforms)
        pos, quat, centre, radius = self._within
        used = self.roster.proxies_used > 0
        if ready is not None:
            ready(used)
        lazy = self._lazy
        if lazy is not None and lazy.pos is pos:
            lazy.gathered[used] = True  # their bodies come from their last step, not the store
            lazy.moved = True
        fast = KERNELS.get()
        if fast is not None:  # the same numbers, a batch in one pass (4 numpy calls less)
            for batch in self.roster.batches:
                fast.moved_bodies(used, batch.members, self.start, self._every, self.rbound,
                                  batch.xpos, batch.xquat, pos, quat, centre, radius)  # fmt: skip
        else:
            for batch, index in zip(self.roster.batches, self.index, strict=True):
                rows = np.flatnonzero(used[batch.members])
                if len(rows):
                    pos[index[rows]] = batch.xpos[rows]
                    quat[index[rows]] = batch.xquat[rows]
            moved = np.flatnonzero(used)
            if len(moved):
                centre[moved], radius[moved] = self._spheres_of(pos, moved)
        self._place(pos, quat, centre, radius, ready)

    def spheres(self, pos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Every creature's reach sphere (centre at its mantle, radius to its farthest
        body's surface) from body positions `pos` in this class's order (`rows`)."""
        centre = pos[self.mantle]
        reach = np.linalg.norm(pos - centre[self.owner], axis=1) + self.rbound
        return centre, np.maximum.reduceat(reach, self.start)

    def _spheres_of(self, pos: np.ndarray, creatures: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """`spheres` of `creatures` (roster indices) only: the same numbers, fewer bodies."""
        per = self.count[creatures]
        first = np.cumsum(per) - per
        owner = np.repeat(np.arange(len(creatures)), per)
        body = np.arange(per.sum()) - first[owner] + self.start[creatures][owner]
        centre = pos[self.mantle[creatures]]
        reach = np.linalg.norm(pos[body] - centre[owner], axis=1) + self.rbound[body]
        return centre, np.maximum.reduceat(reach, first)

    def pair_gaps(
        self, pos: np.ndarray, centre: np.ndarray, radius: np.ndarray, margin: float
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The pairs of creatures (a, b; a < b) whose bodies may come within `margin` of
        each other, and each pair's gap (m) between its nearest bodies (inf: not within).

        Reach spheres find the candidate pairs; of each pair, only the bodies inside the
        other creature's sphere can be near it, and those are compared body against
        body (bounding spheres). A creature's whole reach sphere alone is far too coarse
        for a star of tentacles: neighbours in a crowd are inside each other's spheres
        long before any tentacles meet.
        """
        a, b = self._pairs(centre, radius, margin)
        first = a < b
        a, b = a[first], b[first]
        gaps = np.full(len(a), np.inf)
        if not len(a):
            return a, b, gaps
        fast, lazy = KERNELS.get(), self._lazy
        if fast is not None:  # the same numbers, pair by pair
            source, where = pos, self._every
            if lazy is not None and lazy.pos is pos and not lazy.moved:  # as in the store
                source, where = lazy.transforms.pos, self.rows
            else:
                self.gather(pos, np.concatenate([a, b]))
            fast.pair_gaps(source, where, centre, radius, self.rbound, self.start, self.count,
                           a, b, float(margin), gaps)  # fmt: skip
            return a, b, gaps
        self.gather(pos, np.concatenate([a, b]))
        pa, ba = self._inside(a, b, pos, centre, radius, margin)
        pb, bb = self._inside(b, a, pos, centre, radius, margin)
        na = np.bincount(pa, minlength=len(a))
        nb = np.bincount(pb, minlength=len(a))
        both = na * nb
        if not both.any():
            return a, b, gaps
        pair = np.repeat(np.arange(len(a)), both)
        k = np.arange(len(pair)) - np.repeat(np.cumsum(both) - both, both)
        ia = ba[(np.cumsum(na) - na)[pair] + k // nb[pair]]
        ib = bb[(np.cumsum(nb) - nb)[pair] + k % nb[pair]]
        gap = np.linalg.norm(pos[ia] - pos[ib], axis=1) - self.rbound[ia] - self.rbound[ib]
        np.minimum.at(gaps, pair, gap)
        return a, b, gaps

    def _inside(
        self,
        x: np.ndarray,
        y: np.ndarray,
        pos: np.ndarray,
        centre: np.ndarray,
        radius: np.ndarray,
        margin: float,
    ) -> tuple[np.ndarray, np.ndarray]:
        """(pair, body) for every body of creature x[pair] within `margin` of y[pair]'s
        reach sphere, pair by pair."""
        per = self.count[x]
        pair = np.repeat(np.arange(len(x)), per)
        body = np.arange(per.sum()) - np.repeat(np.cumsum(per) - per, per) + self.start[x][pair]
        gap = np.linalg.norm(pos[body] - centre[y][pair], axis=1) - self.rbound[body]
        keep = gap < radius[y][pair] + margin
        return pair[keep], body[keep]

    def _place(
        self,
        pos: np.ndarray,
        quat: np.ndarray,
        centre: np.ndarray,
        radius: np.ndarray,
        ready: Ready | None = None,
    ) -> None:
        roster = self.roster
        # a replayed creature is not stepped: no proxies (its pairs are not even looked at)
        a, b = self._pairs(centre, radius, MARGIN, among=roster.tier != KINEMATIC)
        self.gather(pos, np.concatenate([a, b]))
        who, body, slot = self._assign(a, b, pos, centre, radius) if len(a) else (_NONE,) * 3
        if ready is not None:
            ready(who)  # their rows are written (those that had proxies were ready before)
        was_used = roster.proxies_used > 0
        if not len(who) and not was_used.any():  # nobody near, before or now: none move
            for batch in roster.batches:
                batch.near[:] = False
            return
        roster.proxies_used[:] = np.bincount(who, minlength=len(roster))
        for batch in roster.batches:
            mocap = batch.grid(S.mjSTATE_MOCAP_POS, 3)
            parked = np.flatnonzero(was_used[batch.members])
            if len(parked):
                mocap[parked[:, None], batch.proxy_mocap] = PROXY_PARKED
            mine = batch.index == roster.batch_of[who]
            rows = roster.row_of[who[mine]]
            if len(rows):
                turns = batch.grid(S.mjSTATE_MOCAP_QUAT, 4)
                mocap_ids = batch.proxy_mocap[slot[mine]]
                mocap[rows, mocap_ids] = pos[body[mine]]
                turns[rows, mocap_ids] = quat[body[mine]]
                batch.proxy_size[rows, slot[mine]] = self.size[body[mine]]
            batch.near[:] = roster.proxies_used[batch.members] > 0

    def _assign(
        self, a: np.ndarray, b: np.ndarray, pos: np.ndarray, centre: np.ndarray, radius: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(creature, source body, proxy slot) triples: b's bodies inside a's sphere,
        nearest first, as many as the pool of each kind holds."""
        fast = KERNELS.get()
        if fast is not None:  # the same candidates in one pass (29 against 59 us at 16 creatures)
            who, body, gap = fast.proxy_candidates(
                pos, centre, radius, self.rbound, self.start, self.count, a, b,
                float(MARGIN), int(POOL.min()), len(self.roster),
            )  # fmt: skip
        else:
            who, body, gap = self._candidates(a, b, pos, centre, radius)
        if not len(who):
            return (_NONE,) * 3
        order = np.lexsort((gap, self.kind[body], who))
        who, body = who[order], body[order]
        group_kind = who * 2 + self.kind[body]
        slot = np.arange(len(body)) - np.searchsorted(group_kind, group_kind, side="left")
        fits = slot < POOL[self.kind[body]]
        who, body, slot = who[fits], body[fits], slot[fits]
        slot = slot + np.where(self.kind[body] == CYLINDER, PROXY_CAPSULES, 0)
        return who, body, slot

    def _candidates(
        self, a: np.ndarray, b: np.ndarray, pos: np.ndarray, centre: np.ndarray, radius: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(creature, body, gap): b's bodies within `MARGIN` of a's sphere, pair by pair;
        a creature with more of them than a pool holds ranks them by its nearest own body."""
        per = self.count[b]
        pair = np.repeat(np.arange(len(a)), per)
        body = np.arange(per.sum()) - np.repeat(np.cumsum(per) - per, per) + self.start[b][pair]
        who = a[pair]
        gap = np.linalg.norm(pos[body] - centre[who], axis=1) - self.rbound[body] - radius[who]
        keep = gap < MARGIN
        who, body, gap = who[keep], body[keep], gap[keep]
        crowded = np.bincount(who, minlength=len(self.roster)) > POOL.min()
        if crowded[who].any():  # more candidates than proxies: rank by the nearest own body
            some = np.flatnonzero(crowded[who])
            gap[some] = self._body_gaps(who[some], body[some], pos)
        return who, body, gap

    def _body_gaps(self, who: np.ndarray, body: np.ndarray, pos: np.ndarray) -> np.ndarray:
        """Gap between each candidate body and the nearest body of creature `who`."""
        per = self.count[who]
        pair = np.repeat(np.arange(len(who)), per)
        own = np.arange(per.sum()) - np.repeat(np.cumsum(per) - per, per) + self.start[who][pair]
        gap = np.linalg.norm(pos[own] - pos[body[pair]], axis=1) - self.rbound[own]
        nearest = np.minimum.reduceat(gap, np.cumsum(per) - per)
        return np.asarray(nearest - self.rbound[body])


@dataclass
class _Lazy:
    """A frame's `sense`: body poses filled creature by creature as `gather` is asked."""

    pos: np.ndarray
    quat: np.ndarray
    gathered: np.ndarray  # per creature: its bodies are in pos / quat
    transforms: TransformStore  # where they come from (as the frame started)
    moved: bool = False  # `refresh` wrote some from their last step: pos is not the store


def _bounds(kind: np.ndarray, size: np.ndarray) -> np.ndarray:
    """Bounding-sphere radii of bodies of `kind` and `size` (radius, half length)."""
    radius, half = size[:, 0], size[:, 1]
    return np.asarray(np.where(kind == CYLINDER, np.hypot(radius, half), radius + half))
