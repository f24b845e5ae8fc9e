"""The §5 estimation study: known c_θ and M come back; c_φ at the published value does not."""

from __future__ import annotations

import numpy as np
import pytest

from metrosync.paper.claims import claim_estimation
from metrosync.paper.estimation import PARAMETERS
from metrosync.paper.figures import plot_estimation
from metrosync.paper.runner import points_of, run_study
from metrosync.paper.studies import ESTIMATION, reduced

SMALL = reduced(ESTIMATION, c_phi_scan=(1e-6, 1e-5, 1e-3, 1.0, 10.0))


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    return run_study(SMALL, "quick", tmp_path_factory.mktemp("estimation"))


def test_c_theta_and_drive_are_recovered(result):
    ds = result.dataset
    assert list(ds.parameter.values) == [name for name, _ in PARAMETERS]
    for row in ("c_theta (trajectory)", "c_theta (light gate)", "M"):
        assert abs(float(ds.relative_error.sel(parameter=row))) < ESTIMATION.tolerance, row
    assert float(ds.true.sel(parameter="M")) == 6e-5
    assert abs(float(ds.relative_error.sel(parameter="c_phi (control)"))) < 0.02


def test_disk_amplitude_does_not_see_the_published_c_phi(result):
    ds = result.dataset
    amp = ds.disk_amplitude.sel(c_phi=[1e-6, 1e-5]).values
    assert abs(amp[1] / amp[0] - 1) < 1e-3
    assert ds.disk_amplitude.sel(c_phi=10.0) < 0.5 * amp[0]  # it does see a large c_φ
    assert not ds.recovered.sel(parameter="c_phi (published)")
    assert not ds.recovered.sel(parameter="c_phi (published, true c_theta and M)")


def test_verdict_names_what_was_and_was_not_recovered(result):
    verdict = claim_estimation(result.dataset)
    assert verdict.claim == 6 and verdict.verdict == "partly reproduced"
    assert verdict.values["recovered"] == {"c_θ": True, "M": True, "c_φ": False}
    assert "relative change" in verdict.numbers and "c_φ no" in verdict.numbers


def test_the_study_has_no_points_and_leaves_its_files(result, tmp_path):
    assert points_of(ESTIMATION, "full") == [] and result.total_work == 0
    assert result.path.exists() and (result.path.parent / "points" / "estimation").is_dir()
    paths = plot_estimation(result.dataset, tmp_path / "estimation")
    assert [p.suffix for p in paths] == [".png", ".pdf"]
    assert all(p.stat().st_size > 1000 for p in paths)
    assert np.all(np.diff(ESTIMATION.full.c_phi_scan) > 0)
