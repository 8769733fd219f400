"""Replayed creatures in a take: recorded as which clip, its phase and root motion.

A crowd's far creatures replay gait clips (`ecs_tentacles.clips`): their bodies are a
clip frame placed on the ground. A version 2 take records such a creature at such a
frame as what it is, not as its body poses, where that reproduces the poses the world
showed within `TOLERANCE` (the recorder checks each creature every frame; on terrain,
where the clips are draped body by body, nothing is recorded this way).

    header["replay"]  null, or {"clips": [{"bodies": B, "dt": s, "frames": [F_idle, F_crawl]}],
                                "creatures": [clip index or -1, per creature]}
    replay_kind     int8    (frames, creatures)     -1: the bodies are in pos/quat;
                                                    0: the idle clip, 1: the crawl clip
    replay_phase    float64 (frames, creatures)     clip frame (wraps; fractions blend)
    replay_xy       float64 (frames, creatures, 2)  ground frame origin, metres
    replay_heading  float64 (frames, creatures)     ground frame yaw, radians about +z
    replay_clip_<i> float64 (F_idle + F_crawl, B, 7)  clip i's frames in the ground frame
                    (x y z, w x y z; idle rows then crawl rows), bodies in the take's
                    order for a creature (mantle, then links tentacle by tentacle)

At a replayed frame the creature's bodies hold zeros in `pos` and `quat` in the file;
`fill` puts the poses back (the readers call it), so a take read back holds every pose.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ecs_tentacles.take.header_entries import HeaderCreature

KEY = "replay"
IDENTITY = np.array([1.0, 0.0, 0.0, 0.0], dtype=np.float32)
PER_FRAME = ("replay_kind", "replay_phase", "replay_xy", "replay_heading")
DTYPES: dict[str, np.dtype[np.generic]] = {
    "replay_kind": np.dtype(np.int8),
    "replay_phase": np.dtype("<f8"),
    "replay_xy": np.dtype("<f8"),
    "replay_heading": np.dtype("<f8"),
}
TOLERANCE = 0.001  # m: a replayed creature recorded as a clip is within this of the world's
MAX_CLIPS = 4096
MAX_CLIP_FRAMES = 100_000
PHYSICAL = -1


def clip_array(index: int) -> str:
    """The file name of clip `index`'s frames."""
    return f"replay_clip_{index}"


def _count(value: object, low: int, high: int) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and low <= value <= high


def problem(header: dict[str, Any]) -> str | None:
    """The first problem of `header["replay"]` (the creatures' bodies already checked)."""
    replay = header.get(KEY)
    if replay is None:
        return None
    if not isinstance(replay, dict) or set(replay) != {"clips", "creatures"}:
        return f"header.{KEY}: must be null or an object with clips and creatures"
    clips, owners = replay["clips"], replay["creatures"]
    if not isinstance(clips, list) or len(clips) > MAX_CLIPS:
        return f"header.{KEY}.clips: must be a list of at most {MAX_CLIPS}"
    for i, clip in enumerate(clips):
        where = f"header.{KEY}.clips[{i}]"
        if not isinstance(clip, dict) or set(clip) != {"bodies", "dt", "frames"}:
            return f"{where}: must be an object with bodies, dt and frames"
        frames, dt = clip["frames"], clip["dt"]
        if not (isinstance(frames, list) and len(frames) == 2):
            return f"{where}.frames: must be [idle frames, crawl frames]"
        if not all(_count(f, 1, MAX_CLIP_FRAMES) for f in frames):
            return f"{where}.frames: each must be a whole number in [1, {MAX_CLIP_FRAMES}]"
        if not _count(clip["bodies"], 1, len(header["bodies"])):
            return f"{where}.bodies: must be a whole number in [1, {len(header['bodies'])}]"
        if isinstance(dt, bool) or not isinstance(dt, (int, float)) or not 0 < dt <= 10:
            return f"{where}.dt: must be a number in (0, 10] s"
    creatures = header["creatures"]
    if not isinstance(owners, list) or len(owners) != len(creatures):
        return f"header.{KEY}.creatures: must list a clip index (or -1) per creature"
    for c, clip in enumerate(owners):
        if not _count(clip, PHYSICAL, len(clips) - 1):
            return f"header.{KEY}.creatures[{c}]: must be a clip index or -1, got {clip!r}"
        if clip >= 0 and len(body_rows(creatures[c])) != clips[clip]["bodies"]:
            return f"header.{KEY}.creatures[{c}]: its bodies do not match clip {clip}'s"
    return None


