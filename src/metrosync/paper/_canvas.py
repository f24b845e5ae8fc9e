"""What every paper figure is drawn on and saved as: a plain `Figure`, a colour map's
colours, and the PNG + PDF pair (`metrosync.paper.figures`, `metrosync.paper.map_figures`).
"""

from __future__ import annotations

from pathlib import Path

from .._files import save_figure

FORMATS = ("png", "pdf")
DPI = 110


def new_figure(nrows: int = 1, ncols: int = 1, **options):
    """A plain `Figure` (no pyplot, no backend switch) and its axes."""
    from matplotlib.figure import Figure  # loaded when a figure is drawn, not on import

    sharex = options.pop("sharex", False)
    fig = Figure(**options)
    return fig, fig.subplots(nrows, ncols, sharex=sharex)


def palette(name: str, values):
    """The colours of the colour map ``name`` at ``values`` (0 .. 1, or indices)."""
    from matplotlib import colormaps

    return colormaps[name](values)


def save_formats(fig, stem: Path) -> list[Path]:
    """``fig`` written as ``<stem>.png`` and ``<stem>.pdf``; the written paths."""
    return [save_figure(fig, Path(stem).with_suffix(f".{ext}"), dpi=DPI) for ext in FORMATS]
