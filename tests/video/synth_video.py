"""Small synthetic videos for the tracker's tests: rods drawn with numpy, encoded by PyAV.

Not a camera model: a flat, square-on picture with a plain or noisy background, rods
of given angles θ_j(t) about given pivots, frame times of our choosing (for variable
rates), and optionally a rotation tag and a click track.
"""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import av
import numpy as np


def angles_sine(t, freq_hz, amplitude, phase):
    """(T, N) θ = A sin(2π f t + φ) for each metronome."""
    t = np.asarray(t)[:, None]
    return amplitude * np.sin(2 * np.pi * np.asarray(freq_hz) * t + np.asarray(phase))


def draw(
    theta, pivots, *, size=(480, 270), length=80, width=4, noise=0.0, rng=None, background=None
):
    """One grey picture (H, W) uint8 with a rod per metronome (pivot below, rod up)."""
    w, h = size
    img = np.full((h, w), 40.0) if background is None else background.astype(float).copy()
    yy, xx = np.mgrid[0:h, 0:w]
    for th, (px, py) in zip(theta, pivots, strict=True):
        ux, uy = np.sin(th), -np.cos(th)
        dx, dy = xx - px, yy - py
        along = dx * ux + dy * uy
        across = np.abs(dx * uy - dy * ux)
        rod = (along > 0) & (along < length) & (across < width / 2)
        bob = (np.abs(along - 0.7 * length) < 6) & (across < 7)
        img[rod | bob] = 220.0
        img[(dx**2 + dy**2) < 16] = 120.0
    if noise:
        img += rng.normal(0, noise, img.shape)
    return np.clip(img, 0, 255).astype(np.uint8)


def write_video(
    path,
    times,
    pictures,
    *,
    rate=30,
    rotation=0,
    codec="libx264",
    audio=None,
    audio_rate=44100,
    time_base=Fraction(1, 90000),
):
    """Encode grey pictures at the given frame times (s) to ``path``; ``audio`` is an
    optional mono float array played from t = 0."""
    path = Path(path)
    with av.open(str(path), "w") as out:
        stream = out.add_stream(codec, rate=rate)
        first = next(iter(pictures))
        stream.height, stream.width = first.shape
        stream.pix_fmt = "yuv420p"
        stream.time_base = time_base
        stream.codec_context.time_base = time_base
        if codec == "libx264":
            stream.options = {"crf": "18", "preset": "ultrafast"}
        if rotation:
            stream.set_display_rotation(rotation)
        astream = None
        if audio is not None:
            astream = out.add_stream("aac", rate=audio_rate)
            astream.layout = "mono"
        for t, pic in zip(times, _chain(first, pictures), strict=False):
            frame = av.VideoFrame.from_ndarray(np.stack([pic] * 3, axis=-1), format="rgb24")
            frame = frame.reformat(format="yuv420p")
            frame.pts = int(round(t / time_base))
            frame.time_base = time_base
            for packet in stream.encode(frame):
                out.mux(packet)
        for packet in stream.encode():
            out.mux(packet)
        if astream is not None:
            block = 1024
            samples = np.asarray(audio, dtype=np.float32)
            for i in range(0, samples.size - block + 1, block):
                af = av.AudioFrame.from_ndarray(
                    samples[None, i : i + block], format="fltp", layout="mono"
                )
                af.sample_rate = audio_rate
                af.pts = i
                for packet in astream.encode(af):
                    out.mux(packet)
            for packet in astream.encode():
                out.mux(packet)
    return path


def _chain(first, rest):
    yield first
    yield from rest


def scene(
    path,
    *,
    n=3,
    seconds=12.0,
    fps=30.0,
    jitter=0.0,
    drop=0.0,
    seed=0,
    size=(480, 270),
    noise=3.0,
    rotation=0,
    audio=False,
    freq=None,
    amplitude=0.45,
):
    """Write a scene of ``n`` rods in a row and return (times, θ (T, N), pivots)."""
    rng = np.random.default_rng(seed)
    w, h = size
    pivots = [(w * (j + 1) / (n + 1), h * 0.8) for j in range(n)]
    nominal = np.arange(0, seconds, 1 / fps)
    times = nominal + rng.uniform(-jitter, jitter, nominal.size) * (1 / fps)
    times[0] = 0.0
    keep = rng.uniform(size=times.size) >= drop
    keep[:2] = True
    times = np.sort(times[keep])
    f = np.full(n, 1.4) + rng.normal(0, 0.03, n) if freq is None else np.asarray(freq)
    phase = rng.uniform(0, 2 * np.pi, n)
    theta = angles_sine(times, f, amplitude, phase)
    length = 0.28 * h
    pictures = (draw(th, pivots, size=size, length=length, noise=noise, rng=rng) for th in theta)
    sound = None
    if audio:
        sound = clicks(times, theta, 44100)
    write_video(path, times, pictures, rate=round(fps), rotation=rotation, audio=sound)
    return times, theta, np.array(pivots)


def clicks(times, theta, rate):
    """A click track: a short burst at each crossing of the vertical (both ways)."""
    t_end = times[-1]
    sound = np.zeros(int(t_end * rate) + rate)
    burst = np.sin(2 * np.pi * 3000 * np.arange(200) / rate) * np.exp(-np.arange(200) / 40)
    for j in range(theta.shape[1]):
        s = np.sign(theta[:, j])
        for i in np.flatnonzero(s[:-1] != s[1:]):
            a0, a1 = theta[i, j], theta[i + 1, j]
            tc = times[i] + (times[i + 1] - times[i]) * a0 / (a0 - a1)
            k = int(tc * rate)
            sound[k : k + 200] += 0.5 * burst[: sound[k : k + 200].size]
    return sound
