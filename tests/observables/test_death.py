"""Metronome death: an escapement that stops firing is noticed by every backend."""

import math

import numpy as np
import pytest

from metrosync import get_preset, simulate
from metrosync.errors import EscapementWarning
from metrosync.observables.death import SILENT_PERIODS, flag_stopped, stopped_metronomes
from metrosync.status import STATUS_DIVERGED, STATUS_OVERTURNED, STATUS_STOPPED

OMEGA = 2 * math.pi  # a period of 1 s


def test_a_metronome_is_stopped_when_its_last_impulse_is_older_than_two_periods():
    last = np.array([[9.5, 8.1, -1.0], [7.9, 9.9, 9.9]])
    stopped = stopped_metronomes(last, 10.0, np.full(last.shape, OMEGA))
    np.testing.assert_array_equal(stopped, [[False, False, True], [True, False, False]])
    assert SILENT_PERIODS == 2.0
    # A run shorter than the span is not judged, even without any impulse.
    assert not stopped_metronomes(np.full((1, 2), -1.0), 1.5, np.full((1, 2), OMEGA)).any()


def test_the_bit_adds_to_others_but_not_to_a_diverged_run():
    last = np.array([[-1.0], [-1.0], [9.9]])
    status = np.array([STATUS_OVERTURNED, STATUS_DIVERGED, 0], dtype=np.int8)
    flagged = flag_stopped(status, last, 10.0, np.full(last.shape, OMEGA))
    np.testing.assert_array_equal(flagged, [STATUS_OVERTURNED | STATUS_STOPPED, STATUS_DIVERGED, 0])
    assert status[0] == STATUS_OVERTURNED  # the input is left alone


#: (integrator, backend) pairs: every CPU backend of every integrator.
BACKENDS = [("verlet", "numba"), ("verlet", "numpy"), ("located", "numba"),
            ("located", "numpy"), ("exact", "scipy")]  # fmt: skip


def dying(integrator, backend, **kwargs):
    """Three metronomes started at 0.1, 0.6 and 0.7 rad at rest under an escapement at
    0.25 rad: the first never reaches it, the others keep swinging about 0.7 rad."""
    options = {"integrator": integrator, "duration": 12.0, "dt": 0.005,
               "theta0": [0.1, 0.6, 0.7], "theta_dot0": [0.0] * 3}  # fmt: skip
    if integrator != "exact":
        options["backend"] = backend
    with pytest.warns(EscapementWarning, match="lies beyond the start swing"):
        return simulate(3, 192, changes={"escapement_offset": 0.25}, **options, **kwargs)


@pytest.mark.parametrize("integrator, backend", BACKENDS)
def test_every_backend_flags_an_escapement_that_never_fires(integrator, backend):
    ds = dying(integrator, backend)
    assert int(ds.status[0]) == STATUS_STOPPED
    np.testing.assert_array_equal(ds.escapement_stopped.values, [[True, False, False]])
    assert np.isnan(ds.tick_rate_bpm.values).all()  # a flagged run has no steady tick


@pytest.mark.parametrize("integrator, backend", BACKENDS)
def test_every_backend_flags_an_escapement_that_stops_firing(integrator, backend):
    # A weak drive cannot keep a 0.6 rad swing: it fires at first, then the swing decays
    # below the escapement's angle and it stops (within about 5 s).
    params = get_preset("default")
    changes = {"escapement_offset": 0.3, "drive": 0.1 * params.as_dict()["drive"]}
    options = {"integrator": integrator, "duration": 12.0, "dt": 0.005, "amplitude": 0.6}
    if integrator != "exact":
        options["backend"] = backend
    ds = simulate(2, 192, runs=2, changes=changes, trajectories=True, **options)
    np.testing.assert_array_equal(ds.status.values, [STATUS_STOPPED] * 2)
    assert ds.escapement_stopped.values.all()
    early = ds.theta.sel(time=slice(0, 0.7)).values
    assert np.abs(early).max() > 0.3  # it did swing through the escapement at first


@pytest.mark.parametrize("integrator, backend", BACKENDS)
def test_every_backend_leaves_a_live_run_unflagged(integrator, backend):
    options = {"integrator": integrator, "duration": 12.0, "dt": 0.005}
    if integrator != "exact":
        options["backend"] = backend
    ds = simulate(3, 192, changes={"escapement_offset": 0.2}, **options)
    assert int(ds.status[0]) == 0 and "escapement_stopped" not in ds


def test_no_warning_when_every_escapement_is_within_the_start_swing(recwarn):
    simulate(2, 192, duration=2.0, changes={"escapement_offset": 0.2}, amplitude=0.5)
    assert not [w for w in recwarn if issubclass(w.category, EscapementWarning)]


def test_the_warning_names_the_offset_the_swing_and_the_fix():
    with pytest.warns(EscapementWarning) as caught:
        ds = simulate(2, 192, runs=3, duration=12.0, changes={"escapement_offset": 0.5},
                      amplitude=0.4)  # fmt: skip
    text = str(caught[0].message)
    assert "`escapement_offset` = 0.5 rad lies beyond `amplitude` = 0.4 rad (0.4 rad)" in text
    assert "of 6 metronomes in 3 of 3 runs" in text and "metronome death" in text
    assert "start wider (`amplitude`)" in text
    assert (ds.status.values == STATUS_STOPPED).all()
