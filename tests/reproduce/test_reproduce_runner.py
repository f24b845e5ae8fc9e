"""The runner calls the public `simulate` verbatim on the sweep machinery, writes
NetCDF, resumes, and never reuses a point whose model or code changed."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from metrosync import simulate
from metrosync.model import presets as presets_module
from metrosync.paper.runner import StudyIncomplete, points_of, run_study
from metrosync.paper.studies import FIG8_BOTTOM, FIG10, Z_STUDY, Statistics, reduced
from metrosync.sweeps import PointStore
from metrosync.sweeps import points as points_module

SMALL = reduced(FIG8_BOTTOM, runs=2, duration=30.0)


def test_a_point_is_exactly_a_public_simulate_call(tmp_path):
    result = run_study(SMALL, "quick", tmp_path)
    point = points_of(SMALL, "quick")[3]
    direct = simulate(**point.kwargs, progress=False)
    np.testing.assert_array_equal(result.dataset.r_eq.isel(case=3).values, direct.r_eq.values)
    assert result.dataset.n.values[3] == direct.attrs["n"] == 5


def test_study_file_holds_data_units_and_parameters(tmp_path):
    result = run_study(SMALL, "quick", tmp_path)
    ds = xr.load_dataset(result.path, engine="h5netcdf")
    assert set(ds.r_eq.dims) == {"case", "run"} and ds.sizes["case"] == 6
    assert ds.time.attrs["units"] == "s" and ds.sigma_bpm.attrs["units"] == "BPM"
    assert ds.attrs["preset"] == "default" and ds.attrs["drive"] == 6e-5
    assert ds.attrs["wall_time_s"] > 0 and ds.attrs["mode"] == "quick"
    np.testing.assert_allclose(ds.r_eq_mean, ds.r_eq.mean("run"))


def test_second_run_resumes_from_finished_points(tmp_path):
    first = run_study(SMALL, "quick", tmp_path)
    again = run_study(SMALL, "quick", tmp_path)
    assert first.cached_points == 0 and again.cached_points == again.points == 6
    assert again.computed_work == 0 and len(again.cached) == 6
    xr.testing.assert_identical(first.dataset.r_eq, again.dataset.r_eq)
    # the one point store of the output folder, one file per point, each computed once
    store = PointStore(tmp_path)
    assert sorted(store.logged_keys()) == sorted(p.key for p in points_of(SMALL, "quick"))
    # the cost of every point is kept with it, so a fully cached run still has one
    assert again.compute_s == pytest.approx(first.compute_s)
    assert again.total_work == first.total_work > 0 and again.throughput > 0


def test_a_changed_preset_is_recomputed_not_reused(tmp_path, monkeypatch):
    study = reduced(FIG8_BOTTOM, runs=2, duration=20.0)
    first = run_study(study, "quick", tmp_path)
    changed = presets_module.PRESETS["default"].with_changes(drive=8e-5)
    monkeypatch.setitem(presets_module.PRESETS, "default", changed)
    again = run_study(study, "quick", tmp_path)
    assert again.cached_points == 0 and again.computed_work == again.total_work
    expected = simulate(**points_of(study, "quick")[0].kwargs, progress=False)
    assert expected.attrs["drive"] == 8e-5
    np.testing.assert_array_equal(again.dataset.r_eq.isel(case=0).values, expected.r_eq.values)
    assert not np.array_equal(again.dataset.r_eq.values, first.dataset.r_eq.values)
    monkeypatch.undo()  # the preset means what it did: the first points are reused again
    assert run_study(study, "quick", tmp_path).cached_points == 6


def test_changed_simulation_code_is_recomputed(tmp_path, monkeypatch):
    study = reduced(FIG8_BOTTOM, runs=2, duration=20.0)
    run_study(study, "quick", tmp_path)
    monkeypatch.setattr(points_module, "source_digest", lambda root=None: "edited kernel")
    assert run_study(study, "quick", tmp_path).cached_points == 0


def test_changed_statistics_or_broken_files_are_recomputed(tmp_path):
    run_study(SMALL, "quick", tmp_path)
    store = PointStore(tmp_path)
    store.path(points_of(SMALL, "quick")[0].key).write_bytes(b"truncated")
    assert run_study(SMALL, "quick", tmp_path).cached_points == 5
    longer = run_study(reduced(SMALL, duration=40.0), "quick", tmp_path)
    assert longer.cached_points == 0
    assert float(longer.dataset.time[-1]) == 40.0


def test_a_failing_point_stops_the_study_and_names_it(tmp_path):
    bad = reduced(FIG8_BOTTOM, runs=1, duration=0.001)  # shorter than one record
    with pytest.raises(StudyIncomplete, match="point 'N = 2' failed: ParameterError"):
        run_study(bad, "quick", tmp_path)


def test_sweep_is_assembled_on_its_grid(tmp_path):
    sweep = reduced(FIG10, ns=(7, 16), bpms=(170.0, 200.0), stats=Statistics(3, 30.0))
    ds = run_study(sweep, "quick", tmp_path).dataset
    assert ds.r_eq.dims == ("n", "bpm", "run") and ds.r_eq.shape == (2, 2, 3)
    direct = simulate(**points_of(sweep, "quick")[3].kwargs, progress=False)
    np.testing.assert_array_equal(ds.r_eq.sel(n=16, bpm=200.0).values, direct.r_eq.values)
    # each drawn ensemble has the study's spread, up to sampling noise
    assert 0.3 < float(ds.sigma_realized.sel(n=16).mean()) < 1.2


def test_z_study_records_warnings_instead_of_raising(tmp_path):
    ds = run_study(reduced(Z_STUDY, duration=30.0, theta2=(-0.1, 0.1)), "quick", tmp_path).dataset
    assert ds.z.dims == ("regime", "theta2") and ds.z.shape == (4, 2)
    assert "overturn" in ds.attrs["warnings"]
    # identical start (θ₂ = θ₁) is in phase for every regime; θ₂ = −θ₁ is anti-phase
    # whenever the pendulums stay below the horizontal
    np.testing.assert_allclose(ds.z.sel(theta2=0.1), 1.0, atol=1e-6)
    ok = ds.status.sel(theta2=-0.1) == 0
    np.testing.assert_allclose(ds.z.sel(theta2=-0.1).where(ok, drop=True), -1.0, atol=0.05)
    np.testing.assert_array_equal(ds.drive.values, [0.0, 6e-5, 6e-4, 1e-4])


def test_run_mean_is_drawn_only_where_every_run_has_a_phase(tmp_path):
    result = run_study(SMALL, "quick", tmp_path)
    direct = simulate(**points_of(SMALL, "quick")[0].kwargs, progress=False)
    r = direct.r_crossing.values
    full = np.isfinite(r).all(axis=1)
    drawn = result.dataset.r_mean.isel(case=0).values
    np.testing.assert_array_equal(np.isfinite(drawn), full)
    np.testing.assert_allclose(drawn[full], r[full].mean(axis=1))


def test_long_runs_report_progress_point_by_point(tmp_path):
    lines = []
    run_study(SMALL, "quick", tmp_path, log=lines.append)
    assert len(lines) == 6
    assert lines[-1].startswith("  fig8_bottom: 6/6 points")


def test_an_interrupted_study_keeps_its_points_and_resumes(tmp_path, monkeypatch):
    from metrosync.paper.pipeline import kept_points
    from metrosync.sweeps import executors

    real, calls = executors.run_point, []

    def interrupted_after_three(spec, threads=None):
        if len(calls) == 3:
            raise KeyboardInterrupt
        calls.append(spec.key)
        return real(spec, threads)

    monkeypatch.setattr(executors, "run_point", interrupted_after_three)
    with pytest.raises(KeyboardInterrupt):
        run_study(SMALL, "quick", tmp_path)
    assert kept_points(tmp_path, "quick", [SMALL]) == (3, 6)
    monkeypatch.undo()
    resumed = run_study(SMALL, "quick", tmp_path)
    specs = points_of(SMALL, "quick")
    assert resumed.cached_points == 3
    assert resumed.computed_work == sum(spec.work for spec in specs[3:])
    assert PointStore(tmp_path).logged_keys()[:3] == calls  # nothing computed twice
    assert len(set(PointStore(tmp_path).logged_keys())) == 6
    fresh = run_study(SMALL, "quick", tmp_path / "fresh")
    xr.testing.assert_identical(resumed.dataset.r_eq, fresh.dataset.r_eq)
