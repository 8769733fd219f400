"""How the reduced tier's maps are built (`physics.reduced`): per tentacle and hinge
axis, the matrices that show a reduced chain as the full one (`expansion`: headings
interpolated at the full links' centres) and fit a full chain with a reduced one
(least squares on the links' ends and headings), each reduced servo's group weighted
by distance to the tip (`tip_compliance`), the reduced body standing for each full one,
and the maps as padded group sums (`padded`, `group_sums`: a row's bits whatever rows
share the call)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from ecs_tentacles.physics.reduced_body import Chain


def expansion(chain: Chain) -> tuple[np.ndarray, np.ndarray]:
    """(E, F) for one axis of `chain`: full angles = E @ reduced angles (headings
    interpolated at the full links' centres); reduced = F @ full (least squares on the
    links' ends and headings, small angles)."""
    lengths, reduced = chain.lengths, chain.reduced_lengths
    n, k = len(lengths), len(reduced)
    centres = np.cumsum(lengths) - 0.5 * lengths
    reduced_centres = np.cumsum(reduced) - 0.5 * reduced
    interp = np.zeros((n, k))  # full headings from reduced headings
    for i, c in enumerate(centres):
        j = int(np.searchsorted(reduced_centres, c))
        if j == 0:
            interp[i, 0] = 1.0
        elif j >= k:
            interp[i, k - 1] = 1.0
        else:
            t = (c - reduced_centres[j - 1]) / (reduced_centres[j] - reduced_centres[j - 1])
            interp[i, j - 1], interp[i, j] = 1.0 - t, t
    heading_n = np.tril(np.ones((n, n)))  # headings = cumulative angles
    heading_k = np.tril(np.ones((k, k)))
    difference = np.linalg.inv(heading_n)
    expand = difference @ interp @ heading_k
    ends = np.tril(np.ones((n, n))) * lengths[None, :]  # small-angle offsets of link ends
    scale = float(lengths.mean())
    measure = np.vstack([ends @ heading_n, scale * heading_n])
    fit = np.linalg.pinv(measure @ expand) @ measure
    return expand, fit


def tip_compliance(chain: Chain) -> np.ndarray:
    """(reduced links, full links): row k weighs full joint i of group k by (d_i / d_1)^2,
    d the joint's distance to the tentacle's tip and d_1 that of the group's first joint
    (where the reduced joint is): the tip's give under a force there, joint by joint."""
    lengths = chain.lengths
    to_tip = lengths.sum() - (np.cumsum(lengths) - lengths)  # from each joint (link start)
    weights = np.zeros((len(chain.groups), len(lengths)))
    for k, group in enumerate(chain.groups):
        weights[k, group] = (to_tip[group] / to_tip[group[0]]) ** 2
    return weights


def reduced_body(name: str | None, tentacles: list[Chain]) -> str | None:
    """The reduced body standing for full body `name` (None for proxies and the world)."""
    if name == "mantle":
        return "mantle"
    if not name or not name.startswith("t") or "/l" not in name:
        return None
    tentacle, link = name[1:].split("/l")
    chain = next(c for c in tentacles if c.tentacle == int(tentacle))
    k = next(k for k, g in enumerate(chain.groups) if int(link) in g)
    return f"t{tentacle}/l{k:02d}"


def block_diagonal(blocks: list[np.ndarray]) -> np.ndarray:
    rows, cols = sum(b.shape[0] for b in blocks), sum(b.shape[1] for b in blocks)
    out = np.zeros((rows, cols))
    r = c = 0
    for b in blocks:
        out[r : r + b.shape[0], c : c + b.shape[1]] = b
        r, c = r + b.shape[0], c + b.shape[1]
    return out


def padded(matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(members, weights), each (rows, most nonzeros in a row): row i's nonzero columns
    of `matrix` in order and their entries, padded with its first column at weight 0."""
    width = max(1, int((matrix != 0).sum(axis=1).max(initial=0)))
    members = np.zeros((len(matrix), width), dtype=np.int64)
    weights = np.zeros((len(matrix), width))
    for i, row in enumerate(matrix):
        columns = np.flatnonzero(row)
        members[i] = columns[0] if len(columns) else 0
        members[i, : len(columns)] = columns
        weights[i, : len(columns)] = row[columns]
    return members, weights


def group_sums(values: np.ndarray, members: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """(rows, len(members)): per row of `values`, sum over p of values[members[:, p]] x
    weights[:, p], p in order (`padded`): elementwise, the same bits for a row however
    many rows are summed at once."""
    total: np.ndarray = values[:, members[:, 0]] * weights[:, 0]
    for p in range(1, members.shape[1]):
        total += values[:, members[:, p]] * weights[:, p]
    return total
