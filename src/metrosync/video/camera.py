"""A phone filming metronomes: simulated runs rendered to a video file with its ground truth.

One entry point::

    truth = film("run.mp4", times, theta, scene=Scene.random(3, seed=1),
                 camera=Camera(fps=60, width=640, height=360), audio=True, seed=0)

``times`` (T,) and ``theta`` (T, N) are a trajectory sampled finely enough to
interpolate linearly (a few ms): a closed form, or a simulation::

    ds = metrosync.simulate(3, 192.0, duration=30.0, dt=0.002, record_every=1,
                            trajectories=True)
    truth = film("run.mp4", ds.time.values, ds.theta.isel(run=0).values,
                 scene=Scene.random(3, seed=1))

θ_i is metronome i's angle from the vertical, positive leaning right as seen from the
front. The metronomes stand still on a table (a simulated platform's rotation φ is not
filmed). Every time below is video time, s: 0 at the first frame, as in a phone's
file; `FilmTruth.start_s` is the simulation time (after ``times[0]``) of video time 0.

What the camera does (`Camera`, each part can be switched off; `Camera.ideal` has none):

* perspective: a pinhole camera ``yaw_deg`` to the side of the metronomes' axis and
  ``pitch_deg`` above it, with a phone's field of view (`_scene_render.Pinhole`);
* motion blur: each pixel averages the scene over ``exposure_s`` (several samples);
* rolling shutter: row y (stored frame, 0 at the top) is exposed around
  t_frame + ``rolling_shutter_s`` · y / height;
* flicker: the light varies at ``flicker_hz`` (100 or 120 Hz, twice the mains) by
  ``flicker_depth``, averaged over each row's exposure (so it shows as bands, and as
  its alias at the frame rate); ``light_drift``: the light (or the phone's automatic
  exposure) also wanders slowly, by up to that fraction, over seconds;
* sensor noise: Gaussian, ``noise`` digital levels rms, in luma only (phones remove
  chroma noise);
* H.264 (libx264, yuv420p, no B-frames, a key frame a second) at ``bitrate`` (default:
  a phone's, about 0.1 bit per pixel per frame), written with PyAV; the container is
  chosen from the file's suffix: .mp4 and .mov (timestamps in 1/90000 s, as phones
  write), .mkv (in ms; it also declares the nominal ``fps``, which readers report as
  its rate whatever the timestamps do), .avi (constant rate only; frame k at k/fps —
  FFmpeg reads an AVI's pts one frame late, its dts is right);
* time: frames are captured every 1/``real_fps`` s (default ``fps``) with Gaussian
  jitter ``vfr_jitter_s``, a fraction ``drop_fraction`` of them is dropped, and each
  frame's presentation timestamp (in the container's time base) is its capture time,
  the first frame's being 0. The encoder is set up at ``fps``; an MKV declares it as
  the nominal rate, MP4 and MOV readers derive theirs from the timestamps;
* ``rotation``: the phone held turned (90 = portrait): the picture is stored turned
  and the container's display matrix says how to turn it back (PyAV: the picture as
  shown is ``np.rot90(decoded, frame.rotation // 90)``, the rotation read back in
  [-180, 180]: 270 reads −90); rows, and so the rolling shutter, run down the stored
  picture.
* sound (``audio``): a mono track (AAC by default) with a click at every passage of
  each metronome through the vertical, ``delay_s`` late.

Cost: the static background is drawn once; per frame only the rods' swept boxes are
drawn, then one compiled pass per plane applies light, noise and rounding. On a 2-core
x86-64 machine a 1080p frame with three metronomes takes about 10 ms of CPU to draw and
about 15 ms (``preset="ultrafast"``) to 30 ms (``"veryfast"``, the default) to encode;
10 s of 640×360 at 60 fps take about 3 s of CPU.

Metronomes standing close together hide one another more or less depending on where
the camera stands: `visibility` (or `FilmTruth.visible`) says how much of each rod shows.

`FilmTruth` is what the tracker should find: per frame its presentation time and the
true angles; per metronome the pixel position of the pivot and of the rod's tip at rest,
and the true upward crossings of the vertical (θ passing 0 from below, interpolated
linearly between the trajectory's samples); all in displayed pixel coordinates (after
the rotation is applied), the centre of pixel [row, col] being (x, y) = (col, row).
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from .._files import atomic_path
from ..errors import ParameterError
from ..observables.entrainment import upward_crossings
from ._scene import Metronome, Scene
from ._scene_filming import Filming, displayed
from ._scene_render import Pinhole, rod_points

__all__ = [
    "Camera", "FilmTruth", "Metronome", "Microphone", "Scene", "film", "upward_crossings",
    "visibility",
]  # fmt: skip

#: Suffixes (containers) `film` writes.
CONTAINERS = {".mp4": "mp4", ".mov": "mov", ".mkv": "matroska", ".avi": "avi"}


@dataclass(frozen=True)
class Camera:
    """How the phone films: geometry, exposure, impairments and encoding (SI units).

    fps : the frame rate the stream declares (30, 60, 240...).
    width, height : stored frame size, px (even; the height a multiple of 4).
    yaw_deg, pitch_deg, roll_deg : turn to the side of the metronomes' axis, tilt
        down, and turn about the view axis, degrees.
    hfov_deg : horizontal field of view, degrees.   framing : fraction of the frame's
        width or height (whichever binds) the metronomes' swing fills.
    exposure_s : exposure time (motion blur); default half a frame period.
    rolling_shutter_s : time from the top row to the bottom row; default 0.5/fps,
        at most 20 ms.
    noise : sensor noise, rms in 8-bit luma levels.
    flicker_hz, flicker_depth : light modulation frequency (0: none) and depth (peak
        to peak fraction of the light).
    light_drift : slow wandering of the light over seconds, largest fraction.
    bitrate : H.264 bit rate, bit/s; default 0.1 bit per pixel per frame.
    preset : libx264 speed preset.
    vfr_jitter_s : rms jitter of the capture times.   drop_fraction : frames dropped.
    real_fps : the rate frames are really captured at (default ``fps``).
    rotation : 0, 90, 180 or 270: the display matrix's counter-clockwise turn.
    max_blur_samples : most samples averaged in one exposure.
    """

    fps: float = 60.0
    width: int = 1280
    height: int = 720
    yaw_deg: float = 25.0
    pitch_deg: float = 12.0
    roll_deg: float = 0.0
    hfov_deg: float = 66.0
    framing: float = 0.7
    exposure_s: float | None = None
    rolling_shutter_s: float | None = None
    noise: float = 2.0
    flicker_hz: float = 100.0
    flicker_depth: float = 0.08
    bitrate: float | None = None
    preset: str = "veryfast"
    vfr_jitter_s: float = 0.0003
    drop_fraction: float = 0.0
    real_fps: float | None = None
    rotation: int = 0
    max_blur_samples: int = 12
    light_drift: float = 0.0

    def __post_init__(self) -> None:
        _check_range("fps", self.fps, 1.0, 1000.0)
        for name in ("width", "height"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | np.integer):
                raise ParameterError(f"`{name}` must be an integer, got {value!r}.")
        if not (64 <= self.width <= 3840 and self.width % 2 == 0):
            raise ParameterError(
                f"`width` must be even, in [64, 3840] px (4K at most), got {self.width}."
            )
        if not (64 <= self.height <= 2160 and self.height % 4 == 0):
            raise ParameterError(
                f"`height` must be a multiple of 4 in [64, 2160] px, got {self.height}."
            )
        _check_range("yaw_deg", self.yaw_deg, -60.0, 60.0)
        _check_range("pitch_deg", self.pitch_deg, -45.0, 60.0)
        _check_range("roll_deg", self.roll_deg, -30.0, 30.0)
        _check_range("hfov_deg", self.hfov_deg, 10.0, 120.0)
        _check_range("framing", self.framing, 0.05, 1.0)
        if self.exposure_s is not None:
            _check_range("exposure_s", self.exposure_s, 0.0, 1.0 / self.frame_rate)
        if self.rolling_shutter_s is not None:
            _check_range("rolling_shutter_s", self.rolling_shutter_s, 0.0, 1.0 / self.frame_rate)
        _check_range("noise", self.noise, 0.0, 64.0)
        _check_range("flicker_hz", self.flicker_hz, 0.0, 10000.0)
        _check_range("flicker_depth", self.flicker_depth, 0.0, 1.0)
        _check_range("light_drift", self.light_drift, 0.0, 0.9)
        if self.bitrate is not None:
            _check_range("bitrate", self.bitrate, 1e4, 1e9)
        _check_range("vfr_jitter_s", self.vfr_jitter_s, 0.0, 0.3 / self.frame_rate)
        _check_range("drop_fraction", self.drop_fraction, 0.0, 0.5)
        if self.real_fps is not None:
            _check_range("real_fps", self.real_fps, 1.0, 1000.0)
        if self.rotation not in (0, 90, 180, 270):
            raise ParameterError(f"`rotation` must be 0, 90, 180 or 270, got {self.rotation!r}.")
        if not (isinstance(self.max_blur_samples, int) and 1 <= self.max_blur_samples <= 64):
            raise ParameterError(
                f"`max_blur_samples` must be an integer in [1, 64], got {self.max_blur_samples!r}."
            )

    @classmethod
    def ideal(cls, **options) -> Camera:
        """A camera with every impairment off: square-on, no blur, noise, flicker,
        rolling shutter or jitter, and a high bit rate; ``options`` change any field."""
        base = dict(
            yaw_deg=0.0, pitch_deg=0.0, exposure_s=0.0, rolling_shutter_s=0.0, noise=0.0,
            flicker_hz=0.0, vfr_jitter_s=0.0, drop_fraction=0.0, light_drift=0.0,
        )  # fmt: skip
        base.update(options)
        if "bitrate" not in options:
            base["bitrate"] = (
                1.0 * base.get("width", 1280) * base.get("height", 720) * base.get("fps", 60.0)
            )
        return cls(**base)

    @classmethod
    def random(cls, seed: int = 0, **options) -> Camera:
        """A phone drawn at random: 20–40° to either side, tilted down 0–30°, a field of
        view of 55–80°, framing, exposure, rolling shutter, noise, 100 or 120 Hz
        flicker, jitter, drops and bit rate all drawn within what phones do; the frame
        rate is 30, 60 or 240 fps. ``options`` fix any field (e.g. ``fps=60``)."""
        rng = np.random.default_rng(seed)
        fps = options.get("fps", float(rng.choice([30.0, 60.0, 60.0, 240.0])))
        _check_range("fps", fps, 1.0, 1000.0)
        if options.get("real_fps") is not None:
            _check_range("real_fps", options["real_fps"], 1.0, 1000.0)
        period = 1.0 / float(options.get("real_fps") or fps)
        drawn = dict(
            fps=fps,
            width=640,
            height=360,
            yaw_deg=float(rng.uniform(20.0, 40.0) * rng.choice([-1.0, 1.0])),
            pitch_deg=float(rng.uniform(0.0, 30.0)),
            roll_deg=float(rng.normal(0.0, 2.0)),
            hfov_deg=float(rng.uniform(55.0, 80.0)),
            framing=float(rng.uniform(0.5, 0.9)),
            exposure_s=float(period * rng.uniform(0.1, 0.9)),
            rolling_shutter_s=float(min(period, 0.03) * rng.uniform(0.3, 0.95)),
            noise=float(rng.uniform(0.5, 4.0)),
            flicker_hz=float(rng.choice([100.0, 120.0])),
            flicker_depth=float(rng.uniform(0.0, 0.15)),
            light_drift=float(rng.uniform(0.0, 0.2)),
            vfr_jitter_s=float(rng.uniform(0.0, 0.2) * period),
            drop_fraction=float(rng.uniform(0.0, 0.03)),
        )
        drawn["bitrate"] = float(
            rng.uniform(0.05, 0.2)
            * options.get("width", drawn["width"])
            * options.get("height", drawn["height"])
            * fps
        )
        drawn.update(options)
        return cls(**drawn)

    @property
    def frame_rate(self) -> float:
        """The rate frames are really captured at, Hz."""
        return float(self.real_fps if self.real_fps is not None else self.fps)

    @property
    def exposure(self) -> float:
        """Exposure time used, s."""
        return 0.5 / self.frame_rate if self.exposure_s is None else float(self.exposure_s)

    @property
    def readout(self) -> float:
        """Rolling-shutter readout time (top row to bottom row) used, s."""
        if self.rolling_shutter_s is None:
            return min(0.5 / self.frame_rate, 0.02)
        return float(self.rolling_shutter_s)

    @property
    def bits_per_second(self) -> int:
        """H.264 bit rate used, bit/s."""
        if self.bitrate is not None:
            return int(self.bitrate)
        return int(0.1 * self.width * self.height * self.fps)


@dataclass(frozen=True)
class Microphone:
    """The sound track: sample rate, codec, the sound's delay behind the picture (s),
    and background noise (rms, full scale 1)."""

    sample_rate: int = 48000
    codec: str = "aac"
    delay_s: float = 0.0
    noise: float = 0.002

    def __post_init__(self) -> None:
        if (
            isinstance(self.sample_rate, bool)
            or self.sample_rate not in (8000, 16000, 22050, 24000, 32000, 44100, 48000)
            or not isinstance(self.sample_rate, int | np.integer)
        ):
            raise ParameterError(
                f"`sample_rate` must be an integer standard rate such as 44100 or 48000 Hz, got "
                f"{self.sample_rate!r}."
            )
        if self.codec not in ("aac", "pcm_s16le"):
            raise ParameterError(f"`codec` must be 'aac' or 'pcm_s16le', got {self.codec!r}.")
        _check_range("delay_s", self.delay_s, -1.0, 1.0)
        _check_range("noise", self.noise, 0.0, 0.5)


@dataclass
class FilmTruth:
    """The ground truth of a filmed run (module docstring for the conventions).

    path : the video file.   n : number of metronomes.
    start_s : simulation time after ``times[0]`` at video time 0 (the first frame), s.
    width, height : displayed frame size, px (after the rotation).
    fps : the rate the stream declares.   frame_times : (F,) presentation times, s.
    theta : (F, N) true angles at the frame times (top row's exposure centre), rad.
    row_delay_s : the rolling shutter's delay per stored row, s: stored row y is
        exposed around frame_time + row_delay_s · y.
    exposure_s : exposure time, s.   dropped : number of frames dropped.
    pivot_px, tip_px, bob_px : (N, 2) displayed pixel positions (x, y) of the pivot, and
        of the rod's tip and the bob's centre at rest (θ = 0).
    crossings : N arrays, upward crossings (θ passing 0 from below) between the first
        and the last frame, s.
    ticks : N arrays, every passage through the vertical (both ways), same span, s.
    visible : (N,) fraction of each rod, over its swing (up to ±0.5 rad), that no nearer
        body hides and that lies inside the picture (1: all of it).
    audio : whether the file has a sound track.   audio_delay_s : its delay, s.
    rotation : the display matrix's counter-clockwise turn, degrees.
    scene, camera : what was filmed and how.
    """

    path: Path
    n: int
    width: int
    height: int
    fps: float
    frame_times: np.ndarray
    theta: np.ndarray
    row_delay_s: float
    exposure_s: float
    dropped: int
    pivot_px: np.ndarray
    tip_px: np.ndarray
    bob_px: np.ndarray
    crossings: list[np.ndarray]
    ticks: list[np.ndarray]
    start_s: float
    audio: bool
    audio_delay_s: float
    rotation: int
    visible: np.ndarray
    scene: Scene = field(repr=False)
    camera: Camera = field(repr=False)
    pinhole: Pinhole = field(repr=False)

    @property
    def rod_length_px(self) -> np.ndarray:
        """(N,) pivot to tip at rest, px."""
        return np.hypot(*(self.tip_px - self.pivot_px).T)

    def tip_at(self, theta) -> np.ndarray:
        """Displayed pixel positions (..., N, 2) of the rods' tips at angles θ (..., N)."""
        return self._at(theta, 0)

    def bob_at(self, theta) -> np.ndarray:
        """Displayed pixel positions (..., N, 2) of the bobs' centres at angles θ (..., N)."""
        return self._at(theta, 1)

    def _at(self, theta, which: int) -> np.ndarray:
        theta = np.asarray(theta, dtype=float)
        if theta.shape[-1:] != (self.n,):
            raise ParameterError(
                f"`theta` must end in one angle per metronome ({self.n}), got shape {theta.shape}."
            )
        out = np.empty(theta.shape + (2,))
        for i, m in enumerate(self.scene.metronomes):
            xy = self.pinhole.project(rod_points(m, theta[..., i])[which]).reshape(-1, 2)
            out[..., i, :] = displayed(xy, self.camera).reshape(theta.shape[:-1] + (2,))
        return out

    def to_json(self) -> str:
        """The truth as JSON (arrays as lists), e.g. to store beside the video."""
        out = {}
        for key in (
            "n", "width", "height", "fps", "start_s", "row_delay_s", "exposure_s", "dropped",
            "audio", "audio_delay_s", "rotation",
        ):  # fmt: skip
            out[key] = getattr(self, key)
        out["path"] = str(self.path)
        for key in ("frame_times", "theta", "pivot_px", "tip_px", "bob_px", "visible"):
            out[key] = np.asarray(getattr(self, key)).tolist()
        out["crossings"] = [c.tolist() for c in self.crossings]
        out["ticks"] = [c.tolist() for c in self.ticks]
        out["camera"] = asdict(self.camera)
        return json.dumps(out)


def film(
    path: str | Path,
    times,
    theta,
    *,
    scene: Scene,
    camera: Camera | None = None,
    audio: bool | Microphone | None = None,
    seed: int = 0,
) -> FilmTruth:
    """Film a simulated run with ``camera`` and write it to ``path``; returns the truth.

    Parameters
    ----------
    path : the video file (.mp4, .mov, .mkv or .avi); written whole or not at all.
    times : (T,) increasing simulation times, s.
    theta : (T, N) angles, rad, N = ``scene.n`` (fine enough to interpolate linearly:
        a few ms apart).
    scene : the metronomes and background.   camera : default `Camera()`.
    audio : None/False (no sound), True (a default `Microphone`) or a `Microphone`.
    seed : draws the jitter, drops and noise.
    """
    camera = Camera() if camera is None else camera
    if not isinstance(scene, Scene):
        raise ParameterError(f"`scene` must be a `Scene` (e.g. Scene.random(3)), got {scene!r}.")
    if not isinstance(camera, Camera):
        raise ParameterError(f"`camera` must be a `Camera`, got {camera!r}.")
    if audio is True:
        audio = Microphone()
    elif audio is False:
        audio = None
    if audio is not None and not isinstance(audio, Microphone):
        raise ParameterError(f"`audio` must be None, True or a `Microphone`, got {audio!r}.")
    times, theta = _check_trajectory(times, theta, scene.n)
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in CONTAINERS:
        raise ParameterError(
            f"`path` must end in one of {', '.join(CONTAINERS)}, got {path.name!r}."
        )
    if suffix == ".avi" and (
        camera.vfr_jitter_s > 0 or camera.real_fps is not None or camera.drop_fraction > 0
    ):
        raise ParameterError(
            "An .avi file has no per-frame timestamps: use .mp4, .mov or .mkv for a "
            "variable frame rate, or set `vfr_jitter_s`=0, `drop_fraction`=0 and "
            "`real_fps`=None."
        )
    if suffix == ".mp4" and audio is not None and audio.codec != "aac":
        raise ParameterError(
            f"An .mp4 file takes AAC sound: use `codec`='aac' or a .mov/.mkv file, got "
            f"{audio.codec!r}."
        )
    rng = np.random.default_rng(seed)
    t_video = times - times[0]
    filming = Filming(scene, camera, t_video, theta, rng, CONTAINERS[suffix])
    try:
        with atomic_path(path, keep_suffix=True) as tmp:
            filming.write(tmp, audio)
    except OSError as error:
        raise OSError(f"Cannot write the video `path` = {str(path)!r}: {error}") from error
    return FilmTruth(**filming.truth(path, audio))


def visibility(
    scene: Scene, camera: Camera | None = None, *, amplitude: float = 0.45
) -> np.ndarray:
    """(N,) the fraction of each rod, swinging ±``amplitude`` rad, that ``camera`` would
    see (`FilmTruth.visible`), without rendering anything: pick scenes where no
    metronome hides another before filming them."""
    camera = Camera() if camera is None else camera
    _check_range("amplitude", amplitude, 0.0, 1.2)
    times = np.linspace(0.0, 2.0 + 4.0 / camera.frame_rate, 5)
    theta = np.tile(amplitude * np.array([0.0, 1.0, 0.0, -1.0, 0.0])[:, None], (1, scene.n))
    filming = Filming(scene, camera, times, theta, np.random.default_rng(0), "mp4", pictures=False)
    return filming.visible()


def _check_trajectory(times, theta, n: int) -> tuple[np.ndarray, np.ndarray]:
    times = np.asarray(times, dtype=float)
    theta = np.asarray(theta, dtype=float)
    if theta.ndim == 1:
        theta = theta[:, None]
    if times.ndim != 1 or times.size < 2:
        raise ParameterError(f"`times` must be 1-dimensional with 2 or more samples, got shape "
                             f"{times.shape}.")  # fmt: skip
    if theta.shape != (times.size, n):
        raise ParameterError(
            f"`theta` must have shape (T, N) = ({times.size}, {n}) (one column per metronome of "
            f"the scene), got {theta.shape}."
        )
    if not (np.all(np.isfinite(times)) and np.all(np.diff(times) > 0)):
        raise ParameterError("`times` must be finite and strictly increasing.")
    if not np.all(np.isfinite(theta)):
        raise ParameterError("`theta` must be finite (a run that overturned cannot be filmed).")
    worst = float(np.abs(theta).max())
    if worst >= 1.3:
        raise ParameterError(
            f"`theta` must stay within ±1.3 rad for a metronome's rod, got |θ| = {worst:.3g}."
        )
    return times, theta


def _check_range(name: str, value, low: float, high: float) -> None:
    if isinstance(value, bool) or not isinstance(value, int | float | np.number):
        raise ParameterError(f"`{name}` must be a number in [{low:g}, {high:g}], got {value!r}.")
    if not (math.isfinite(value) and low <= value <= high):
        raise ParameterError(f"`{name}` must be in [{low:g}, {high:g}], got {value!r}.")
