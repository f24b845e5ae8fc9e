"""The plot of a recording's analysis, for one metronome, two and three told apart."""

from __future__ import annotations

import pytest

from metrosync.audio import analyze_audio
from metrosync.audio.plots import MAX_COLUMNS, _columns, colour, plot_audio
from metrosync.synthetic import clicks


@pytest.mark.parametrize(
    ("trains", "pans", "panels"),
    [
        ([(150, 0.1, 0.05)], None, 3),
        ([(150, 0.1, 0.0), (153, 0.6, 0.0)], [-0.9, 0.9], 4),
        ([(150, 0.1, 0.0), (151, 0.4, 0.0), (152, 0.7, 0.0)], None, 4),
    ],
)
def test_panels(tmp_path, trains, pans, panels):
    times = [clicks.metronome_train(b, 30, phase=p, asymmetry=a) for b, p, a in trains]
    ds = analyze_audio(clicks.write(tmp_path / "r.wav", clicks.render(times, 30, pans=pans)))
    fig = plot_audio(ds, tmp_path / "r.png")
    axes = [ax for ax in fig.axes if ax.get_ylabel() != "distinct ticks per beat"]
    assert len(axes) == panels
    assert (tmp_path / "r.png").stat().st_size > 10_000
    t, lo, hi = _columns(ds, MAX_COLUMNS)
    assert t.size <= MAX_COLUMNS and lo.min() == ds.wave_min.min() and hi.max() == ds.wave_max.max()
    # the ticks in the waveform panel: one colour per metronome (grey: none)
    marks = [line for line in fig.axes[0].lines if line.get_marker() == "|"]
    colours = {line.get_color() for line in marks}
    assert colours == {colour(m) for m in set(ds.tick_metronome.values.tolist())}
    assert {colour(m) for m in range(len(trains))} <= colours
