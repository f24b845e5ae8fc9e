"""What phones and cameras write, read through FFmpeg: AAC in M4A, raw ADTS, a video's sound.

Each file is encoded here, through PyAV, from a recording rendered from known tick times,
and analysed beside the WAV it came from: the same metronomes, tempo and tick times.
"""

from __future__ import annotations

import av
import numpy as np
import pytest
import soundfile as sf
import xarray as xr

from metrosync.audio import AudioFileError
from metrosync.audio.decode import _Writer
from metrosync.audio.reader import open_recording
from metrosync.cli import main
from metrosync.synthetic import clicks, score

RATE = 44100


def encode(path, samples, *, rate=RATE, codec="aac", video=False):
    """Write (S, C) float samples as ``codec`` into ``path`` (its suffix picks the
    container); with ``video``, a 32x32 picture stream beside it, as a phone's film has.

    96 kbit/s per channel, as phones record: FFmpeg's own encoder at its default 128
    kbit/s for stereo leaves artefacts that are heard as ticks of a second metronome."""
    channels = samples.shape[1]
    with av.open(str(path), "w") as out:
        if video:
            picture = out.add_stream("mpeg4", rate=10)
            picture.width, picture.height, picture.pix_fmt = 32, 32, "yuv420p"
        sound = out.add_stream(codec, rate=rate)
        sound.layout = "mono" if channels == 1 else "stereo"
        sound.bit_rate = 96_000 * channels
        planar = np.ascontiguousarray(samples.T, dtype=np.float32)
        for start in range(0, planar.shape[1], 1024):
            frame = av.AudioFrame.from_ndarray(planar[:, start : start + 1024].copy(),
                                               format="fltp", layout=sound.layout.name)  # fmt: skip
            frame.sample_rate, frame.pts = rate, start
            for packet in sound.encode(frame):
                out.mux(packet)
        for packet in sound.encode():
            out.mux(packet)
        if video:
            seconds = samples.shape[0] / rate
            for k in range(int(seconds * 10)):
                image = np.full((32, 32, 3), 8 * (k % 32), np.uint8)
                frame = av.VideoFrame.from_ndarray(image, format="rgb24")
                frame.pts = k
                for packet in picture.encode(frame):
                    out.mux(packet)
            for packet in picture.encode():
                out.mux(packet)
    return path


def analysed(capsys, tmp_path, path):
    """`metrosync analyze PATH --out`: its printed summary and dataset."""
    nc = tmp_path / f"{path.name}.nc"
    code = main(["analyze", str(path), "--out", str(nc)])
    out, err = capsys.readouterr()
    assert code == 0, err
    with xr.open_dataset(nc, engine="h5netcdf") as ds:
        return out, ds.load()


@pytest.fixture(scope="module")
def one_metronome(tmp_path_factory):
    """A 160 BPM metronome, 20 s, as a 16-bit WAV, and its tick times."""
    train = clicks.metronome_train(160, 20, phase=0.2)
    path = tmp_path_factory.mktemp("formats") / "tick.wav"
    clicks.write(path, clicks.render([train], 20))
    return path, train


def same_analysis(wav, other, train):
    assert int(other.attrs["metronomes"]) == int(wav.attrs["metronomes"]) == 1
    assert abs(float(other.bpm[0]) - float(wav.bpm[0])) < 0.01
    assert abs(float(other.bpm[0]) - 160) < 0.05
    # Every tick heard in both, at the same time: AAC's 1024 priming samples (23 ms)
    # are cut, so the only difference left is the coder's smearing of the attack.
    a, b = wav.tick_time.values, other.tick_time.values
    assert a.size == b.size == score.match(train, a)[2].size
    assert np.abs(b - a).max() < 1e-3


def test_a_phones_m4a_is_analysed_as_its_wav(capsys, tmp_path, one_metronome):
    wav, train = one_metronome
    samples, _ = sf.read(str(wav), always_2d=True)
    m4a = encode(tmp_path / "Voice 001.m4a", samples)
    out_wav, ds_wav = analysed(capsys, tmp_path, wav)
    out_m4a, ds_m4a = analysed(capsys, tmp_path, m4a)
    assert "(M4A AAC, 1 channel, 44100 Hz" in out_m4a
    same_analysis(ds_wav, ds_m4a, train)