def body_owners(header: dict[str, Any]) -> np.ndarray:
    """Each take body's creature index (bodies,)."""
    return np.array([body["creature"] for body in header["bodies"]], dtype=np.int64)


def body_rows(creature: HeaderCreature) -> list[int]:
    """A take creature's body indices in clip order: mantle, then links by tentacle."""
    return [creature["mantle"], *(i for chain in creature["tentacles"] for i in chain)]


def shapes(header: dict[str, Any]) -> dict[str, tuple[int, ...]]:
    """Array name -> shape for a sound header (none without replayed creatures)."""
    replay = header.get(KEY)
    if replay is None:
        return {}
    frames, count = header["frames"], len(header["creatures"])
    out: dict[str, tuple[int, ...]] = {
        "replay_kind": (frames, count),
        "replay_phase": (frames, count),
        "replay_xy": (frames, count, 2),
        "replay_heading": (frames, count),
    }
    for i, clip in enumerate(replay["clips"]):
        out[clip_array(i)] = (sum(clip["frames"]), clip["bodies"], 7)
    return out


def dtypes(header: dict[str, Any]) -> dict[str, np.dtype[np.generic]]:
    """Array name -> dtype, in file order, for a sound header."""
    replay = header.get(KEY)
    if replay is None:
        return {}
    out = dict(DTYPES)
    out.update({clip_array(i): np.dtype("<f8") for i in range(len(replay["clips"]))})
    return out


def values_problem(header: dict[str, Any], arrays: dict[str, np.ndarray]) -> str | None:
    """The first replay value the poses cannot come from: a kind other than -1, 0, 1, a
    kind on a creature with no clip, a non-finite phase, place or heading, a clip frame
    whose rotation has no length. `arrays` holds (some frames of) the per-frame arrays."""
    replay = header.get(KEY)
    if replay is None:
        return None
    kind = arrays["replay_kind"]
    if kind.size and (kind.min() < PHYSICAL or kind.max() > 1):
        return "replay_kind: must be -1, 0 or 1"
    clipless = np.asarray(replay["creatures"]) < 0
    if clipless.any() and (kind[:, clipless] >= 0).any():
        return "replay_kind: a creature without a clip is marked replayed"
    for name in ("replay_phase", "replay_xy", "replay_heading"):
        values = arrays[name]
        if not np.isfinite(values).all() or (np.abs(values) > 1e9).any():
            return f"{name}: values must be finite numbers"
    return clips_problem(header, {i: arrays[clip_array(i)] for i in range(len(replay["clips"]))
                                  if clip_array(i) in arrays})  # fmt: skip


def clips_problem(header: dict[str, object], clips: dict[int, np.ndarray]) -> str | None:
    """The first clip frame the poses cannot come from: a number not finite or beyond
    1e6 m, a rotation of no length."""
    for i, pose in clips.items():
        if not np.isfinite(pose).all() or (np.abs(pose[..., :3]) > 1e6).any():
            return f"{clip_array(i)}: values must be finite numbers within 1e6 m"
        if (np.einsum("...i,...i->...", pose[..., 3:], pose[..., 3:]) < 1e-12).any():
            return f"{clip_array(i)}: a rotation of zero length"
    return None


