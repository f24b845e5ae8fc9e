"""Figures typeset their symbols, tell their curves apart and keep legends off the data."""

import numpy as np
import pytest
import xarray as xr
from matplotlib.colors import to_rgb

import metrosync
from metrosync.paper import figures
from metrosync.sweeps.critical import critical_frequency, plot_critical


@pytest.fixture
def drawn(monkeypatch):
    """The figures the paper's plotting functions make, instead of writing them."""
    made = []
    monkeypatch.setattr(figures, "save_formats", lambda fig, stem: made.append(fig) or [])
    return made


def _texts(fig) -> str:
    parts = []
    for ax in fig.axes:
        parts += [ax.get_xlabel(), ax.get_ylabel(), ax.get_title()]
        legend = ax.get_legend()
        if legend is not None:
            parts += [t.get_text() for t in legend.get_texts()]
    parts += [t.get_text() for t in fig.texts] + [t.get_text() for t in fig.legends[0].texts] \
        if fig.legends else [t.get_text() for t in fig.texts]  # fmt: skip
    if fig._suptitle is not None:
        parts.append(fig._suptitle.get_text())
    return " | ".join(parts)


def _no_literal_subscripts(text: str) -> None:
    for plain in ("ω_c", "r_sim", "r_exp", "c_θ", "c_φ", "σ_r", "r_eq"):
        assert plain not in text, f"{plain!r} shown literally in {text!r}"


def test_fig9_typesets_r_and_has_error_bars_in_both_directions(drawn):
    ds = xr.Dataset(
        {"r_exp": ("bpm", [0.6, 0.9]), "r_exp_std": ("bpm", [0.05, 0.02]),
         "r_sim": ("bpm", [0.5, 0.85]), "sigma_r_sim": ("bpm", [0.1, 0.03]),
         "n_logs": ("bpm", [3, 3])},
        coords={"bpm": [176.0, 192.0]},
    )  # fmt: skip
    figures.plot_comparison(ds, "fig9")
    (fig,) = drawn
    text = _texts(fig)
    _no_literal_subscripts(text)
    assert r"$r_\mathrm{exp}$" in text and r"$r_\mathrm{sim}$" in text
    (bars,) = fig.axes[0].containers
    assert bars.has_xerr and bars.has_yerr


def test_time_series_curves_differ_in_colour_and_style(drawn):
    cases = [f"ω₀ = {b} BPM" for b in (160, 168, 176, 184, 192, 208)]
    t = np.arange(0, 600, 1.0)
    r = np.tile(np.linspace(0.3, 0.9, t.size), (len(cases), 1))  # every curve the same
    ds = xr.Dataset({"r_mean": (("case", "time"), r)}, coords={"case": cases, "time": t},
                    attrs={"figure": "Fig. 8 (top)", "title": "t", "mode": "quick"})  # fmt: skip
    figures.plot_order_in_time(ds, "fig8")
    lines = drawn[0].axes[0].get_lines()
    colours = [np.array(to_rgb(line.get_color())) for line in lines]
    closest = min(np.abs(a - b).sum() for i, a in enumerate(colours) for b in colours[i + 1 :])
    assert closest > 0.3  # viridis gave 176 and 184 BPM a difference of about 0.2
    # Coinciding curves: neighbours differ in line style and in where their markers sit.
    for a, b in zip(lines, lines[1:], strict=False):
        assert a.get_linestyle() != b.get_linestyle()
        assert a.get_markevery() != b.get_markevery()


def test_critical_bands_stay_inside_the_swept_grid_and_symbols_are_typeset():
    rng = np.random.default_rng(0)
    bpm = np.arange(180.0, 190.5, 2.0)
    x = (bpm - 180)[None, :, None]  # a transition at the top end: wide error bars there
    r = 0.2 + 0.006 * x**2 + rng.normal(0, 1, (1, 6, 40)) * (0.002 + 0.01 * x)
    sweep = xr.Dataset({"r_eq": (("n", "bpm", "run"), r)}, coords={"n": [7], "bpm": bpm})
    fig = plot_critical(critical_frequency(sweep, n_boot=30))
    for ax in fig.axes[:2]:
        for patch in ax.patches:
            xs = patch.get_xy()[:, 0] if hasattr(patch, "get_xy") else []
            assert np.all((np.asarray(xs) >= 180.0) & (np.asarray(xs) <= 190.0))
    _no_literal_subscripts(_texts(fig))


def test_plot_run_keeps_its_legends_beside_the_panels():
    ds = metrosync.simulate(3, 192.0, duration=4.0, record_every=2, trajectories=True)
    fig = metrosync.plot_run(ds)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    for ax in fig.axes:
        legend = ax.get_legend()
        if legend is not None:
            assert legend.get_window_extent(renderer).x0 >= ax.get_window_extent(renderer).x1
    _no_literal_subscripts(_texts(fig))
    import matplotlib.pyplot as plt

    plt.close(fig)
