"""Observations that are an array or a dict of arrays (a ``Dict`` space, such
as a map beside a vector), handled alike: as float32, stacked over steps,
indexed by rows, as torch tensors; and which spaces are maps.

>>> batch = stack([{"map": np.zeros((2, 3)), "vector": np.ones(4)}] * 5)
>>> {k: v.shape for k, v in take(batch, [0, 2]).items()}
{'map': (2, 2, 3), 'vector': (2, 4)}
"""
from __future__ import annotations

import numpy as np

__all__ = ["is_map_space", "as_float32", "stack", "take", "length", "as_tensor"]


def is_map_space(space) -> bool:
    """Whether ``space`` is a map: a ``Box`` of three axes (channels, rows,
    columns), such as a costmap or an image."""
    from gymnasium.spaces import Box

    return isinstance(space, Box) and len(space.shape) == 3


def as_float32(obs, copy: bool = False):
    """``obs`` as float32 arrays (each value of a dict); with ``copy``, always
    copies (an environment may write its next observation into the same
    buffer)."""
    convert = np.array if copy else np.asarray
    if isinstance(obs, dict):
        return {k: convert(v, dtype=np.float32) for k, v in obs.items()}
    return convert(obs, dtype=np.float32)


def stack(rows: list):
    """One float32 array of ``rows`` (observations), or one per key of dict
    observations."""
    if rows and isinstance(rows[0], dict):
        return {k: np.stack([np.asarray(r[k], dtype=np.float32) for r in rows])
                for k in rows[0]}
    return np.asarray(rows, dtype=np.float32)


def take(batch, index):
    """The rows ``index`` of a batch (of each array of a dict)."""
    if isinstance(batch, dict):
        return {k: v[index] for k, v in batch.items()}
    return batch[index]


def length(batch) -> int:
    """The number of rows of a batch."""
    if isinstance(batch, dict):
        return len(next(iter(batch.values())))
    return len(batch)


def as_tensor(batch):
    """A batch as float32 torch tensors (a dict of them for a dict)."""
    import torch

    if isinstance(batch, dict):
        return {k: torch.as_tensor(np.asarray(v), dtype=torch.float32) for k, v in batch.items()}
    return torch.as_tensor(np.asarray(batch), dtype=torch.float32)
