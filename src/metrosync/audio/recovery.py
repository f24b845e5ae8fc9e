"""Ticks that another tick hid, found again where their metronome's beat puts them.

Contract: `recover(recording, scan, ticks, trains)` takes the ticks (`detection.Ticks`,
sorted) and the metronomes' trains over them (`trains.Train`), and returns (ticks,
trains, found): the ticks with those it recovered added, the trains with each
recovered tick in its beat, and how many were recovered.

A tick that falls a few milliseconds after another metronome's, or on its ringing,
barely raises the detection curve: the detector's threshold, set for the whole
recording, misses it. Its metronome's beat says where it is. For each beat a train
missed, its time is predicted from the ticks a full swing before and after (their
mean when both were heard: exact for an uneven beat and a steady drift); the
detection curve's highest point within `WINDOW` of it, if it rises at least
`MIN_RISE` dB, is timed on the waveform like any tick (`detection.refine`), and kept
when its onset lies within `TOLERANCE` of the prediction and no tick is within the
detector's resolution (`detection.RESOLUTION`) of it.
"""

from __future__ import annotations

import numpy as np

from . import detection as det
from .trains import Train

WINDOW = 3e-3
MIN_RISE = 1.0
TOLERANCE = 1.5e-3


def _predictions(times: np.ndarray, train: Train) -> tuple[np.ndarray, np.ndarray]:
    """(beats missed, their predicted times) of one train."""
    beat = train.beat
    t = times[train.index]
    at = dict(zip(beat.tolist(), t.tolist(), strict=True))
    missing = np.setdiff1d(np.arange(beat[0], beat[-1] + 1), beat)
    swing = 2 * train.period
    out_n, out_t = [], []
    for n in missing.tolist():
        before, after = at.get(n - 2), at.get(n + 2)
        if before is not None and after is not None:
            p = 0.5 * (before + after)
        elif before is not None:
            p = before + swing
        elif after is not None:
            p = after - swing
        else:
            continue
        out_n.append(n)
        out_t.append(p)
    return np.array(out_n, dtype=np.int64), np.array(out_t)


def recover(recording, scan, ticks, trains: list[Train]):
    """(ticks, trains, recovered): see the module docstring."""
    rate = recording.sample_rate
    hop_s = scan.hop / rate
    reach = max(1, round(WINDOW / hop_s))
    owners, beats, predicted = [], [], []
    for m, train in enumerate(trains):
        n, p = _predictions(ticks.time, train)
        owners.append(np.full(n.size, m))
        beats.append(n)
        predicted.append(p)
    if not trains:
        return ticks, trains, 0
    owner, beat, pred = (np.concatenate(x) for x in (owners, beats, predicted))
    if pred.size == 0:
        return ticks, trains, 0
    centre = np.round(pred / hop_s).astype(np.int64)
    offsets = np.arange(-reach, reach + 1)
    cols = np.clip(centre[:, None] + offsets[None, :], 0, scan.curve.size - 1)
    best = cols[np.arange(cols.shape[0]), np.argmax(scan.curve[cols], axis=1)]
    ok = scan.curve[best] >= MIN_RISE
    owner, beat, pred, best = owner[ok], beat[ok], pred[ok], best[ok]
    if best.size == 0:
        return ticks, trains, 0
    order = np.argsort(best, kind="stable")
    owner, beat, pred, best = owner[order], beat[order], pred[order], best[order]
    found = det.refine(recording, scan, best)
    near = np.abs(found.time - pred) <= TOLERANCE
    j = np.clip(np.searchsorted(ticks.time, found.time), 1, max(ticks.time.size - 1, 1))
    gap = np.minimum(np.abs(ticks.time[j] - found.time), np.abs(ticks.time[j - 1] - found.time))
    near &= gap > det.RESOLUTION
    if not near.any():
        return ticks, trains, 0
    fields = det.Ticks.__dataclass_fields__
    merged = {f: np.concatenate([getattr(ticks, f), getattr(found, f)[near]]) for f in fields}
    order = np.argsort(merged["time"], kind="stable")
    new_ticks = det.Ticks(*(merged[f][order] for f in fields))
    where = np.empty(order.size, dtype=np.int64)
    where[order] = np.arange(order.size)
    base = ticks.time.size
    added_index = base + np.arange(int(near.sum()))
    new_trains = []
    for m, train in enumerate(trains):
        mine = owner[near] == m
        index = np.concatenate([train.index, added_index[mine]])
        number = np.concatenate([train.beat, beat[near][mine]])
        masked = np.concatenate([train.masked, np.zeros(int(mine.sum()), dtype=bool)])
        k = np.argsort(number, kind="stable")
        new_trains.append(Train(where[index[k]], number[k], train.period, masked[k]))
    return new_ticks, new_trains, int(near.sum())
