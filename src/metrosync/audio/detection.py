"""Tick detection: every tick's onset time (sub-millisecond) and strength.

Contract: `scan(recording)` reads the file once, block by block, and returns a `Scan`:
the detection curve, its adaptive threshold, a min/max waveform for plots, and the
level checks (peak, clipping). `pick_ticks(scan, refractory)` finds the ticks on the
curve, and `refine(recording, scan, frames)` times each one on the waveform itself.
Memory is bounded by one block and the curve (two float32 per 0.5 ms).

The detection curve. The channels are averaged and band-passed (Butterworth, 4 poles,
`band`, default 1–10 kHz: a tick's click is loud there, room rumble and voices are
mostly below). The power is summed over hops of `HOP` (0.5 ms). The curve is the rise
in dB of the power over the next `AHEAD` (1 ms) above the mean power over the
preceding `PAST` (4 ms): a tick is a sudden rise, whatever its loudness, while steady
noise and a decaying reverberation tail stay near 0 dB.

The threshold adapts to the room: over spans of `THRESHOLD_SPAN` (2 s), the median of
the curve plus `sensitivity` times its robust spread above the median (1.4826 × the
median of the deviations above it: the fast falls of a decaying reverberation, below
the median, do not raise the threshold), and never below `MIN_RISE` dB; linear
between the spans' centres. A tick is a peak of the curve above the threshold that
is the largest within ± the refractory time, which the caller derives from the
tempo, so that the echo or the rattle of a click is not a tick of its own. Rises
below the noise of 16-bit sound (−100 dBFS) do not count.

Onset times. Around each tick the waveform (channels averaged) is band-passed again
with the same filter run forwards and backwards (no delay), and its envelope taken
(Hilbert). The onset is the instant, interpolated between samples, at which the
envelope first rises, within `RISE_WINDOW` before the tick's peak, through
`ONSET_FRACTION` (a quarter) of the way from the background before the tick to the
peak, and `NOISE_CLEARANCE` robust spreads above that background (at most halfway):
a tick's resonances can beat and dip after its first impact, whose onset is wanted.
For a click that starts abruptly it is the click's first sample within a
few tens of microseconds, and echoes, which come later, do not move it. The strength
of a tick is its envelope peak (dBFS), also per channel.

A knock on the phone. A hand that knocks the phone makes a crack (a millisecond of
broadband noise) and a low thump. A crack a few milliseconds before a tick is the
rise the detector hears, and the tick, within the refractory time, is not heard
apart: its onset would be the crack's. Where the waveform smoothed over a millisecond
(what is left of the thump) swings right after the rise and far less before it
(`THUMP_LEVEL`, `THUMP_RISE`: a tick within a thump already going on is left alone),
and the envelope then falls below `CRACK_DIP` of the crack's and rises again within
`CRACK_REACH`, the onset is that later rise's, timed the same way from the dip.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from scipy import fft, ndimage, signal

from .._words import plural
from .reader import AudioFileError, Recording
from .settings import DEFAULT_BAND, DEFAULT_SENSITIVITY, DEFAULT_TOP

HOP = 0.5e-3
AHEAD = 1.0e-3
PAST = 4.0e-3
#: A tick that starts less than this after another is hidden in the detection curve
#: (it sees the other's power as its own background), s.
RESOLUTION = PAST + AHEAD
THRESHOLD_SPAN = 2.0
MIN_RISE = 6.0
#: Samples at or above this magnitude count as clipped.
CLIP_LEVEL = 0.999
#: Width of one column of the plotted waveform, in hops.
DISPLAY_HOPS = 10
#: The onset is where the envelope rises through this fraction of the way from the
#: background to the tick's peak.
ONSET_FRACTION = 0.25
#: The onset is sought this far before the envelope's peak, s.
RISE_WINDOW = 2.5e-3
#: ... and at least this many robust spreads of the envelope before the tick above its
#: median (at most halfway up).
NOISE_CLEARANCE = 6.0
#: Half-width of the waveform window timed around each tick, s.
REFINE_HALF = 6e-3
#: A knock on the phone opens with a crack, a burst of broadband noise that the
#: detector hears as a rise, and goes on as a low thump. Its rise is taken for a crack
#: where the waveform smoothed over this long (s; it keeps the thump, not the clicks)
THUMP_SMOOTHING = 1e-3
#: ... swings within this long after the rise (s)
THUMP_AFTER = 3e-3
#: ... more than over this long before it (s)
THUMP_BEFORE = 5e-3
#: ... by more than this times the tick's band-passed peak
THUMP_LEVEL = 0.7
#: ... and by this many times more than just before the rise.
THUMP_RISE = 5.0
#: The crack's own burst lasts about this long (s) ...
CRACK_OWN = 0.5e-3
#: ... and a tick that begins after it is sought this far after it (s), ...
CRACK_REACH = 5e-3
#: ... at a peak at least this many times the crack's, ...
CRACK_TICK = 0.5
#: ... after the crack has fallen below this fraction of its own (a tick's ring does
#: not fall so far so soon).
CRACK_DIP = 0.2
#: Power floor per sample (−100 dBFS, about the noise of 16-bit sound): quieter rises
#: are not ticks, and the logarithms of digital silence stay finite.
_FLOOR = 1e-10


@dataclass(frozen=True)
class Scan:
    """What one pass over a recording found.

    hop : frames per hop of the detection curve.
    curve : (F,) detection curve, dB (rise of the power into each hop).
    threshold : (F,) adaptive threshold on the curve, dB.
    level : (F,) band-passed power over each hop, dBFS.
    wave_min, wave_max : (D,) range of the channel mix over each `DISPLAY_HOPS` hops.
    peak : largest sample magnitude, any channel (1 = full scale).
    clipped : samples at or above `CLIP_LEVEL` (any channel).
    band : the band-pass edges used, Hz.
    sos : the band-pass filter (second-order sections).
    """

    hop: int
    curve: np.ndarray
    threshold: np.ndarray
    level: np.ndarray
    wave_min: np.ndarray
    wave_max: np.ndarray
    peak: float
    clipped: int
    band: tuple[float, float]
    sos: np.ndarray


def band_filter(band, sample_rate: int) -> tuple[tuple[float, float], np.ndarray]:
    """The band-pass for ``band`` (Hz); None: `DEFAULT_BAND`, its top lowered to
    `DEFAULT_TOP` × the rate where the rate is too low for it.

    A band given is used as given or refused: the digital Butterworth design needs
    both edges strictly inside (0, rate/2), the Nyquist frequency (at 44.1 kHz the top
    must be below 22 050 Hz), and the detector needs ``low`` >= 20 Hz.
    """
    if band is None:
        lo, hi = DEFAULT_BAND[0], min(DEFAULT_BAND[1], DEFAULT_TOP * sample_rate)
    else:
        lo, hi = (float(b) for b in band)
    nyquist = sample_rate / 2
    if not (np.isfinite(lo) and np.isfinite(hi) and 20.0 <= lo < hi < nyquist):
        raise AudioFileError(
            f"`band` must be two frequencies 20 Hz <= low < high < {nyquist:g} Hz, the "
            f"Nyquist frequency of this {sample_rate} Hz recording (a digital filter's "
            f"edges lie below half the sample rate), got {(lo, hi)!r}."
        )
    return (lo, hi), signal.butter(2, (lo, hi), btype="bandpass", fs=sample_rate, output="sos")


def scan(
    recording: Recording,
    *,
    band=None,
    sensitivity: float = DEFAULT_SENSITIVITY,
    progress=None,
) -> Scan:
    """Read ``recording`` once and build the detection curve and its threshold.

    progress : an object with ``update(frames)``, told after each block (or None).

    Raises `AudioFileError` for a file whose every sample is 0; warns for one that
    clipped or is very quiet.
    """
    rate = recording.sample_rate
    hop = max(1, round(HOP * rate))
    band, sos = band_filter(band, rate)
    zi = np.zeros((sos.shape[0], 2))
    block = hop * DISPLAY_HOPS * max(1, (1 << 20) // (hop * DISPLAY_HOPS))
    energies, mins, maxs = [], [], []
    peak, clipped = 0.0, 0
    rest = np.zeros(0, dtype=np.float32)
    for _, data in recording.blocks(block):
        magnitude = np.abs(data)
        peak = max(peak, float(magnitude.max()))
        clipped += int(np.count_nonzero(magnitude >= CLIP_LEVEL))
        del magnitude
        # float64: scipy's sosfilt runs twice as fast on it as on float32
        mix = data @ np.full(data.shape[1], 1.0 / data.shape[1])
        mix = np.concatenate([rest, mix]) if rest.size else mix
        whole = mix.size - mix.size % (hop * DISPLAY_HOPS)
        if whole == 0:
            rest = mix
            continue
        rest = mix[whole:].copy()
        mix = mix[:whole]
        y, zi = signal.sosfilt(sos, mix, zi=zi)
        energies.append((y * y).reshape(-1, hop).sum(axis=1).astype(np.float32))
        cols = mix.reshape(-1, hop * DISPLAY_HOPS)
        mins.append(cols.min(axis=1))
        maxs.append(cols.max(axis=1))
        if progress is not None:
            progress.update(data.shape[0])
    if rest.size:  # the last partial column, padded with silence
        padded = np.zeros(hop * DISPLAY_HOPS, dtype=np.float32)
        padded[: rest.size] = rest
        y, zi = signal.sosfilt(sos, padded, zi=zi)
        energies.append((y * y).reshape(-1, hop).sum(axis=1).astype(np.float32))
        mins.append(np.array([rest.min()], dtype=np.float32))
        maxs.append(np.array([rest.max()], dtype=np.float32))
    _check_levels(recording, peak, clipped)
    energy = np.concatenate(energies)
    del energies
    curve = detection_curve(energy, hop)
    threshold = adaptive_threshold(curve, hop / rate, sensitivity)
    level = 10 * np.log10(energy / np.float32(hop) + np.float32(_FLOOR))
    return Scan(
        hop, curve.astype(np.float32), threshold.astype(np.float32), level.astype(np.float32),
        np.concatenate(mins), np.concatenate(maxs), peak, clipped, band, sos,
    )  # fmt: skip


def _check_levels(recording: Recording, peak: float, clipped: int) -> None:
    name = str(recording.path)
    if peak == 0.0:
        raise AudioFileError(
            f"recording {name!r} is silent: every sample is 0. Check the microphone "
            f"and that the file is the recording you meant."
        )
    if peak < 10 ** (-60 / 20):
        warnings.warn(
            f"recording {name!r} is very quiet (peak {20 * np.log10(peak):.0f} dBFS); "
            f"ticks may drown in the noise of the recorder: record closer or louder.",
            UserWarning,
            stacklevel=3,
        )
    if clipped:
        share = clipped / (recording.frames * recording.channels)
        warnings.warn(
            f"recording {name!r} clipped: {plural(clipped, 'sample')} ({100 * share:.2g} %) "
            f"at full scale. Tick times stay usable, but loudness (tick strengths, and telling "
            f"metronomes apart by it) is capped: record with a lower input gain.",
            UserWarning,
            stacklevel=3,
        )


def detection_curve(energy: np.ndarray, hop: int, *, chunk: int = 1 << 20) -> np.ndarray:
    """(F,) rise (dB) of the mean power over `AHEAD` above that over the preceding `PAST`.

    energy : (F,) band-passed energy summed over each hop of ``hop`` samples. Before
    the first hop the power is taken as the mean of the first `PAST`, after the last
    as 0. Computed ``chunk`` hops at a time: the temporary arrays stay small.
    """
    ahead = max(1, round(AHEAD / HOP))
    past = max(1, round(PAST / HOP))
    floor = _FLOOR * hop
    f = energy.size
    start = np.full(past, energy[:past].mean(dtype=np.float64))
    padded = np.concatenate([start, energy, np.zeros(ahead)])
    curve = np.empty(f, dtype=np.float32)
    for lo in range(0, f, chunk):
        hi = min(f, lo + chunk)
        # hop k of the chunk sits at padded[past + k]
        c = np.concatenate([[0.0], np.cumsum(padded[lo : hi + past + ahead], dtype=np.float64)])
        k = np.arange(hi - lo) + past
        power_ahead = (c[k + ahead] - c[k]) / ahead
        power_past = (c[k] - c[k - past]) / past
        curve[lo:hi] = 10 * np.log10((power_ahead + floor) / (power_past + floor))
    curve[0] = 0.0  # nothing before the first hop to rise from
    return curve


def adaptive_threshold(curve: np.ndarray, hop_seconds: float, sensitivity: float) -> np.ndarray:
    """(F,) median + ``sensitivity`` × robust upper spread of ``curve`` over spans of
    `THRESHOLD_SPAN`, at least `MIN_RISE`; linear between the spans' centres."""
    span = max(8, round(THRESHOLD_SPAN / hop_seconds))
    count = max(1, curve.size // span)
    edges = np.linspace(0, curve.size, count + 1).astype(int)
    centres, values = [], []
    for lo, hi in zip(edges[:-1], edges[1:], strict=True):
        part = curve[lo:hi]
        med = float(np.median(part))
        above = part[part >= med] - med
        spread = 1.4826 * float(np.median(above)) if above.size else 0.0
        centres.append(0.5 * (lo + hi))
        values.append(max(MIN_RISE, med + sensitivity * spread))
    return np.interp(np.arange(curve.size), centres, values)


def pick_ticks(scan: Scan, refractory_hops: int) -> np.ndarray:
    """(K,) hop indices of the ticks: peaks above the threshold that are the largest of
    the curve within ± ``refractory_hops``."""
    width = 2 * max(1, int(refractory_hops)) + 1
    local = ndimage.maximum_filter1d(scan.curve, size=width, mode="constant", cval=-np.inf)
    return np.flatnonzero((scan.curve >= local) & (scan.curve > scan.threshold))


@dataclass(frozen=True)
class Ticks:
    """Ticks timed on the waveform.

    time : (K,) onset times, s from the start of the recording.
    strength : (K,) envelope peak of the channel mix, dBFS.
    channel_strength : (K, C) envelope peak of each channel, dBFS.
    rise : (K,) value of the detection curve at the tick, dB.
    """

    time: np.ndarray
    strength: np.ndarray
    channel_strength: np.ndarray
    rise: np.ndarray

    @staticmethod
    def none(channels: int) -> Ticks:
        """No ticks, for a recording of ``channels`` channels."""
        empty = np.zeros(0)
        return Ticks(empty, empty, np.zeros((0, channels)), empty)

    def taken(self, which: np.ndarray) -> Ticks:
        """The ticks ``which`` (indices or a mask) selects, every field alike."""
        return Ticks(*(getattr(self, f)[which] for f in Ticks.__dataclass_fields__))

    def joined(self, other: Ticks) -> Ticks:
        """These ticks, then ``other``'s, every field alike."""
        return Ticks(*(np.concatenate([getattr(self, f), getattr(other, f)])
                       for f in Ticks.__dataclass_fields__))  # fmt: skip


def heard_apart(times: np.ndarray, refractory: float) -> np.ndarray:
    """(K,) of sorted onset ``times`` (s), those not within ``refractory`` (s) after the
    last one kept: two rises of the curve that `refine` times within it (a coder's
    pre-echo and the attack it precedes, both timed at the attack) are one impact."""
    keep = np.ones(times.size, dtype=bool)
    close = np.flatnonzero(np.diff(times) < refractory) + 1
    if not close.size:
        return keep
    last = times[0]
    for i in range(1, times.size):
        if times[i] - last < refractory:
            keep[i] = False
        else:
            last = times[i]
    return keep


def refine(recording: Recording, scan: Scan, hops: np.ndarray, *, chunk: int = 2048) -> Ticks:
    """Time the ticks found at ``hops`` on the waveform (see the module docstring)."""
    rate = recording.sample_rate
    half = round(REFINE_HALF * rate)
    starts = hops.astype(np.int64) * scan.hop - half
    times = np.empty(hops.size)
    strength = np.empty(hops.size)
    per_channel = np.empty((hops.size, recording.channels))
    for first, segments in _segments(recording, starts, 2 * half, chunk):
        sl = slice(first, first + segments.shape[0])
        onset, peak, channel_peak = _time_segments(segments, scan, half)
        times[sl] = (starts[sl] + onset) / rate
        strength[sl] = 20 * np.log10(peak + 1e-12)
        per_channel[sl] = 20 * np.log10(channel_peak + 1e-12)
    return Ticks(times, strength, per_channel, scan.curve[hops].astype(float))


def _time_segments(segments: np.ndarray, scan: Scan, half: int):
    """Onset (fractional sample in the segment), envelope peak of the mix, per channel."""
    hop = scan.hop
    width = segments.shape[1]
    mix = segments @ np.full(segments.shape[2], 1.0 / segments.shape[2], dtype=np.float32)
    filtered = signal.sosfiltfilt(scan.sos, mix, axis=1)
    env = np.abs(signal.hilbert(filtered, N=fft.next_fast_len(width), axis=1))[:, :width]
    lo, hi = half - 2 * hop, half + 4 * hop
    ip = lo + np.argmax(env[:, lo:hi], axis=1)
    rows = np.arange(env.shape[0])
    peak = env[rows, ip]
    before = env[:, : half - 2 * hop]
    background = np.median(before, axis=1)
    noise = 1.4826 * np.median(np.abs(before - background[:, None]), axis=1)
    # a quarter of the way up, and clear of the noise before the tick
    clear = np.minimum(background + NOISE_CLEARANCE * noise, 0.5 * (peak + background))
    level = np.maximum(background + ONSET_FRACTION * (peak - background), clear)
    # the first rise through the level within `RISE_WINDOW` before the peak: a tick's
    # resonances can beat and dip after its first impact, whose onset is wanted
    cols = np.arange(env.shape[1])
    reach = round(RISE_WINDOW * half / REFINE_HALF)
    near = (cols[None, :] >= np.maximum(ip - reach, 1)[:, None]) & (cols[None, :] <= ip[:, None])
    first = np.argmax((env >= level[:, None]) & near, axis=1)
    cracked = _opens_thump(mix, first, peak, half)
    for r in np.flatnonzero(cracked):
        first[r], level[r], peak[r] = _after_crack(env[r], first[r], level[r], peak[r], half)
    j = np.maximum(first - 1, 0)
    e0, e1 = env[rows, j], env[rows, np.minimum(j + 1, env.shape[1] - 1)]
    frac = np.clip((level - e0) / np.where(e1 > e0, e1 - e0, 1.0), 0.0, 1.0)
    if segments.shape[2] > 1:
        # the largest band-passed sample: within 2 % of the envelope's peak for a click
        # with 10 or more samples per cycle, and a third of the cost
        chan = np.abs(signal.sosfilt(scan.sos, segments, axis=1)[:, lo:hi, :])
        channel_peak = chan.max(axis=1)
    else:
        channel_peak = peak[:, None]
    return j + frac, peak, channel_peak


def _opens_thump(mix: np.ndarray, first: np.ndarray, peak: np.ndarray, half: int) -> np.ndarray:
    """(n,) True where the rise at ``first`` opens a low-frequency thump: the waveform
    smoothed over `THUMP_SMOOTHING` (which keeps what is below a few hundred hertz)
    swings, from its lowest to its highest, within `THUMP_AFTER` after the rise by more
    than `THUMP_LEVEL` times the band-passed peak, and by `THUMP_RISE` times more than
    over `THUMP_BEFORE` before it (where a thump already goes on, it swings there too)."""
    per_second = half / REFINE_HALF
    low = ndimage.uniform_filter1d(mix, max(1, round(THUMP_SMOOTHING * per_second)), axis=1)
    cols = np.arange(mix.shape[1])[None, :]
    after = (cols >= first[:, None]) & (cols < first[:, None] + THUMP_AFTER * per_second)
    before = (cols < first[:, None]) & (cols >= first[:, None] - THUMP_BEFORE * per_second)
    swing = _swing(low, after)
    return (swing > THUMP_LEVEL * peak) & (swing > THUMP_RISE * _swing(low, before))


def _swing(values: np.ndarray, where: np.ndarray) -> np.ndarray:
    """(n,) highest less lowest of each row of ``values`` where ``where`` (0 for none)."""
    high = np.max(np.where(where, values, -np.inf), axis=1)
    low = np.min(np.where(where, values, np.inf), axis=1)
    return np.where(where.any(axis=1), high - low, 0.0)


def _after_crack(env: np.ndarray, first: int, level: float, peak: float, half: int):
    """(first, level, peak) of the tick that begins after a knock's crack at ``first``,
    or the same three where none does: the crack, a burst of noise, decays within a
    millisecond or two; a tick that starts then rises from the dip it leaves to a peak
    `CRACK_TICK` times the crack's or more, within `CRACK_REACH`."""
    per_second = half / REFINE_HALF
    start = first + round(CRACK_OWN * per_second)
    stop = min(env.size, first + round(CRACK_REACH * per_second))
    if stop <= start + 2:
        return first, level, peak
    crack = env[first:start].max()
    top = start + int(np.argmax(env[start:stop]))
    dip = first + int(np.argmin(env[first : top + 1]))
    if env[top] < CRACK_TICK * crack or env[dip] > CRACK_DIP * crack:
        return first, level, peak
    new_level = env[dip] + ONSET_FRACTION * (env[top] - env[dip])
    rise = dip + int(np.argmax(env[dip : top + 1] >= new_level))
    return rise, new_level, env[top]


def _segments(recording: Recording, starts: np.ndarray, length: int, chunk: int):
    """Yield (index of the first, (n, length, C) segments) in order of ``starts`` (sorted),
    reading the file once and keeping only the blocks a segment needs (a few segments
    near the end of an hour's file do not hold it all); frames outside the file are
    zeros."""
    n = starts.size
    done = 0
    buffer = np.zeros((0, recording.channels), dtype=np.float32)
    buffer_start = 0
    stream = recording.blocks()
    exhausted = False
    while done < n:
        # extend the buffer until it covers the next tick's whole segment (zeros past the end)
        need = starts[done] + length
        while buffer_start + buffer.shape[0] < need:
            block = None if exhausted else next(stream, None)
            if block is None:
                exhausted = True
                block = (0, np.zeros((need - buffer_start - buffer.shape[0], recording.channels),
                                     dtype=np.float32))  # fmt: skip
            end = buffer_start + buffer.shape[0] + block[1].shape[0]
            if end <= starts[done]:  # all before the next segment: not kept
                buffer = buffer[:0]
                buffer_start = end
                continue
            buffer = np.concatenate([buffer, block[1]])
        end = buffer_start + buffer.shape[0]
        stop = done + int(np.searchsorted(starts[done:] + length, end, side="right"))
        stop = min(stop, done + chunk)
        idx = starts[done:stop] - buffer_start
        take = np.empty((stop - done, length, recording.channels), dtype=np.float32)
        for m, s in enumerate(idx):
            if s >= 0:
                take[m] = buffer[s : s + length]
            else:  # before the first frame
                take[m] = 0.0
                take[m, -s:] = buffer[: length + s]
        yield done, take
        done = stop
        if done < n:  # drop what no later segment needs
            keep_from = min(max(0, starts[done] - buffer_start), buffer.shape[0])
            buffer = buffer[keep_from:]
            buffer_start += keep_from
