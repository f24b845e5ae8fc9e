"""Light-gate measurement: the experiment's pipeline (paper §2), real or virtual.

``reader``    logger captures → `GateLog` (wraps, polarity, skipped lines)
``cleaning``  gate edges → one pass per period in one direction (`ChannelPasses`)
``phases``    passes → phases, r(t), mean frequencies, jitter, σ
``analyze``   the entry point: log files → `xarray.Dataset`
``virtual``   a virtual gate writing logs from simulated trajectories
``messages``  the logger's header and overflow lines, `record`'s gap lines
``follow``    a growing capture, read as the finished file would be
``live``      what the live panel shows: passes, BPM, silence, running r(t)
``recorder``  the logger's serial stream → a capture file, safely
``replay``    a capture written into a serial line at its own pace
``summary``   the printed summary of an analysed dataset
"""

from .analyze import analyze, analyze_logs
from .cleaning import ChannelPasses, clean_channel, clean_log, cleaning_report
from .follow import LogFollower
from .messages import LoggerHeader
from .reader import GateLog, SkippedLine, parse_log, read_log
from .virtual import LightGate, format_log, gate_edges, write_logs

__all__ = [
    "ChannelPasses",
    "GateLog",
    "LightGate",
    "LogFollower",
    "LoggerHeader",
    "SkippedLine",
    "analyze",
    "analyze_logs",
    "clean_channel",
    "clean_log",
    "cleaning_report",
    "format_log",
    "gate_edges",
    "parse_log",
    "read_log",
    "write_logs",
]
