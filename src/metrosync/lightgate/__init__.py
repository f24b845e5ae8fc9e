"""Light-gate measurement: the experiment's pipeline (paper §2), real or virtual.

``reader``    logger captures → `GateLog` (wraps, polarity, skipped lines)
``cleaning``  gate edges → one pass per period in one direction (`ChannelPasses`)
``phases``    passes → phases, r(t), mean frequencies, jitter, σ
``analyze``   the entry point: log files → `xarray.Dataset`
``virtual``   a virtual gate writing logs from simulated trajectories
"""

from .analyze import analyze
from .cleaning import ChannelPasses, clean_channel, clean_log, cleaning_report
from .reader import GateLog, SkippedLine, parse_log, read_log
from .virtual import LightGate, format_log, gate_edges, write_logs

__all__ = [
    "ChannelPasses",
    "GateLog",
    "LightGate",
    "SkippedLine",
    "analyze",
    "clean_channel",
    "clean_log",
    "cleaning_report",
    "format_log",
    "gate_edges",
    "parse_log",
    "read_log",
    "write_logs",
]
