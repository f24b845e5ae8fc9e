"""`Estimate`: the result of a calibration, with what is needed to plot its fit."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np


@dataclass(frozen=True)
class Estimate:
    """An estimated model parameter and the data it was fitted to.

    name, value, unit : the parameter (SI units).
    x, y : (K,) the data of the fit (e.g. time and envelope coordinate).
    fit_x, fit_y : (F,) the fitted curve on the same axes.
    xlabel, ylabel, title : plot labels.
    details : further numbers (standard error, sensitivity, ...).
    """

    name: str
    value: float
    unit: str
    x: np.ndarray
    y: np.ndarray
    fit_x: np.ndarray
    fit_y: np.ndarray
    xlabel: str
    ylabel: str
    title: str
    details: dict = field(default_factory=dict)

    def summary(self) -> str:
        """One line: the value with its unit and the details."""
        extra = ", ".join(f"{k} = {v:.4g}" if isinstance(v, float) else f"{k} = {v}"
                          for k, v in self.details.items())  # fmt: skip
        return f"{self.name} = {self.value:.6g} {self.unit}" + (f" ({extra})" if extra else "")

    def plot(self, path: Path | str | None = None):
        """Data and fitted curve; returns the figure, writes it to ``path`` if given."""
        from ..plots import finish_figure, new_figure

        fig = new_figure(path, figsize=(6, 4), layout="constrained")
        ax = fig.subplots()
        ax.plot(self.x, self.y, "o", ms=4, label="data")
        ax.plot(
            self.fit_x,
            self.fit_y,
            "-",
            lw=1.2,
            label=f"fit: {self.name} = {self.value:.4g} {self.unit}",
        )
        ax.set_xlabel(self.xlabel)
        ax.set_ylabel(self.ylabel)
        ax.set_title(self.title)
        ax.legend()
        return finish_figure(fig, path)
