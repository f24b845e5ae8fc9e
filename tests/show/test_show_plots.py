"""Single-run plots: four panels, the equilibrium window, a written file."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from metrosync.show.plots import plot_run


def test_plot_run_draws_four_panels_and_marks_the_window(recorded_ds, tmp_path):
    fig = plot_run(recorded_ds, run=0)
    axes = fig.axes
    assert [ax.get_ylabel() for ax in axes] == ["θ (rad)", r"$\Phi_i - \Phi_0$", "φ (rad)", "r"]
    assert len(axes[0].lines) == 7 and len(axes[1].lines) == 6
    spans = [p for p in axes[3].patches]
    assert len(spans) == 1
    x0, x1 = spans[0].get_x(), spans[0].get_x() + spans[0].get_width()
    assert (x0, x1) == (15.0, 20.0)  # the final quarter of 20 s
    r_eq = float(recorded_ds.r_eq[0])
    marked = [c for c in axes[3].collections if np.allclose(c.get_segments()[0][:, 1], r_eq)]
    assert marked
    plt.close(fig)
    path = tmp_path / "run.png"
    plot_run(recorded_ds, path, start=5.0, end=10.0)
    assert path.stat().st_size > 10_000


def test_a_board_run_plots_the_board_position(board_ds):
    fig = plot_run(board_ds, run=0)
    assert fig.axes[2].get_ylabel() == "x (m)"
    plt.close(fig)
