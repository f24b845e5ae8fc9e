"""Executors: in process, a Dask LocalCluster and an existing Dask scheduler give
bit-identical results."""

import logging

import pytest
import xarray as xr

from metrosync import ParameterError, sweep
from metrosync.sweeps import Grid

GRID = Grid(
    axes={"bpm": "184:192:4", "n": [2, 3]}, fixed={"runs": 3, "duration": 5.0, "sigma": 0.5}
)


@pytest.fixture(scope="module")
def in_process(tmp_path_factory):
    result = sweep(GRID, tmp_path_factory.mktemp("in_process"))
    assert result.complete and len(result.execution.computed) == GRID.size
    return result.dataset


@pytest.mark.slow
def test_local_cluster_with_two_workers_is_bit_identical(tmp_path, in_process):
    result = sweep(GRID, tmp_path, scheduler="local", n_workers=2)
    assert len(result.execution.computed) == GRID.size and not result.execution.lost
    xr.testing.assert_identical(result.dataset, in_process)
    assert result.execution.throughput > 0


@pytest.mark.slow
def test_existing_scheduler_over_tcp_is_bit_identical(tmp_path, in_process):
    from dask.distributed import LocalCluster

    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
        dashboard_address=None, silence_logs=logging.ERROR,
    ) as cluster:  # fmt: skip
        address = cluster.scheduler_address
        assert address.startswith("tcp://127.0.0.1:")
        result = sweep(GRID, tmp_path, scheduler=address)
    xr.testing.assert_identical(result.dataset, in_process)


def test_misplaced_worker_counts_are_clear_errors(tmp_path):
    with pytest.raises(ParameterError, match="n_workers"):
        sweep(GRID, tmp_path, scheduler="tcp://127.0.0.1:1", n_workers=2)
    with pytest.raises(ParameterError, match="`n_workers` must be an integer >= 1"):
        sweep(GRID, tmp_path, scheduler="local", n_workers=0)


def test_a_worker_count_without_a_local_cluster_is_refused(tmp_path):
    with pytest.raises(ParameterError, match="runs in process"):
        sweep(GRID, tmp_path, n_workers=2)
    assert not (tmp_path / "points").exists()
