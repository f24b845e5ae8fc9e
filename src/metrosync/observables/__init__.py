"""Observables: order parameters, the z parameter, energy and momentum."""

from .mechanics import platform_momentum, total_energy
from .order import (
    analytic_phase,
    common_span,
    crossing_order,
    crossing_phase,
    ensemble_statistics,
    equilibrium_order,
    order_parameter,
)
from .zorder import extrema_times, z_order

__all__ = [
    "analytic_phase",
    "common_span",
    "crossing_order",
    "crossing_phase",
    "ensemble_statistics",
    "equilibrium_order",
    "extrema_times",
    "order_parameter",
    "platform_momentum",
    "total_energy",
    "z_order",
]
