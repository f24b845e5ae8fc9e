"""`simulate` is its stages composed one way: request -> ensemble -> run -> dataset."""

from __future__ import annotations

import dataclasses

import pytest

from metrosync import simulate
from metrosync.errors import ParameterError
from metrosync.simulation.dataset import to_dataset
from metrosync.simulation.request import SimulationRequest
from metrosync.simulation.run import run


def test_the_stages_by_hand_give_what_simulate_gives():
    options = dict(n=3, bpm=192.0, sigma_bpm=0.5, runs=2, duration=3.0, backend="numpy")
    request = SimulationRequest(**options)
    ensemble = request.build_ensemble()
    by_hand = to_dataset(request, ensemble, run(request, ensemble))
    assert by_hand.identical(simulate(**options))


def test_a_request_resolves_what_follows_from_its_options_and_stays_as_made():
    request = SimulationRequest(duration=3.0, dt=0.01)
    assert (request.n_steps, request.stride, request.n_records) == (300, 10, 31)
    assert request.stride_reason == "default 0.1 s" and request.params.name == "default"
    assert request.simulated_time == pytest.approx(3.0) and request.window() == 0.75
    with pytest.raises(dataclasses.FrozenInstanceError):
        request.dt = 0.02  # type: ignore[misc]


def test_a_request_checks_itself_when_made():
    with pytest.raises(ParameterError, match="unknown `backend` 'abacus'"):
        SimulationRequest(backend="abacus")
    with pytest.raises(ParameterError, match="`duration` must be a finite time > 0 s"):
        SimulationRequest(duration=-1.0)
