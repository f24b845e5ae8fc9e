"""Bootstrap resampling of per-run values, each point among its own runs.

A point of a sweep may hold fewer runs than the widest one (`Grid.target_error` grows
each point to its own count; flagged runs are NaN): its row is padded with NaN. A
bootstrap replica of such a row draws, with replacement, as many values as the row
has finite ones, from those alone, so that a replica has the point's own number of
runs. Rows without NaN are drawn exactly as `numpy.random.Generator.integers` indices
over all runs.
"""

from __future__ import annotations

import numpy as np


def resample_runs(values, rng: np.random.Generator, size: tuple[int, ...]) -> np.ndarray:
    """Bootstrap replicas of ``values`` (..., B): one draw of run indices of shape
    ``size``, which broadcasts against ``values`` (e.g. ``(replicas, *values.shape)``, or
    a 1 along an axis whose rows share their draw). Returns the broadcast shape; a
    row's slots past its count of finite runs are NaN."""
    values = np.asarray(values, dtype=float)
    runs = values.shape[-1]
    count = np.isfinite(values).sum(axis=-1, keepdims=True)
    if np.all(count == runs):
        idx = rng.integers(0, runs, size=size)
        packed = values
    else:
        packed = np.sort(values, axis=-1)  # the finite runs first, NaN last
        idx = (rng.random(size) * count).astype(np.int64)
    shape = np.broadcast_shapes(idx.shape, values.shape)
    out = np.take_along_axis(np.broadcast_to(packed, shape), np.broadcast_to(idx, shape), axis=-1)
    if packed is values:
        return out
    return np.where(np.arange(runs) < count, out, np.nan)
