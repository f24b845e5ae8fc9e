"""The integrator registry: what each integrator declares is what `simulate` and the
CLI offer and do."""

import pytest

from metrosync import ParameterError, simulate
from metrosync.cli import build_parser
from metrosync.integrators import (
    BACKENDS,
    REGISTRY,
    get_integrator,
    integrator_names,
    load_backend,
)


@pytest.mark.parametrize("name", integrator_names())
def test_every_backend_of_every_integrator_is_implemented(name):
    scheme = get_integrator(name)
    assert scheme.name == name and scheme.summary
    assert 1 <= scheme.order and 1 <= scheme.order_with_kicks <= scheme.order
    assert set(scheme.trajectories) <= set(scheme.backends)
    for backend, module in scheme.modules.items():
        entry = "advance_state" if scheme.fixed_step else "integrate"
        assert callable(getattr(load_backend(module), entry)), (backend, module)
        if scheme.fixed_step:
            assert backend in BACKENDS


def test_an_unknown_integrator_lists_the_valid_ones():
    with pytest.raises(ParameterError, match=r"unknown `integrator` 'rk4'; choose one of "):
        get_integrator("rk4")
    with pytest.raises(ParameterError, match=r"\['verlet', 'located', 'exact'\]"):
        simulate(3, 192, duration=1, integrator="rk4")


def test_the_cli_offers_exactly_the_registered_integrators_and_backends(capsys):
    parser = build_parser()
    for name in integrator_names():
        args = parser.parse_args(["simulate", "--integrator", name])
        assert args.integrator == name
    with pytest.raises(SystemExit):
        parser.parse_args(["simulate", "--integrator", "rk4"])
    err = capsys.readouterr().err
    assert all(repr(name) in err for name in REGISTRY)
    for backend in BACKENDS:
        assert parser.parse_args(["simulate", "--backend", backend]).backend == backend


def test_a_backend_that_cannot_record_trajectories_says_which_can():
    verlet = get_integrator("verlet")
    missing = [b for b in verlet.backends if b not in verlet.trajectories]
    assert missing == ["gpu"]
    with pytest.raises(ParameterError, match=r"`integrator` 'verlet' has no backend 'scipy'"):
        verlet.stepper("scipy", trajectories=False)
