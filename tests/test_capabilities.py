"""The capability table: every consumer asked about every feature either runs it or
refuses it by name, and the table says which."""

from __future__ import annotations

import re
import subprocess
import sys
import warnings

import numpy as np
import pytest

from metrosync import ParameterError, build_ensemble, get_preset, simulate
from metrosync.capabilities import (
    CONSUMERS,
    FEATURES,
    UnsupportedFeature,
    consumer_of,
    features_on,
    require,
    runs,
)
from metrosync.errors import EscapementWarning
from metrosync.integrators import BACKENDS, REGISTRY
from metrosync.model import Metronome, MetronomeDesign
from metrosync.show.playground import playground_config
from two_coordinates import padded


def simulate_options(name: str) -> dict:
    """`simulate`'s keyword arguments that switch feature ``name`` on, for N = 2."""
    f = FEATURES[name]
    options = {"changes": dict(f.example)} if f.kind == "model" else dict(f.example)
    if "groups" in options:
        return {"n": None, "bpm": None, **options}
    return {"n": 2, "bpm": 192.0, **options}


def test_the_consumers_are_the_registry_and_the_playground():
    expected = {f"{i.name}/{b}" for i in REGISTRY.values() for b in i.backends}
    assert set(CONSUMERS) == expected | {"playground"}
    for c in CONSUMERS.values():
        assert c.runs <= set(FEATURES)
        assert c.cost in ("compiled", "numpy", "whole-run")
        if c.integrator and REGISTRY[c.integrator].fixed_step:
            assert c.backend in BACKENDS
    for f in FEATURES.values():
        assert f.summary and f.lacks and f.parameters and f.kind in ("model", "run", "system")


#: What switches on each feature that no parameter makes yet, in the per-run arrays.
SYSTEM_EXAMPLES = {"platform-coordinates": padded}
BY_PARAMETERS = [name for name, f in FEATURES.items() if f.kind != "system"]


def assert_refused_by_name(refused, consumer: str, feature: str) -> None:
    """``refused`` names the feature, its parameter and the consumer, and offers
    consumers that run it."""
    integrator = consumer.split("/")[0]
    assert refused.feature == feature and refused.consumer == consumer
    message = str(refused)
    assert f"`{FEATURES[feature].parameters[0]}` = " in message
    assert FEATURES[feature].lacks in message and "; use " in message
    # What it offers instead does run the feature.
    offered = message.rsplit("; use ", 1)[1]
    names = re.findall(r"'(\w+)'", offered)
    assert names
    for other in names:
        if offered.startswith("backend="):
            assert runs(f"{integrator}/{other}", feature)
        else:
            assert runs(consumer_of(other, REGISTRY[other].backends[0]).name, feature)


@pytest.mark.parametrize("feature", BY_PARAMETERS)
@pytest.mark.parametrize("consumer", [c for c in CONSUMERS if c != "playground"])
def test_every_integrator_runs_each_feature_or_refuses_it_by_name(consumer, feature):
    integrator, backend = consumer.split("/")
    runs_it = runs(consumer, feature)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", EscapementWarning)  # the death feature's start
            ds = simulate(**simulate_options(feature), duration=2.0, integrator=integrator,
                          backend=backend if backend in BACKENDS else "numba", progress=False)  # fmt: skip  # noqa: E501
    except UnsupportedFeature as refused:
        assert not runs_it, f"{consumer} refused {feature}, which the table says it runs"
        assert_refused_by_name(refused, consumer, feature)
        return
    except ParameterError as error:  # no GPU here: the table let it through to the device
        assert backend == "gpu" and "needs an NVIDIA GPU" in str(error), error
        assert runs_it
        return
    assert runs_it, f"{consumer} ran {feature}, which the table says it does not"
    if feature == "trajectories":
        assert "theta" in ds
    if feature == "groups":
        assert "group" in ds.dims
    if feature == "death":
        assert bool(ds.escapement_stopped.isel(run=0, metronome=0))


def test_every_feature_no_parameter_makes_has_an_example_here():
    assert {n for n, f in FEATURES.items() if f.kind == "system"} == set(SYSTEM_EXAMPLES)


@pytest.mark.parametrize("feature", list(SYSTEM_EXAMPLES))
@pytest.mark.parametrize("consumer", list(CONSUMERS))
def test_every_consumer_takes_the_arrays_of_a_feature_or_refuses_them_by_name(consumer, feature):
    """The per-run arrays alone switch these on; each consumer's entry point asks the
    table with them (tests/integrators/test_platform_coordinates.py runs them)."""
    plain = build_ensemble(3, 192.0, params=get_preset("default"), runs=2, seed=1).system
    system = SYSTEM_EXAMPLES[feature](plain)
    assert [f.name for f, _ in features_on(system)] == [feature]
    if runs(consumer, feature):
        require(consumer, system)
        return
    with pytest.raises(UnsupportedFeature) as refused:
        require(consumer, system)
    if consumer == "playground":
        assert "the playground has no" in str(refused.value)
    else:
        assert_refused_by_name(refused.value, consumer, feature)


