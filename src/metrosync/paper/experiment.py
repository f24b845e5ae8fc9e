"""Fig. 9: simulated against measured equilibrium r, from folders of light-gate logs.

Contract: ``DIR`` holds one sub-folder per nominal ω₀, named by its BPM (``DIR/192/``),
each with the logger captures of that ω₀: every file in it that is not hidden (``*.txt``
from the logger, ``*.log`` from ``metrosync simulate --lightgate-dir``, any name the
reader accepts). `find_experiment` reads each capture up front (so a long
reproduction never fails at its end on a stray file); `compare_experiment`
analyses each folder with `metrosync.lightgate.analyze` (whose result carries the
equilibrium r averaged over the logs in ``attrs["r_eq"]``) and pairs it with the
simulated N = 7 equilibrium r at the same ω₀ from the Fig. 8 (top) study.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from ..errors import MetrosyncError, ParameterError


def find_experiment(directory: Path) -> dict[float, list[Path]]:
    """Map each ω₀ (BPM) to its sorted log files; raise on a layout that cannot work."""
    directory = Path(directory)
    if not directory.is_dir():
        raise ParameterError(f"`--experiment` {str(directory)!r} is not a folder.")
    found: dict[float, list[Path]] = {}
    for sub in sorted(directory.iterdir()):
        if not sub.is_dir():
            continue
        try:
            bpm = float(sub.name)
        except ValueError:
            continue  # folders not named by a BPM are not ω₀ data
        logs = sorted(p for p in sub.iterdir() if p.is_file() and not p.name.startswith("."))
        if logs:
            found[bpm] = logs
    if not found:
        raise ParameterError(
            f"`--experiment` {str(directory)!r} holds no folder named by a BPM with light-gate "
            f"logs; expected e.g. {str(directory / '192' / 'run01.txt')!r} (or run01.log)."
        )
    _check_captures([path for paths in found.values() for path in paths])
    return found


def _check_captures(paths: list[Path]) -> None:
    """Read every capture once, so a file the reader refuses stops the run at its start."""
    from ..errors import LogFormatError
    from ..lightgate.reader import read_log

    for path in paths:
        try:
            read_log(path)
        except LogFormatError as error:
            raise ParameterError(
                f"`--experiment`: {str(path)!r} is not a light-gate capture ({error}); move it "
                f"out of the folder."
            ) from None


def lightgate_analyze():
    """The light-gate pipeline's `analyze`, imported only when experiments are given."""
    try:
        from ..lightgate import analyze
    except ImportError as error:
        raise MetrosyncError(
            f"`--experiment` needs the light-gate analysis (metrosync.lightgate), which is not "
            f"available in this installation ({error})."
        ) from None
    return analyze


def compare_experiment(directory: Path, simulated: xr.Dataset) -> xr.Dataset:
    """r_exp and r_sim (with σ_r of the simulation) for each ω₀ found in ``directory``.

    Parameters
    ----------
    directory : the ``--experiment`` folder.
    simulated : the Fig. 8 (top) study dataset, with ``bpm``, ``r_eq_mean`` and
        ``sigma_r`` along ``case``.

    Returns
    -------
    Dataset over ``bpm`` with ``r_exp``, ``r_exp_std`` (σ of the logs' own equilibrium
    r, NaN for one log), ``n_logs``, ``r_sim``, ``sigma_r_sim``; r_sim is NaN for an ω₀
    the simulation did not cover.
    """
    from ..observables.order import equilibrium_order

    analyze = lightgate_analyze()
    logs = find_experiment(directory)
    bpms = sorted(logs)
    r_exp, r_exp_std = [], []
    for b in bpms:
        measured = analyze(logs[b])
        r_exp.append(float(measured.attrs["r_eq"]))
        per_log = equilibrium_order(measured.r_runs.values.T, measured.time.values,
                                    measured.attrs["equilibrium_window"])  # fmt: skip
        r_exp_std.append(float(np.std(per_log, ddof=1)) if per_log.size > 1 else np.nan)
    sim_bpm = np.asarray(simulated.bpm.values, dtype=float)
    r_sim, s_sim = [], []
    for b in bpms:
        hit = np.nonzero(np.isclose(sim_bpm, b))[0]
        r_sim.append(float(simulated.r_eq_mean.values[hit[0]]) if hit.size else np.nan)
        s_sim.append(float(simulated.sigma_r.values[hit[0]]) if hit.size else np.nan)
    return xr.Dataset(
        {
            "r_exp": ("bpm", r_exp, {"long_name": "measured equilibrium r (mean over logs)"}),
            "r_exp_std": ("bpm", r_exp_std, {"long_name": "std over logs of their equilibrium r"}),
            "n_logs": ("bpm", [len(logs[b]) for b in bpms]),
            "r_sim": ("bpm", r_sim, {"long_name": "simulated equilibrium r, N = 7"}),
            "sigma_r_sim": ("bpm", s_sim),
        },
        coords={"bpm": ("bpm", bpms, {"units": "BPM"})},
        attrs={
            "experiment_dir": str(directory),
            "simulated_study": simulated.attrs.get("study", ""),
        },
    )
