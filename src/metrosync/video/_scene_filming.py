"""Frame by frame: the schedule of capture times, each frame's pixels, and the encoder.

`Filming` prepares once what does not change (the framing, the background in Y'CbCr,
each metronome's swept box and what of it nearer bodies hide, a bank of noise), then
renders and encodes one frame at a time, so memory does not grow with the length. The
conventions (times, pixels, rows) are those of `metrosync.video.camera`.
"""

from __future__ import annotations

import math
from fractions import Fraction
from pathlib import Path

import av
import numpy as np

from ..errors import ParameterError
from ..observables.entrainment import upward_crossings
from ._scene import Scene
from ._scene_render import (
    MIN_SWEEP,
    Pinhole,
    background,
    body_faces,
    composite,
    convex_coverage,
    finish_plane,
    restore,
    rod_coverage,
    rod_points,
)
from ._scene_sound import Sound

#: Tick of the presentation timestamps in each container: MP4 and MOV take a phone's
#: 1/90000 s, Matroska counts milliseconds, and AVI counts frame periods.
TIME_BASES = {"mp4": Fraction(1, 90000), "mov": Fraction(1, 90000), "matroska": Fraction(1, 1000)}
RGB_TO_YUV = np.array(
    [[65.481, 128.553, 24.966], [-37.797, -74.203, 112.0], [112.0, -93.786, -18.214]],
    np.float32,
)
YUV_OFFSET = np.array([16.0, 128.0, 128.0], np.float32)


def to_yuv(rgb) -> np.ndarray:
    """BT.601 limited-range Y'CbCr (..., 3) of RGB (..., 3) in [0, 1]."""
    return np.asarray(rgb, np.float32) @ RGB_TO_YUV.T + YUV_OFFSET


def half(a: np.ndarray) -> np.ndarray:
    """2×2 means of an (even, even) array."""
    return 0.25 * (a[0::2, 0::2] + a[1::2, 0::2] + a[0::2, 1::2] + a[1::2, 1::2])


def aim(scene: Scene, camera, sweeps: np.ndarray) -> Pinhole:
    """A pinhole that frames every metronome's body and swing at ``camera.framing``."""
    points = []
    for m, sweep in zip(scene.metronomes, sweeps, strict=True):
        angles = np.linspace(-sweep, sweep, 9)
        tips, _ = rod_points(m, angles)
        points.append(tips)
        for x in (-0.5 * m.base_width, 0.5 * m.base_width):
            points.append([[m.x + x, 0.0, m.z], [m.x + x, 0.0, m.z + m.body_depth]])
    points = np.vstack(points)
    target = 0.5 * (points.min(axis=0) + points.max(axis=0))
    extent = float(np.ptp(points, axis=0).max())
    distance = 2.0 * extent + 0.2
    pinhole = None
    for _ in range(6):
        pinhole = Pinhole.aimed(
            target, distance, yaw_deg=camera.yaw_deg, pitch_deg=camera.pitch_deg,
            roll_deg=camera.roll_deg + camera.rotation, hfov_deg=camera.hfov_deg,
            width=camera.width, height=camera.height,
        )  # fmt: skip
        xy = pinhole.project(points)
        centre = np.array([0.5 * (camera.width - 1), 0.5 * (camera.height - 1)])
        reach = np.abs(xy - centre).max(axis=0) / (camera.framing * centre)
        distance *= max(reach.max(), 0.2)
    return pinhole


