"""Following a capture as it grows: the same `GateLog` as reading the finished file.

Contract: `LogFollower` takes text as it arrives, from a file that another program
is writing (`poll`) or from a stream (`feed`), classifies each complete line once
(`reader.classify`), and `log()` assembles the lines so far (`reader.assemble`)
exactly as `read_log` would read the file as it stands at that moment: a final line
without its line end is a partial line, and a ``\\r`` at the end of what has arrived
is held back until the next byte says whether it began a ``\\r\\n``. So the analysis
of a followed capture equals the analysis of the finished file.

A file that shrinks (truncated or replaced by a new capture) is an error: the lines
already read no longer describe it.
"""

from __future__ import annotations

import codecs
from pathlib import Path

from ..errors import EmptyLogError, ParameterError
from .gatelog import GateLog
from .messages import LoggerHeader
from .reader import DEFAULT_TICK, Line, assemble, classify, split_lines


class LogFollower:
    """Reads a growing capture incrementally.

    Parameters
    ----------
    path : the capture to follow (None to take text only through `feed`).
    tick, counter_bits, polarity, strict : as for `read_log`.
    keep : keep only about this many recent lines in memory (and the logger's first
        header), for a live view of a run of days; `log` then reads those. None keeps
        every line, as the final analysis of a followed file needs.
    """

    def __init__(
        self,
        path: str | Path | None = None,
        *,
        tick: float = DEFAULT_TICK,
        counter_bits: int | str | None = "auto",
        polarity: int | str = "auto",
        strict: bool = False,
        keep: int | None = None,
    ):
        self.keep = keep
        self.n_lines = 0  # complete lines seen, kept or not
        self.path = None if path is None else Path(path)
        self.options = dict(tick=tick, counter_bits=counter_bits, polarity=polarity, strict=strict)
        self.source = "<stream>" if path is None else str(path)
        self.lines: list[Line] = []
        self.records = 0
        self._changes = [0] * 8  # level changes per gate, over the whole capture
        self._last_gates: str | None = None
        self._widths: list[int] = []  # gates per record of the last three records
        self._header: tuple[int, Line] | None = None  # the first header, and its index
        self._pending = ""  # text after the last complete line
        self._offset = 0
        self._decoder = codecs.getincrementaldecoder("utf-8")(errors="replace")

    def poll(self, *, final: bool = False) -> int:
        """Read what the file gained since the last call; returns the new complete lines.

        final : the file is finished: bytes of a character cut at the end are decoded
            now (as `read_log` decodes them), instead of waiting for the rest.
        """
        try:
            with open(self.path, "rb") as f:
                size = f.seek(0, 2)
                if size < self._offset:
                    raise ParameterError(
                        f"{self.source} shrank from {self._offset} to {size} bytes while it was "
                        f"followed; it was truncated or replaced. Follow the new capture anew."
                    )
                f.seek(self._offset)
                data = f.read(size - self._offset)
        except FileNotFoundError:
            if self._offset:
                raise ParameterError(f"{self.source} vanished while it was followed.") from None
            return 0  # not created yet: `record` may be about to start
        except OSError as error:
            raise ParameterError(f"cannot read {self.source!r}: {error.strerror}.") from None
        self._offset += len(data)
        return self.feed(self._decoder.decode(data, final=final))

    def feed(self, text: str) -> int:
        """Add text as it arrived; returns the number of new complete lines."""
        text = self._pending + text
        # The last line end seen: what follows is not a line yet, and a final \r may be
        # the first half of \r\n.
        end = max(text.rfind("\n"), text.rfind("\r", 0, len(text) - 1))
        if end < 0:
            self._pending = text
            return 0
        complete, self._pending = text[: end + 1], text[end + 1 :]
        new = [classify(line) for line in split_lines(complete)[0]]
        first = len(self.lines)
        self.lines.extend(new)
        for i, line in enumerate(new, start=first):
            if line.gates is None:
                if self._header is None and isinstance(line.message, LoggerHeader):
                    self._header = (i, line)
                continue
            self.records += 1
            last = self._last_gates
            if last is not None and len(last) == len(line.gates):
                for k, (a, b) in enumerate(zip(last, line.gates, strict=True)):
                    self._changes[k] += a != b
            self._last_gates = line.gates
            self._widths = [*self._widths[-2:], len(line.gates)]
        self.n_lines += len(new)
        if self.keep is not None and len(self.lines) > 2 * self.keep:
            del self.lines[: len(self.lines) - self.keep]
            if self._header is not None:
                self._header = (-1, self._header[1])  # now before every kept line
        return len(new)

    @property
    def gates(self) -> int | None:
        """Gates per record: the logger header's, or else that of the last three records
        when they agree (the first line of a stream may be a fragment); None before."""
        if self._header is not None:
            return self._header[1].message.channels
        if len(self._widths) == 3 and len(set(self._widths)) == 1:
            return self._widths[0]
        return None

    @property
    def changes(self) -> list[int]:
        """Per gate, level changes over the whole capture."""
        return list(self._changes)

    @property
    def interruptions(self) -> list[int]:
        """Per gate, beam interruptions (two level changes each) over the whole capture."""
        return [n // 2 for n in self._changes]

    def log(self, *, last: int | None = None) -> GateLog:
        """The capture so far, read as `read_log` reads the file as it stands now.

        last : read only the last ``last`` complete lines (and the logger's header, if
            it came before them): a bounded cost for a live view of a long run; times
            then count from the first of them.

        Raises `EmptyLogError` (a `LogFormatError`) while it has no record yet.
        """
        tail, terminated = split_lines(self._pending)
        first = 0 if last is None else max(0, len(self.lines) - last)
        lines = self.lines[first:]
        if self._header is not None and self._header[0] < first:  # -1: trimmed (`keep`)
            lines = [self._header[1], *lines]
        lines = lines + [classify(line) for line in tail]
        if not lines:
            raise EmptyLogError(f"{self.source}: the light-gate log is empty (no lines).")
        return assemble(lines, terminated, **self.options, source=self.source)
