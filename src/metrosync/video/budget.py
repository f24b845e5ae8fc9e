"""What tracking a video will hold in memory and how long it will take (`metrosync.budget`).

Contract: `tracking_budget(video, ...)` describes a `track` request as a `Budget`, from
the video's checked header (`reader`) and the options alone, so that `track` refuses
what cannot fit before it decodes a frame, as every other entry point does. Its memory
is the larger of two parts done one after the other: finding the metronomes (the
pictures of the first seconds, and the detection's copies of them), then measuring
(per frame and metronome, the angles and their flags, and the r(t) grid, whose points
are the video's length over ``grid_dt``). Its time is not guessed: it is 0 until
``seconds_per_frame`` is measured on the first frames tracked, then that rate times
the frames left (a `LongRunWarning` when that is long).

The bytes are counted for the temporaries as well as the arrays kept, on the safe side
of what was measured on the 2-core x86-64 development machine (finding three
metronomes in 176 pictures of 640x360 peaked at 12 bytes a pixel; the grid's phases
are built as float64 and complex128 arrays of one row per metronome).
"""

from __future__ import annotations

import math

from .._words import plural
from ..budget import Budget, combine

#: Bytes per pixel of each picture the metronomes are found in: the decoded grey
#: picture, its float32 copy, and the detection's float32 differences and masks.
PICTURE_BYTES = 16
#: Bytes per frame of the measurements (its time and the lists they are gathered in),
#: and per frame and metronome (angle, strength, skew, quality, confidence, the angle
#: seen, and the copies of writing them).
FRAME_BYTES, METRONOME_FRAME_BYTES = 256, 192
#: Bytes per point of the r(t) grid, and per point and metronome (each one's phase, the
#: stack of them, and the complex exponentials r is the mean of).
GRID_BYTES, METRONOME_GRID_BYTES = 64, 48


def learning_pictures(video, learn: float, most: int) -> int:
    """Pictures `track` keeps of the first ``learn`` s: every ``every``-th frame, so as
    to keep about ``most`` (as `metrosync.video.tracking` takes them)."""
    length = min(learn, video.duration) if math.isfinite(video.duration) else learn
    rate = max(video.nominal_fps if math.isfinite(video.nominal_fps) else 0.0, 1.0)
    if video.frames_estimate and math.isfinite(video.duration) and video.duration > 0:
        # a file may declare a nominal rate below the one its frames come at
        rate = max(rate, video.frames_estimate / video.duration)
    every = max(1, int(round(learn * max(video.nominal_fps, 1.0) / most)))
    return math.ceil(length * rate / every) + 1


def tracking_budget(
    video,
    *,
    metronomes: int,
    max_side: int,
    learn: float,
    grid_dt: float,
    most_pictures: int,
    frames: int | None = None,
    length: float | None = None,
    seconds_per_frame: float | None = None,
    frames_done: int = 0,
) -> Budget:
    """The `Budget` of tracking ``video`` (a `metrosync.video.reader.Video`).

    metronomes : how many are tracked (before they are found: those asked for, or 1).
    max_side, learn, grid_dt : as `track` takes them.   most_pictures : the most
    pictures kept for finding the metronomes.
    frames, length : the frames and seconds the video holds (default: its header's).
    seconds_per_frame : the time one frame took to track, measured; its ``frames_done``
    first frames are done.
    """
    width, height = video.scaled_size(max_side)
    pictures = learning_pictures(video, learn, most_pictures)
    frames = video.frames_estimate if frames is None else frames
    length = video.duration if length is None else length
    points = length / grid_dt + 1 if math.isfinite(length) and length > 0 else 1.0
    name = f"tracking {video.path.name}"
    finding = Budget(
        name,
        {"the pictures metronomes are found in": PICTURE_BYTES * float(pictures) * width * height},
        fixes=f"a smaller `max_side` (now {max_side}) or a shorter `learn` (now {learn:g} s)",
    )
    left = max(frames - frames_done, 0)
    seconds, work = 0.0, ""
    if seconds_per_frame is not None:
        seconds = seconds_per_frame * left
        work = (
            f"{plural(left, 'frame')} left, {plural(metronomes, 'metronome')}, measured at "
            f"{seconds_per_frame * 1e3:.3g} ms a frame"
        )
    arrays = {
        "the angles of every frame": float(frames)
        * (FRAME_BYTES + METRONOME_FRAME_BYTES * metronomes),
        "the r(t) grid": points * (GRID_BYTES + METRONOME_GRID_BYTES * metronomes),
    }
    if arrays["the r(t) grid"] >= arrays["the angles of every frame"]:
        fixes = (
            f"a larger `grid_dt` (now {grid_dt:g} s: {points:.2g} points over "
            f"{length:.1f} s of video)"
        )
    else:
        fixes = "a shorter video: cut it into parts and track each"
    measuring = Budget(name, arrays, seconds, work, fixes)
    if seconds_per_frame is not None:
        # measured once the memory was checked: what is left to shrink is the time
        quicker = f"a smaller `max_side` (now {max_side}), which makes each frame quicker"
        return combine(name, finding, measuring, fixes=quicker)
    # the larger part's arrays and fixes: they are what to shrink
    return combine(name, finding, measuring)