def blend(
    pose: np.ndarray, frames: tuple[int, int], kind: np.ndarray, phase: np.ndarray
) -> np.ndarray:
    """(K, B, 7) ground-frame poses of clip `pose` (F_idle + F_crawl, B, 7) at `phase` (K,)
    of `kind` (K,): positions blended linearly between the two frames around the phase,
    rotations by nlerp (the next frame's sign taken the shorter way round)."""
    counts = np.asarray(frames, dtype=np.int64)[kind]
    offset = np.where(kind == 1, frames[0], 0)
    below = np.floor(phase)
    fraction = (phase - below)[:, None, None]
    here = pose[offset + np.mod(below.astype(np.int64), counts)]
    after = pose[offset + np.mod(below.astype(np.int64) + 1, counts)]
    flip = np.einsum("kbi,kbi->kb", here[..., 3:], after[..., 3:]) < 0.0
    after[..., 3:][flip] *= -1.0
    out: np.ndarray = here + (after - here) * fraction
    rot = out[..., 3:]
    rot /= np.sqrt(np.einsum("kbi,kbi->kb", rot, rot))[..., None]
    return out


def place(pose: np.ndarray, xy: np.ndarray, heading: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World positions (K, B, 3) and rotations (K, B, 4) of ground-frame poses (K, B, 7)
    turned by `heading` (K,) about +z and moved by `xy` (K, 2)."""
    c, s = np.cos(heading)[:, None], np.sin(heading)[:, None]
    x, y = pose[..., 0], pose[..., 1]
    pos = np.empty((*pose.shape[:2], 3))
    pos[..., 0] = c * x - s * y + xy[:, 0:1]
    pos[..., 1] = s * x + c * y + xy[:, 1:2]
    pos[..., 2] = pose[..., 2]
    hc, hs = np.cos(0.5 * heading)[:, None], np.sin(0.5 * heading)[:, None]
    w, qx, qy, qz = pose[..., 3], pose[..., 4], pose[..., 5], pose[..., 6]
    quat = np.empty((*pose.shape[:2], 4))
    quat[..., 0] = hc * w - hs * qz
    quat[..., 1] = hc * qx - hs * qy
    quat[..., 2] = hc * qy + hs * qx
    quat[..., 3] = hc * qz + hs * w
    return pos, quat


def poses(
    header: dict[str, Any],
    clips: dict[int, np.ndarray],
    creatures: np.ndarray,
    kind: np.ndarray,
    phase: np.ndarray,
    xy: np.ndarray,
    heading: np.ndarray,
    rows: dict[int, np.ndarray] | None = None,
    needed: np.ndarray | None = None,
) -> dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Clip index -> (body indices (K, B), positions (K, B, 3), rotations (K, B, 4)) of
    the creature-frames given (K each: creature index, kind, phase, place, heading).
    `rows`: clip -> each creature's `body_rows` (C, B), when the caller keeps them (a
    recorder does, every frame); else they are worked out here, a creature at a time.
    `needed` (bool per take body): only the clip's bodies some of these creatures need
    are posed (B is then their count)."""
    replay = header[KEY]
    owner = np.asarray(replay["creatures"], dtype=np.int64)[creatures]
    out = {}
    for clip in np.unique(owner).tolist():
        mine = np.flatnonzero(owner == clip)
        entry = replay["clips"][clip]
        frames = (int(entry["frames"][0]), int(entry["frames"][1]))
        if rows is not None:
            table = rows[clip][creatures[mine]]
        else:
            which, back = np.unique(creatures[mine], return_inverse=True)  # per creature
            table = np.array([body_rows(header["creatures"][c]) for c in which.tolist()])
            table = table.reshape(len(which), -1)[back.reshape(-1)]
        pose = clips[clip]
        if needed is not None:
            columns = np.flatnonzero(needed[table].any(axis=0))
            table, pose = table[:, columns], pose[:, columns]
        ground = blend(pose, frames, kind[mine].astype(np.int64), phase[mine])
        pos, quat = place(ground, xy[mine], heading[mine])
        out[clip] = (table, pos, quat)
    return out


def fill(
    header: dict[str, object],
    clips: dict[int, np.ndarray],
    arrays: dict[str, np.ndarray],
    pos: np.ndarray,
    quat: np.ndarray,
    bodies: np.ndarray | None = None,
    whole: np.ndarray | None = None,
    owners: np.ndarray | None = None,
) -> None:
    """Put the poses of every replayed creature-frame of `arrays` (per-frame replay
    arrays of some frames) into `pos` (frames, bodies, 3) and `quat` of those frames.

    `bodies` (take body indices): pose only these (a reader that needs the mantles and
    the sucker links, not every link), except at the creature-frames `whole` (frames,
    creatures) marks, posed whole; a replayed creature's other bodies are left at the
    origin with the identity rotation (the file's zeros are no rotation at all).
    `owners`: each body's creature (`body_owners`), when the caller keeps it.
    """
    if header.get(KEY) is None:
        return
    replayed = arrays["replay_kind"] >= 0
    frame, creature = np.nonzero(replayed)
    if not len(frame):
        return
    out = (pos, quat)
    if bodies is None:
        _fill(header, clips, arrays, out, (frame, creature), None)
        return
    needed = np.zeros(pos.shape[1], dtype=bool)
    needed[bodies] = True
    owners = body_owners(header) if owners is None else owners
    quat[replayed[:, owners] & ~needed] = IDENTITY
    full = np.zeros(len(frame), dtype=bool) if whole is None else whole[frame, creature]
    _fill(header, clips, arrays, out, (frame[full], creature[full]), None)
    _fill(header, clips, arrays, out, (frame[~full], creature[~full]), needed)


def _fill(
    header: dict[str, Any],
    clips: dict[int, np.ndarray],
    arrays: dict[str, np.ndarray],
    out: tuple[np.ndarray, np.ndarray],
    at: tuple[np.ndarray, np.ndarray],
    needed: np.ndarray | None,
) -> None:
    """`fill` into `out` (pos, quat) at the creature-frames `at` (frame, creature
    indices), `needed` bodies only (None: all)."""
    (pos, quat), (frame, creature) = out, at
    if not len(frame):
        return
    found = poses(
        header,
        clips,
        creature,
        arrays["replay_kind"][frame, creature],
        arrays["replay_phase"][frame, creature],
        arrays["replay_xy"][frame, creature],
        arrays["replay_heading"][frame, creature],
        needed=needed,
    )
    owner = np.asarray(header[KEY]["creatures"], dtype=np.int64)[creature]
    for clip, (rows, where, rot) in found.items():
        frames = frame[owner == clip][:, None]
        pos[frames, rows] = where
        quat[frames, rows] = rot


def blanked(
    header: dict[str, Any], arrays: dict[str, np.ndarray], in_place: bool = False
) -> dict[str, np.ndarray]:
    """`arrays` (some frames of the chunked arrays) as the file stores them: the bodies
    of every replayed creature-frame hold zeros in `pos` and `quat` (copies where any;
    with `in_place`, zeroed where they are: a recorder's own buffers)."""
    if header.get(KEY) is None:
        return arrays
    frame, creature = np.nonzero(arrays["replay_kind"] >= 0)
    if not len(frame):
        return arrays
    creatures = header["creatures"]
    which, back = np.unique(creature, return_inverse=True)  # Python once per creature
    each = [np.asarray(body_rows(creatures[c]), dtype=np.int64) for c in which.tolist()]
    rows = [each[k] for k in back.reshape(-1).tolist()]
    frames = np.repeat(frame, [len(r) for r in rows])
    bodies = np.concatenate(rows)
    out = dict(arrays)
    if not in_place:
        out["pos"], out["quat"] = arrays["pos"].copy(), arrays["quat"].copy()
    out["pos"][frames, bodies] = 0.0
    out["quat"][frames, bodies] = 0.0
    return out