class Filming:
    """One run filmed by one camera: schedule, static layers, per-frame rendering."""

    def __init__(self, scene: Scene, camera, times, theta, rng, fmt: str, *, pictures: bool = True):
        self.scene, self.camera, self.format = scene, camera, fmt
        self.rate = Fraction(camera.fps).limit_denominator(1001)
        self.time_base = TIME_BASES.get(fmt, 1 / self.rate)
        self.times, self.theta, self.rng = times, theta, rng
        self.sweeps = np.maximum(np.abs(theta).max(axis=0) + 0.05, MIN_SWEEP)
        self.pinhole = aim(scene, camera, self.sweeps)
        self.row_delay = camera.readout / camera.height
        self.exposure = camera.exposure
        self._schedule()
        self._layout()
        if pictures:
            self._static()

    # -- time ---------------------------------------------------------------------------
    def _schedule(self) -> None:
        cam, rng = self.camera, self.rng
        period = 1.0 / cam.frame_rate
        jitter_cap = 0.35 * period
        lead = 0.5 * self.exposure + jitter_cap
        tail = 0.5 * self.exposure + cam.readout + jitter_cap
        last = self.times[-1] - tail
        count = int(math.floor((last - lead) / period)) + 1
        if count < 1:
            raise ParameterError(
                f"`times` spans {self.times[-1]:.3g} s, too short for one frame at "
                f"{cam.frame_rate:g} fps with its exposure and readout "
                f"({lead + tail:.3g} s): pass a longer run."
            )
        nominal = lead + period * np.arange(count)
        jitter = np.clip(rng.normal(0.0, cam.vfr_jitter_s, count), -jitter_cap, jitter_cap)
        keep = rng.random(count) >= cam.drop_fraction
        keep[0] = True
        self.dropped = int(count - keep.sum())
        capture = (nominal + (jitter if cam.vfr_jitter_s > 0 else 0.0))[keep]
        # A phone's first frame has timestamp 0 (an MP4's edit list could only delay the
        # start by whole milliseconds): from here on, times are video times.
        self.origin = float(capture[0])
        self.times = self.times - self.origin
        self.pts = np.round((capture - self.origin) / float(self.time_base)).astype(np.int64)
        self.frame_times = self.pts * float(self.time_base)

    # -- static layers ------------------------------------------------------------------
    def _layout(self) -> None:
        """Each metronome's swept box, what nearer bodies hide of it, sizes and colours."""
        cam, pin = self.camera, self.pinhole
        order = sorted(
            range(self.scene.n), key=lambda i: -pin.depth(self.scene.metronomes[i].pivot)
        )
        self.order = order
        self.boxes, self.vis, self.sizes, self.colours = {}, {}, {}, {}
        for rank, i in enumerate(order):
            m = self.scene.metronomes[i]
            depth = pin.depth(m.pivot)
            f = pin.focal_px / depth
            rod_hw, bob_hl, bob_hw = (
                0.5 * f * m.rod_width,
                0.5 * f * m.bob_length,
                0.5 * f * m.bob_width,
            )
            self.sizes[i] = (rod_hw, bob_hl, bob_hw)
            angles = np.linspace(-self.sweeps[i], self.sweeps[i], 41)
            tips, bobs = rod_points(m, angles)
            xy = np.vstack([pin.project(tips), pin.project(bobs), pin.project(m.pivot)[None]])
            margin = math.hypot(bob_hl, bob_hw) + rod_hw + 3.0
            x0 = max(0, int(math.floor(xy[:, 0].min() - margin)) // 2 * 2)
            y0 = max(0, int(math.floor(xy[:, 1].min() - margin)) // 2 * 2)
            x1 = min(cam.width, (int(math.ceil(xy[:, 0].max() + margin)) + 2) // 2 * 2)
            y1 = min(cam.height, (int(math.ceil(xy[:, 1].max() + margin)) + 2) // 2 * 2)
            if x1 <= x0 or y1 <= y0:
                self.boxes[i] = None
                continue
            self.boxes[i] = (x0, y0, x1, y1)
            vis = np.ones((y1 - y0, x1 - x0), np.float32)
            for j in order[rank + 1 :]:
                for poly, _ in body_faces(self.scene.metronomes[j], pin):
                    cov = convex_coverage(pin.project_clipped(poly), x0, y0, y1 - y0, x1 - x0)
                    vis *= 1.0 - cov
            self.vis[i] = vis
            self.colours[i] = (to_yuv(m.rod_colour), to_yuv(m.bob_colour))

    def _static(self) -> None:
        cam = self.camera
        rgb = background(self.scene, self.pinhole)
        yuv = to_yuv(rgb)
        del rgb
        self.Y = np.ascontiguousarray(yuv[..., 0])
        self.U = half(yuv[..., 1])
        self.V = half(yuv[..., 2])
        del yuv
        h, w = cam.height, cam.width
        self.noise_pad = 16
        if cam.noise > 0:
            shape = (2, h + self.noise_pad, w + self.noise_pad)
            self.noise_y = self.rng.normal(0.0, cam.noise, shape).astype(np.float32)
        self.flicker_phase = float(self.rng.uniform(0, 2 * np.pi))
        self.drift = (self.rng.uniform(2.0, 15.0, 3), self.rng.uniform(0, 2 * np.pi, 3))
        self.buffer = np.empty((h * 3 // 2, w), np.uint8)
        self.work = (self.Y.copy(), self.U.copy(), self.V.copy())
        self.no_flicker = np.ones(h, np.float32)
        self.no_noise = np.zeros((0, 0), np.float32)

    # -- one frame ----------------------------------------------------------------------
    def render(self, t: float) -> np.ndarray:
        """(H·3/2, W) uint8 yuv420p picture of the frame captured at ``t``.

        The rods are drawn into working copies of the static planes, inside their
        boxes only; one pass per plane then applies the light, the noise and the
        rounding; the boxes are restored for the next frame.
        """
        cam, pin = self.camera, self.pinhole
        h, w = cam.height, cam.width
        Y, U, V = self.work
        drawn = []
        for i in self.order:
            box = self.boxes[i]
            if box is None:
                continue
            x0, y0, x1, y1 = box
            m = self.scene.metronomes[i]
            k = self._samples(i, t + self.row_delay * 0.5 * (y0 + y1))
            offsets = self.exposure * ((np.arange(k) + 0.5) / k - 0.5)
            row_times = t + self.row_delay * np.arange(y0, y1)
            angles = np.interp(row_times[:, None] + offsets[None, :], self.times, self.theta[:, i])
            tips, bobs = rod_points(m, angles)
            tips, bobs = pin.project(tips), pin.project(bobs)
            pivot = pin.project(m.pivot)
            rod = np.zeros((y1 - y0, x1 - x0), np.float32)
            bob = np.zeros_like(rod)
            span = np.empty((y1 - y0, 2), np.int64)
            rod_coverage(rod, bob, span, x0, y0, pivot[0], pivot[1], tips, bobs, *self.sizes[i])
            rod_yuv, bob_yuv = self.colours[i]
            composite(Y, U, V, x0, y0, rod, bob, self.vis[i], span, rod_yuv, bob_yuv)
            drawn.append((x0, y0, span))
        gain = self._light(t)
        gain2 = 0.5 * (gain[0::2] + gain[1::2])
        buf = self.buffer
        targets = (
            buf[:h],
            buf[h : h + h // 4].reshape(h // 2, w // 2),
            buf[h + h // 4 :].reshape(h // 2, w // 2),
        )
        for plane, target, offset, g, c in zip(
            self.work, targets, (16.0, 128.0, 128.0), (gain, gain2, gain2), (0, 1, 1), strict=True
        ):
            noise, dy, dx = self._noise(c)
            finish_plane(target, plane, offset, g, noise, dy, dx)
        for x0, y0, span in drawn:
            restore(Y, self.Y, x0, y0, span, 1)
            restore(U, self.U, x0, y0, span, 2)
            restore(V, self.V, x0, y0, span, 2)
        return buf

    def _light(self, t: float) -> np.ndarray:
        """(H,) float32: each row's light, 1 on average, averaged over its exposure."""
        cam = self.camera
        level = 1.0
        if cam.light_drift > 0:
            periods, phases = self.drift
            level += cam.light_drift * float(np.mean(np.sin(2 * np.pi * t / periods + phases)))
        if not (cam.flicker_hz > 0 and cam.flicker_depth > 0):
            return self.no_flicker if level == 1.0 else np.full(cam.height, level, np.float32)
        rows = t + self.row_delay * np.arange(cam.height)
        smear = np.sinc(cam.flicker_hz * self.exposure)
        gain = 1.0 + 0.5 * cam.flicker_depth * smear * np.cos(
            2 * np.pi * cam.flicker_hz * rows + self.flicker_phase
        )
        return (level * gain).astype(np.float32)

    def _noise(self, chroma: int) -> tuple[np.ndarray, int, int]:
        # Luma only: a phone's processing removes nearly all chroma noise, which would
        # otherwise cost the encoder most of its bits.
        if self.camera.noise <= 0 or chroma:
            return self.no_noise, 0, 0
        bank = self.noise_y
        pad = self.noise_pad
        b, dy, dx = self.rng.integers(len(bank)), self.rng.integers(pad), self.rng.integers(pad)
        return bank[b], int(dy), int(dx)

    def _samples(self, i: int, t: float) -> int:
        if self.exposure <= 0:
            return 1
        m = self.scene.metronomes[i]
        half_e = 0.5 * self.exposure
        a, b = np.interp([t - half_e, t + half_e], self.times, self.theta[:, i])
        length_px = self.pinhole.focal_px * m.rod_length / self.pinhole.depth(m.pivot)
        return int(
            np.clip(math.ceil(abs(b - a) * length_px / 1.2), 1, self.camera.max_blur_samples)
        )

    # -- file ---------------------------------------------------------------------------
    def write(self, path: Path, audio) -> None:
        cam = self.camera
        with av.open(str(path), mode="w", format=self.format) as container:
            stream = container.add_stream("libx264", rate=self.rate)
            stream.width, stream.height = cam.width, cam.height
            stream.pix_fmt = "yuv420p"
            stream.bit_rate = cam.bits_per_second
            stream.time_base = self.time_base
            stream.codec_context.time_base = self.time_base
            stream.codec_context.gop_size = max(1, int(round(cam.fps)))
            stream.codec_context.max_b_frames = 0
            stream.options = {"preset": cam.preset}
            if cam.rotation:
                stream.set_display_rotation(cam.rotation)
            sound = Sound(container, audio, self.ticks(), self.rng) if audio is not None else None
            for t, pts in zip(self.frame_times, self.pts, strict=True):
                frame = av.VideoFrame.from_ndarray(self.render(float(t)), format="yuv420p")
                frame.pts = int(pts)
                frame.time_base = self.time_base
                container.mux(stream.encode(frame))
                if sound is not None:
                    sound.until(float(t) + 1.0 / cam.frame_rate)
            container.mux(stream.encode(None))
            if sound is not None:
                sound.close()

    # -- truth --------------------------------------------------------------------------
    def ticks(self) -> list[np.ndarray]:
        return [all_crossings(self.times, self.theta[:, i]) for i in range(self.scene.n)]

    def visible(self) -> np.ndarray:
        """(N,) fraction of each rod, over its whole swing, that nearer bodies leave seen."""
        out = np.ones(self.scene.n)
        for i, m in enumerate(self.scene.metronomes):
            if self.boxes[i] is None:
                out[i] = 0.0
                continue
            x0, y0, x1, y1 = self.boxes[i]
            angles = np.linspace(-1.0, 1.0, 9)[:, None] * min(self.sweeps[i], 0.5)
            tips = self.pinhole.project(rod_points(m, angles)[0])
            pivot = self.pinhole.project(m.pivot)
            along = np.linspace(0.05, 1.0, 24)[None, :, None]
            xy = pivot + along * (tips - pivot)
            col = np.clip(np.round(xy[..., 0]).astype(int) - x0, 0, x1 - x0 - 1)
            row = np.clip(np.round(xy[..., 1]).astype(int) - y0, 0, y1 - y0 - 1)
            inside = (xy[..., 0] >= 0) & (xy[..., 0] < self.camera.width)
            inside &= (xy[..., 1] >= 0) & (xy[..., 1] < self.camera.height)
            out[i] = float(np.mean(self.vis[i][row, col] * inside))
        return out

    def _filmed(self, times: np.ndarray) -> np.ndarray:
        return times[(times >= 0.0) & (times <= self.frame_times[-1])]

    def truth(self, path: Path, audio) -> dict:
        """The fields of `FilmTruth`."""
        cam, pin = self.camera, self.pinhole
        rest = [rod_points(m, 0.0) for m in self.scene.metronomes]
        pivot = pin.project(np.array([m.pivot for m in self.scene.metronomes]))
        tip = pin.project(np.array([r[0] for r in rest]))
        bob = pin.project(np.array([r[1] for r in rest]))
        theta = np.column_stack(
            [np.interp(self.frame_times, self.times, self.theta[:, i]) for i in range(self.scene.n)]
        )
        width, height = (
            (cam.height, cam.width) if cam.rotation in (90, 270) else (cam.width, cam.height)
        )
        return dict(
            path=path, n=self.scene.n, width=width, height=height, fps=float(cam.fps),
            frame_times=self.frame_times.copy(), theta=theta, row_delay_s=self.row_delay,
            exposure_s=self.exposure, dropped=self.dropped,
            pivot_px=displayed(pivot, cam), tip_px=displayed(tip, cam), bob_px=displayed(bob, cam),
            crossings=[self._filmed(upward_crossings(self.times, self.theta[:, i]))
                       for i in range(self.scene.n)],
            ticks=[self._filmed(t) for t in self.ticks()], start_s=self.origin,
            audio=audio is not None,
            audio_delay_s=0.0 if audio is None else float(audio.delay_s), rotation=cam.rotation,
            visible=self.visible(), scene=self.scene, camera=cam, pinhole=pin,
        )  # fmt: skip


def all_crossings(times: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Times (K,) where θ (T,) passes 0 either way, linear between samples ``times``."""
    sign = theta >= 0
    k = np.flatnonzero(sign[:-1] != sign[1:])
    return times[k] + (times[k + 1] - times[k]) * theta[k] / (theta[k] - theta[k + 1])


def displayed(xy: np.ndarray, cam) -> np.ndarray:
    """Stored pixel positions (K, 2) as displayed after the counter-clockwise turn
    ``cam.rotation`` (the picture np.rot90(stored, rotation // 90))."""
    x, y = xy[:, 0], xy[:, 1]
    w, h = cam.width, cam.height
    if cam.rotation == 90:
        x, y = y, w - 1 - x
    elif cam.rotation == 180:
        x, y = w - 1 - x, h - 1 - y
    elif cam.rotation == 270:
        x, y = h - 1 - y, x
    return np.column_stack([x, y])
