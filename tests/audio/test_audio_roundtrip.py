"""Round trip: `metrosync listen`'s WAV of a simulation, analysed, against the crossings.

The WAV has a click at every simulated zero crossing of every pendulum. Analysing it
must find the clicks within 1 ms, at recall and precision >= 0.99, and the acoustic
order parameter of the crossings themselves, also with noise and reverberation added
(SNR 10 dB). Ticks closer than the detector's refractory time sound as one, but the
analysis seeks the ticks another's hid where their metronome's timing puts them
(`audio.seek`), so its r(t) is held to that of every crossing, not of the crossings
merged as a detector hears them.
"""

from __future__ import annotations

import numpy as np
import pytest
import soundfile as sf

from metrosync.audio import analyze_audio
from metrosync.audio.order import acoustic_order
from metrosync.audio.tempo import beat_period
from metrosync.synthetic import clicks, score


def r_from_crossings(ds, crossings):
    truth = np.sort(np.concatenate(crossings))
    o = acoustic_order(truth, beat_period(truth), window=ds.attrs["order_window"],
                       centres=ds.window.values, metronomes=ds.attrs["metronomes"])  # fmt: skip
    return o.r


def recording(condition, listen_run, tmp_path_factory):
    """The listen WAV, clean or with reverberation and noise at 10 dB SNR."""
    path, crossings = listen_run
    if condition != "clean":
        x, rate = sf.read(str(path))
        rng = np.random.default_rng(15)
        x = clicks.add_noise(clicks.add_reverb(x, rng, rate), 10.0, crossings, rng, rate)
        path = clicks.write(tmp_path_factory.mktemp("noisy") / "noisy.wav", x, rate)
    return path


@pytest.fixture(scope="module", params=["clean", "noise+reverb 10 dB"])
def analysed(request, listen_run, tmp_path_factory):
    path = recording(request.param, listen_run, tmp_path_factory)
    return analyze_audio(path, metronomes=3), listen_run[1]


def test_clicks_found_within_a_millisecond(analysed):
    # each metronome's own sound keeps it through the crossings (benchmarks/audio_listen.py)
    ds, crossings = analysed
    found = ds.tick_time.values
    times, alone = score.resolvable(crossings, ds.attrs["resolution"])
    recall, _, errors = score.match(times[alone], found)
    _, precision, _ = score.match(times, found)
    assert recall >= 0.99 and precision >= 0.99
    assert np.abs(errors).max() <= 1e-3
    assert ds.attrs["beat_period"] == pytest.approx(beat_period(np.sort(times)), rel=1e-3)


def test_acoustic_order_parameter_is_the_crossings_own(analysed):
    """0.004 mean and 0.06 at most from every crossing's r (2026-12-03), the largest
    where the three tick within a few milliseconds for a window; merged crossings
    would differ by 0.009 on average."""
    ds, crossings = analysed
    raw = np.abs(ds.r_acoustic.values - r_from_crossings(ds, crossings))
    assert raw.mean() <= 0.01 and raw.max() <= 0.08
