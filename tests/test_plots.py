"""Figures written to a file leave matplotlib's backend and pyplot's state alone."""

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pytest
import xarray as xr

import metrosync
from metrosync import ParameterError
from metrosync.calibration import Estimate
from metrosync.plots import plot_order
from metrosync.show import plot_run
from metrosync.sweeps.critical import critical_frequency, plot_critical


@pytest.fixture(scope="module")
def run():
    return metrosync.simulate(3, 192.0, runs=2, duration=4.0, record_every=5,
                              trajectories=True, progress=False)  # fmt: skip


def _critical():
    rng = np.random.default_rng(0)
    bpm = np.arange(170.0, 200.5, 2.0)
    r = np.where(rng.random((1, bpm.size, 20)) < (bpm > 185)[None, :, None], 0.9, 0.2)
    return critical_frequency(
        xr.Dataset({"r_eq": (("n", "bpm", "run"), r)}, coords={"n": [7], "bpm": bpm}), n_boot=20
    )


def test_writing_figures_neither_switches_backend_nor_leaks_pyplot_figures(
    run, tmp_path, monkeypatch
):
    def no_switch(*args, **kwargs):
        raise AssertionError("a library function called matplotlib.use")

    monkeypatch.setattr(matplotlib, "use", no_switch)
    before = plt.get_fignums()
    est = Estimate("c", 1.0, "u", np.arange(3.0), np.arange(3.0), np.arange(3.0),
                   np.arange(3.0), "x", "y", "t")  # fmt: skip
    figures = [
        plot_order(run, tmp_path / "order.png"),
        plot_run(run, tmp_path / "run.png"),
        est.plot(tmp_path / "est.png"),
        plot_critical(_critical(), tmp_path / "critical.png"),
    ]
    assert plt.get_fignums() == before
    assert all(fig.axes for fig in figures)
    assert all((tmp_path / f"{name}.png").stat().st_size > 1000
               for name in ("order", "run", "est", "critical"))  # fmt: skip


def test_without_a_path_the_figure_is_pyplots(run):
    fig = plot_order(run)
    assert fig.number in plt.get_fignums()
    plt.close(fig)


def test_path_and_ax_together_are_refused(run, tmp_path):
    fig, ax = plt.subplots()
    with pytest.raises(ParameterError, match="not both"):
        plot_order(run, tmp_path / "x.png", ax=ax)
    assert plot_order(run, ax=ax) is fig
    plt.close(fig)


def test_the_crossing_curve_averages_all_runs_or_none(run):
    fig = plot_order(run)
    y = fig.axes[0].lines[1].get_ydata()
    every = run.r_crossing.notnull().all("run").values
    assert np.array_equal(np.isfinite(y), every) and every.any()
    assert np.allclose(y[every], run.r_crossing.mean("run").values[every])
    plt.close(fig)
