"""See and hear a simulated run: animation, click track, interactive page, plots.

Every view reads the trajectories that `metrosync.simulate(..., trajectories=True)`
recorded, through `RecordedRun`; none of them simulates again. The exception is
`write_playground`, a page that runs the model live in the browser.
"""

from .animation import animate
from .page import write_page
from .playground import write_playground
from .plots import plot_run
from .recording import NoTrajectoriesError, RecordedRun
from .sound import ClickTrack, click_track, crossing_times, write_wav

__all__ = [
    "ClickTrack",
    "NoTrajectoriesError",
    "RecordedRun",
    "animate",
    "click_track",
    "crossing_times",
    "plot_run",
    "write_page",
    "write_playground",
    "write_wav",
]