def test_a_videos_sound_track_is_analysed(capsys, tmp_path, one_metronome):
    wav, train = one_metronome
    samples, _ = sf.read(str(wav), always_2d=True)
    stereo = samples * np.array([[1.0, 0.6]])
    film = encode(tmp_path / "film.mp4", stereo, video=True)
    with av.open(str(film)) as container:
        assert {s.type for s in container.streams} == {"video", "audio"}
    out, ds = analysed(capsys, tmp_path, film)
    assert "(MP4 AAC, 2 channels, 44100 Hz" in out
    same_analysis(analysed(capsys, tmp_path, wav)[1], ds, train)


def test_raw_adts_aac_keeps_its_priming_and_is_read_whole(tmp_path, one_metronome):
    """ADTS records no encoder delay: the sound comes 1024 samples late, and its stated
    length is a guess from the bit rate, which the decoder outgrows."""
    wav, _ = one_metronome
    samples, _ = sf.read(str(wav), always_2d=True)
    m4a = open_recording(encode(tmp_path / "a.m4a", samples))
    adts = open_recording(encode(tmp_path / "a.aac", samples))
    assert (m4a.format, adts.format) == ("M4A", "AAC")
    assert m4a.frames >= samples.shape[0] and adts.frames == m4a.frames + 1024
    assert np.array_equal(adts.samples[1024:], m4a.samples)
    assert not m4a.samples.flags.writeable  # the analysis reads blocks of it, never writes


def test_the_decoder_grows_its_array_by_doubling():
    """Frames longer than the stated length cost a few copies, not one per frame."""
    writer = _Writer(1024)
    frame = np.ones((1024, 2), np.float32)
    grown = []
    for k in range(1000):
        before = writer._out
        writer.put(k * 1024, frame * k)
        grown.append(writer._out is not before)
    out = writer.result(2)
    assert out.shape == (1024 * 1000, 2) and out[-1, 0] == 999
    assert sum(grown) <= 12  # 1 + log2(1000)


def test_a_gap_in_the_frames_stays_silent_and_priming_is_cut():
    writer = _Writer(4096)
    writer.put(-100, np.ones((1024, 1), np.float32))  # priming before time 0
    writer.put(924, np.full((1024, 1), 2, np.float32))
    writer.put(3000, np.full((1024, 1), 3, np.float32))  # a damaged packet before it
    out = writer.result(1)[:, 0]
    assert out.size == 4024 and np.all(out[:924] == 1) and np.all(out[924:1948] == 2)
    assert np.all(out[1948:3000] == 0) and np.all(out[3000:] == 3)


def test_a_video_without_sound_is_named_and_refused(capsys, tmp_path):
    film = tmp_path / "silent film.mp4"
    with av.open(str(film), "w") as out:
        picture = out.add_stream("mpeg4", rate=10)
        picture.width, picture.height, picture.pix_fmt = 32, 32, "yuv420p"
        for k in range(10):
            frame = av.VideoFrame.from_ndarray(np.zeros((32, 32, 3), np.uint8), format="rgb24")
            frame.pts = k
            for packet in picture.encode(frame):
                out.mux(packet)
        for packet in picture.encode():
            out.mux(packet)
    with pytest.raises(AudioFileError, match=r"'.*silent film.mp4' has no sound .*streams: video"):
        open_recording(film)
    assert main(["analyze", str(film)]) == 2
    err = capsys.readouterr().err
    assert "silent film.mp4" in err and "no sound track" in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err


@pytest.mark.parametrize(
    ("name", "content"),
    [("phone.m4a", b"\0\0\0\x18ftypM4A "), ("notes.mov", b"not a film"), ("clip.3gp", b"\0" * 64)],
)
def test_a_damaged_file_is_one_clear_line(capsys, tmp_path, name, content):
    (tmp_path / name).write_bytes(content)
    assert main(["analyze", str(tmp_path / name)]) == 2
    err = capsys.readouterr().err
    assert f"cannot read '{tmp_path / name}' as audio (FFmpeg:" in err and "ffmpeg -i" in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_an_m4a_cut_short_is_refused(tmp_path, one_metronome):
    wav, _ = one_metronome
    samples, _ = sf.read(str(wav), always_2d=True)
    whole = encode(tmp_path / "whole.m4a", samples).read_bytes()
    (tmp_path / "cut.m4a").write_bytes(whole[: len(whole) // 2])
    with pytest.raises(AudioFileError, match="cannot read .*cut.m4a.* as audio"):
        open_recording(tmp_path / "cut.m4a")
