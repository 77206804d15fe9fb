"""Splits made of whole groups of records (``data.group_by``): every scaled copy and both
components of one recording land in the same split, so a test record is never trained on
in another guise."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..signals.errors import ConfigError
from .datasets import SPLITS


def grouped_order(
    groups: Sequence[str], sizes: tuple[int, int, int], rng: np.random.Generator
) -> np.ndarray:
    """A permutation of the records that puts every group wholly in one split.

    The groups are shuffled by ``rng`` and dealt to the splits so that they hold exactly
    ``sizes`` (train, val, test) records: a dynamic programme over the (test, val) record
    counts reachable with the groups taken so far finds the groups of test and val, the
    rest is train. Inside each split the records are shuffled by ``rng`` again.

    Args:
        groups: ``[n]`` the group of each record, ``n = sum(sizes)``.
        sizes: records in train, val and test.
        rng: the generator that shuffles; the same state gives the same order.

    Returns:
        ``[n]`` record indices: train's first, then val's, then test's.

    Raises:
        ConfigError: no choice of whole groups gives these sizes; the message lists the
            group sizes and the split sizes whole groups can make.
    """
    names, index, counts = np.unique(
        np.asarray(groups, dtype=str), return_inverse=True, return_counts=True
    )
    if counts.sum() != sum(sizes):
        raise ValueError(f"{counts.sum()} records for split sizes {sizes}")
    shuffled = rng.permutation(names.size)
    n_val, n_test = sizes[1], sizes[2]
    # first[t, v]: 1 + the position in `shuffled` of the group that first made (t, v)
    # reachable (0: not yet; -1: reachable with no group); bin: 0 test, 1 val.
    first = np.zeros((n_test + 1, n_val + 1), dtype=np.int64)
    dealt_to = np.zeros_like(first, dtype=np.int8)
    first[0, 0] = -1
    for position, group in enumerate(shuffled):
        size = int(counts[group])
        reached = first != 0
        if size <= n_test:  # the group into test
            new = np.zeros_like(reached)
            new[size:] = reached[: n_test + 1 - size]
            new &= first == 0
            first[new], dealt_to[new] = position + 1, 0
        if size <= n_val:  # the group into val
            new = np.zeros_like(reached)
            new[:, size:] = reached[:, : n_val + 1 - size]
            new &= first == 0
            first[new], dealt_to[new] = position + 1, 1
    if first[n_test, n_val] == 0:
        raise ConfigError(_impossible_split(counts, sizes))
    split_of = np.zeros(names.size, dtype=np.int64)  # 0 train, 1 val, 2 test
    t, v = n_test, n_val
    while (t, v) != (0, 0):
        group = shuffled[first[t, v] - 1]
        if dealt_to[t, v] == 0:
            split_of[group], t = 2, t - int(counts[group])
        else:
            split_of[group], v = 1, v - int(counts[group])
    record_split = split_of[index]
    return np.concatenate(
        [rng.permutation(np.flatnonzero(record_split == s)) for s in range(len(SPLITS))]
    )


def _impossible_split(counts: np.ndarray, sizes: tuple[int, int, int]) -> str:
    """Why whole groups of ``counts`` records cannot make ``sizes``, and what they can."""
    total = int(counts.sum())
    reachable = np.zeros(total + 1, dtype=bool)
    reachable[0] = True
    for size in counts:
        reachable[size:] |= reachable[: total + 1 - size].copy()
    possible = np.flatnonzero(reachable[1:]) + 1
    size_counts = dict(zip(*np.unique(counts, return_counts=True), strict=True))
    held = ", ".join(f"{c} x {int(s)}" for s, c in sorted(size_counts.items()))
    step = int(np.gcd.reduce(counts))
    if np.array_equal(possible, np.arange(step, total + 1, step)):
        can = f"multiples of {step} up to {total}"
    else:
        can = ", ".join(str(int(s)) for s in possible[:40]) + (
            ", ..." if possible.size > 40 else ""
        )
    wanted = ", ".join(f"n_{name} = {size}" for name, size in zip(SPLITS, sizes, strict=True))
    if all(reachable[size] for size in sizes):
        why = "each size alone can be made of whole groups, but not all three at once"
    else:
        why = "; ".join(
            f"n_{name} = {size} cannot (nearest: {_nearest(possible, size)})"
            for name, size in zip(SPLITS, sizes, strict=True)
            if not reachable[size]
        )
    return (
        f"{wanted} cannot be made of whole groups: the {total} records form {counts.size} "
        f"groups (sizes {held}), so a split can hold {can} records; {why}"
    )


def _nearest(possible: np.ndarray, size: int) -> str:
    """The possible split sizes just below and above ``size``."""
    below, above = possible[possible < size], possible[possible > size]
    return " or ".join(str(int(v)) for v in (*below[-1:], *above[:1]))
