"""See real metronomes: angles, passes, phases and r(t) measured from a video.

One entry point, `track(path)`; the steps are modules of their own: `reader` (the
file, streamed with the container's times), `detection` (the metronomes found from
what swings), `angles` (each rod's angle per frame), `tracking` (the steps in order),
`dataset` (passes, phases, r and the dataset), `regions` (metronomes given by hand),
`sound` (the audio track against the picture), `plots` (the preview of what was
found, and r(t)). `camera` films simulated runs as a phone would, with their ground
truth, for tests. `track` is imported on first use (it needs scipy and xarray), so
that the reader's checks stay quick to import.
"""

from .reader import VideoFileError, open_video

__all__ = ["VideoFileError", "open_video", "track"]


def __getattr__(name: str):
    if name == "track":
        from .tracking import track

        return track
    raise AttributeError(f"module 'metrosync.video' has no attribute {name!r}")