@pytest.mark.parametrize("feature", BY_PARAMETERS)
def test_the_playground_runs_each_feature_or_refuses_it_by_name(feature):
    f = FEATURES[feature]
    if f.kind != "model":  # the page takes model parameters only: ask the table
        request = {p: f.example.get(p, True) for p in f.parameters}
        if runs("playground", feature):
            require("playground", request)
        else:
            with pytest.raises(UnsupportedFeature, match=f"`{f.parameters[0]}` = "):
                require("playground", request)
        return
    if runs("playground", feature):
        assert playground_config(changes=f.example)["start"]["preset"] == "default+changes"
    else:
        with pytest.raises(UnsupportedFeature, match=f"`{f.parameters[0]}` = .*the playground"):
            playground_config(changes=f.example)


@pytest.mark.parametrize(
    "feature", [n for n, f in FEATURES.items() if f.from_system and f.kind == "model"]
)
def test_the_per_run_arrays_tell_the_same_as_the_parameters(feature):
    params = get_preset("default").with_changes(**FEATURES[feature].example)
    ens = build_ensemble(3, 192.0, params=params, runs=2, seed=1)
    assert [f.name for f, _ in features_on(params)] == [feature]
    assert [f.name for f, _ in features_on(ens.system)] == [feature]
    plain = build_ensemble(3, 192.0, params=get_preset("default"), runs=2, seed=1)
    assert features_on(plain.system) == []
    for name, c in CONSUMERS.items():
        if feature in c.runs:
            require(name, ens.system)
        else:
            with pytest.raises(UnsupportedFeature, match=FEATURES[feature].parameters[0]):
                require(name, ens.system)


def test_a_metronome_given_one_by_one_switches_a_feature_on_in_the_arrays():
    plain, out_of_beat = Metronome(), Metronome(MetronomeDesign(escapement_offset=-0.05))
    ens = build_ensemble(None, None, params=get_preset("default"), runs=1, seed=1,
                         metronomes=[plain, out_of_beat])  # fmt: skip
    found = features_on(ens.system)
    assert [f.name for f, _ in found] == ["escapement-offset"]
    assert found[0][1] == ("escapement_offset", -0.05, "rad")
    assert np.count_nonzero(ens.system.escapement_offset) == 1


def test_refusals_keep_the_project_s_words():
    with pytest.raises(UnsupportedFeature) as refused:
        simulate(2, 192, duration=1.0, integrator="located", changes={"disk_dry_friction": 5e-3})
    assert str(refused.value) == (
        "`disk_dry_friction` = 0.005 N m: integrator 'located' has no dry friction on the "
        "platform; use integrator='verlet' (or 'exact')."
    )
    with pytest.raises(UnsupportedFeature) as refused:
        simulate(2, 192, duration=1.0, integrator="located", preset="pantaleone2002",
                 changes={"board_dry_friction": 0.02})  # fmt: skip
    assert str(refused.value) == (
        "`board_dry_friction` = 0.02 N: integrator 'located' has no dry friction on the "
        "platform; use integrator='verlet' (or 'exact')."
    )
    with pytest.raises(UnsupportedFeature) as refused:
        require("verlet/gpu", get_preset("default").with_changes(disk_dry_friction=5e-3))
    assert str(refused.value).endswith("use backend='numba' (or 'numpy').")


def test_reading_the_table_loads_nothing_heavy():
    code = (
        "import sys, metrosync.capabilities, metrosync.cli\n"
        "print(sorted({m.split('.')[0] for m in sys.modules} & {'numba', 'scipy', 'xarray'}))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_the_budget_times_each_consumer_as_its_cost_in_the_table_says():
    from metrosync import budget

    size = {"n": 7, "runs": 10, "steps": 1000, "records": 101, "trajectories": False}
    per_run_step = 10 * 1000 * (budget.NUMBA_RUN_STEP + budget.NUMBA_OSC_STEP * 7)
    expected = {
        "compiled": per_run_step,
        "numpy": 1000 * (budget.NUMPY_STEP + budget.NUMPY_OSC_STEP * 70),
        "whole-run": 10 * 1000 * 0.01 * (budget.EXACT_RUN_SECOND + budget.EXACT_OSC_SECOND * 7),
    }
    for c in CONSUMERS.values():
        if c.integrator is None:
            continue
        estimate = budget.simulation_budget(**size, integrator=c.integrator, backend=c.backend)
        assert estimate.seconds == pytest.approx(expected[c.cost]), c.name
        assert ("one run's samples" in estimate.arrays) == (c.cost == "whole-run")
