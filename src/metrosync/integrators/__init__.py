"""Integrators, picked by name from one table (as scipy's ``solve_ivp`` and diffrax do).

Each `Integrator` declares its name, its convergence order without and with the
escapement's kicks, the backends it runs on, and the module of each backend (imported
on first use, so that importing metrosync does not load numba or scipy). Which model
features and records each backend has is the table of `metrosync.capabilities`
(``Integrator.trajectories`` reads it); `simulate` asks that table before it runs.
`simulate` looks a name up with `get_integrator`; the CLI's ``--integrator`` choices
are `integrator_names()`; an unknown name lists the valid ones.

There are two kinds. A *fixed-step* scheme advances a `StepState` chunk by chunk:
`Integrator.stepper` gives the backend's module, whose ``advance_state(state, sys, *,
dt, step0, n_steps, record_every, overturn_angle)`` the driver in `simulate` calls.
A *whole-run* integrator (``exact``) integrates every run in one call,
``integrate(sys, theta0, theta_dot0, phi_dot0, *, duration, grid_dt, n_records,
trajectories, overturn_angle, on_run_done)``.

A new scheme adds one entry to `REGISTRY` and a test that measures the orders it
declares (tests/integrators/test_verlet.py does so for ``verlet``).
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass, field
from types import ModuleType

from ..capabilities import backends_running, consumer_of, require
from ..errors import ParameterError

#: The backends a user can ask for, with what each is.
BACKENDS = {
    "numba": "compiled CPU kernel, parallel over runs",
    "numpy": "plain NumPy twin of the compiled kernel (slow; the reference it is tested against)",
    "gpu": "an NVIDIA GPU through numba.cuda (no trajectories yet)",
}


@dataclass(frozen=True)
class Integrator:
    """What a user can rely on about one integrator.

    name : the name `simulate` and ``--integrator`` take.
    summary : one line for help texts.
    order : global order of accuracy in dt without kicks (smooth dynamics).
    order_with_kicks : the same with the escapement's impulses.
    modules : backend name → where it is implemented, ``module`` or ``module:object``
        (the first is the default).
    fixed_step : True for a scheme driven step by step (see the module docstring).
    """

    name: str
    summary: str
    order: int
    order_with_kicks: int
    modules: dict[str, str] = field(repr=False)
    fixed_step: bool

    @property
    def backends(self) -> tuple[str, ...]:
        return tuple(self.modules)

    @property
    def trajectories(self) -> tuple[str, ...]:
        """The backends that record θ, θ̇, φ, φ̇ (`metrosync.capabilities`)."""
        return backends_running(self.name, "trajectories")

    def require(self, backend: str, *sources) -> None:
        """Refuse what this scheme cannot run on ``backend``: `ParameterError` if it
        lacks the backend, `metrosync.capabilities.UnsupportedFeature` for a feature on
        in ``sources`` (model parameters, system arrays, a mapping of `simulate`'s
        options) that the backend does not run. A whole-run integrator has one backend,
        whatever ``backend`` says."""
        if self.fixed_step:
            self._check_backend(backend)
        require(consumer_of(self.name, backend).name, *sources)

    def _check_backend(self, backend: str) -> None:
        if backend not in self.modules:
            raise ParameterError(
                f"`integrator` {self.name!r} has no backend {backend!r}; "
                f"choose one of {list(self.modules)}."
            )

    def stepper(self, backend: str, *, trajectories: bool) -> ModuleType:
        """The module that advances this scheme on ``backend``; `ParameterError` if the
        scheme lacks that backend, the backend cannot record the asked trajectories, or
        it needs hardware this machine does not have."""
        self._check_backend(backend)
        if backend == "gpu":
            _require_gpu()
        if trajectories:
            require(consumer_of(self.name, backend).name, {"trajectories": True})
        return load_backend(self.modules[backend])

    def integrate(self, *args, **kwargs):
        """Run a whole-run integrator (see the module docstring for the arguments)."""
        if self.fixed_step:
            raise TypeError(f"{self.name!r} is a fixed-step scheme: drive its `stepper`.")
        return load_backend(self.modules[self.backends[0]]).integrate(*args, **kwargs)


REGISTRY: dict[str, Integrator] = {
    "verlet": Integrator(
        name="verlet",
        summary="the paper's fixed-step velocity-Verlet-type scheme with the discrete ±M/dt kick",
        order=2,  # measured: tests/integrators/test_verlet.py
        order_with_kicks=1,  # the kick is quantised to the step; measured there too
        modules={
            "numba": "metrosync.integrators.verlet",
            "numpy": "metrosync.integrators.twin:VERLET",
            "gpu": "metrosync.integrators.kernel_cuda:VERLET",
        },
        fixed_step=True,
    ),
    "located": Integrator(
        name="located",
        summary="the paper's fixed-step scheme with each escapement impulse applied at its "
        "located crossing instant",
        order=2,
        order_with_kicks=2,
        modules={
            "numba": "metrosync.integrators.located",
            "numpy": "metrosync.integrators.twin:LOCATED",
            "gpu": "metrosync.integrators.kernel_cuda:LOCATED",
        },
        fixed_step=True,
    ),
    "exact": Integrator(
        name="exact",
        summary="the accurate reference: DOP853 between impulses, each crossing located "
        "and kicked exactly",
        order=8,  # DOP853's; its error is set by its tolerances, not by a step
        order_with_kicks=8,  # crossings located on the dense output, impulses exact
        modules={"scipy": "metrosync.integrators.exact"},
        fixed_step=False,
    ),
}


def integrator_names() -> tuple[str, ...]:
    """The registered integrators' names, the default (``verlet``) first."""
    return tuple(REGISTRY)


def get_integrator(name: str) -> Integrator:
    """The integrator called ``name``; `ParameterError` listing the valid names if none."""
    try:
        return REGISTRY[name]
    except (KeyError, TypeError):
        raise ParameterError(
            f"unknown `integrator` {name!r}; choose one of {list(REGISTRY)}."
        ) from None


def load_backend(where: str):
    """The module ``package.module``, or the object ``package.module:name`` in it."""
    module, _, name = where.partition(":")
    loaded = importlib.import_module(module)
    return getattr(loaded, name) if name else loaded


def _require_gpu() -> None:
    from . import kernel_cuda

    if not kernel_cuda.gpu_available():
        raise ParameterError(
            "`backend` 'gpu' needs an NVIDIA GPU with a working CUDA driver, and numba found "
            "none (numba.cuda.is_available() is False). Install the driver and "
            "`pip install metrosync[gpu]` on a GPU machine, or use backend='numba'."
        )


#: The names alone, as before the registry (kept for callers that test membership).
INTEGRATORS = integrator_names()
