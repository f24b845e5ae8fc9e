"""The sound track of a filmed run: a click at every passage through the vertical.

Each metronome has a pitch of its own (the clicks of `metrosync listen`); a click
starts at the sample nearest its tick time plus the microphone's delay, with gain
0.9/N so the mix never clips; background noise is added. The track is rendered and
encoded one AAC-sized block at a time as the picture advances, so the muxer
interleaves sound and picture and memory does not grow with the length.
"""

from __future__ import annotations

import math
from fractions import Fraction

import av
import numpy as np

from ..show.sound import PITCH_RANGE, click_waveform

#: Audio samples per encoded audio frame.
AUDIO_FRAME = 1024


class Sound:
    """The sound track, rendered and encoded block by block as the picture advances."""

    def __init__(self, container, mic, ticks: list[np.ndarray], rng):
        self.mic, self.rate = mic, mic.sample_rate
        self.stream = container.add_stream(mic.codec, rate=self.rate, layout="mono")
        self.container = container
        self.rng = rng
        n = len(ticks)
        pitches = np.linspace(*PITCH_RANGE, n) if n > 1 else [PITCH_RANGE[0]]
        self.waves = [0.9 / n * click_waveform(p, self.rate) for p in pitches]
        onsets, owners = [], []
        for i, times in enumerate(ticks):
            onsets.append(np.round((times + mic.delay_s) * self.rate).astype(np.int64))
            owners.append(np.full(times.size, i))
        onsets, owners = np.concatenate(onsets), np.concatenate(owners)
        order = np.argsort(onsets, kind="stable")
        self.onsets, self.owners = onsets[order], owners[order]
        self.longest = max(w.size for w in self.waves)
        self.done = 0
        self.s16 = mic.codec == "pcm_s16le"

    def until(self, t: float) -> None:
        end = int(math.floor(t * self.rate))
        while self.done + AUDIO_FRAME <= end:
            self._frame()

    def _frame(self) -> None:
        s0, n = self.done, AUDIO_FRAME
        block = (
            self.rng.normal(0.0, self.mic.noise, n).astype(np.float32)
            if self.mic.noise
            else (np.zeros(n, np.float32))
        )
        lo = np.searchsorted(self.onsets, s0 - self.longest, side="left")
        hi = np.searchsorted(self.onsets, s0 + n, side="left")
        for onset, owner in zip(self.onsets[lo:hi], self.owners[lo:hi], strict=True):
            wave = self.waves[owner]
            a, b = max(s0, onset), min(s0 + n, onset + wave.size)
            if b > a:
                block[a - s0 : b - s0] += wave[a - onset : b - onset]
        np.clip(block, -1.0, 1.0, out=block)
        if self.s16:
            frame = av.AudioFrame.from_ndarray(
                (block * 32767).astype(np.int16)[None, :], format="s16", layout="mono"
            )
        else:
            frame = av.AudioFrame.from_ndarray(block[None, :], format="fltp", layout="mono")
        frame.sample_rate = self.rate
        frame.pts = s0
        frame.time_base = Fraction(1, self.rate)
        self.container.mux(self.stream.encode(frame))
        self.done += n

    def close(self) -> None:
        self.container.mux(self.stream.encode(None))
