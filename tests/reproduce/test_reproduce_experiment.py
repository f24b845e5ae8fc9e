"""Fig. 9 plumbing: folder layout checks, and the comparison through `lightgate.analyze`."""

from __future__ import annotations

import sys
import types

import numpy as np
import pytest
import xarray as xr

from metrosync import MetrosyncError, ParameterError
from metrosync.paper.experiment import compare_experiment, find_experiment
from metrosync.paper.figures import plot_comparison


def _layout(root, bpms=(160, 192)):
    for bpm in bpms:
        (root / str(bpm)).mkdir(parents=True)
        for k in range(2):
            (root / str(bpm) / f"run{k}.txt").write_text("0-0-0-0-0-0-0 0\n")
    (root / "notes").mkdir()
    return root


def test_layout_is_read_by_bpm(tmp_path):
    found = find_experiment(_layout(tmp_path))
    assert list(found) == [160.0, 192.0]
    assert [p.name for p in found[192.0]] == ["run0.txt", "run1.txt"]


def test_bad_layouts_fail_early_with_a_fix(tmp_path):
    with pytest.raises(ParameterError, match="not a folder"):
        find_experiment(tmp_path / "missing")
    (tmp_path / "empty").mkdir()
    with pytest.raises(ParameterError, match="192"):
        find_experiment(tmp_path / "empty")


def _simulated():
    return xr.Dataset(
        {"r_eq_mean": ("case", [0.5, 0.9]), "sigma_r": ("case", [0.1, 0.02])},
        coords={"case": ["a", "b"], "bpm": ("case", [160.0, 192.0])},
    )


def test_comparison_pairs_each_folder_with_the_simulation(tmp_path, monkeypatch):
    seen = []

    def analyze(paths):
        seen.append(list(paths))
        r = 0.25 + 0.5 * len(seen)
        # two logs whose own equilibrium r is r -+ 0.1: their std is 0.1 * sqrt(2)
        r_runs = np.array([[r - 0.1] * 4, [r + 0.1] * 4])
        return xr.Dataset({"r_runs": (("log", "time"), r_runs)}, coords={"time": np.arange(4.0)},
                          attrs={"r_eq": r, "equilibrium_window": 1.0})  # fmt: skip

    fake = types.ModuleType("metrosync.lightgate")
    fake.analyze = analyze
    monkeypatch.setitem(sys.modules, "metrosync.lightgate", fake)
    ds = compare_experiment(_layout(tmp_path / "exp", bpms=(160, 192, 200)), _simulated())
    assert [len(p) for p in seen] == [2, 2, 2]
    np.testing.assert_allclose(ds.r_exp, [0.75, 1.25, 1.75])
    np.testing.assert_allclose(ds.r_exp_std, 0.1 * np.sqrt(2))  # Fig. 9's error bar in r_exp
    np.testing.assert_allclose(ds.r_sim.values[:2], [0.5, 0.9])
    assert np.isnan(ds.r_sim.values[2])  # 200 BPM was not simulated
    paths = plot_comparison(ds, tmp_path / "fig9")
    assert all(p.stat().st_size > 0 for p in paths)


def test_missing_pipeline_is_a_clear_error(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "metrosync.lightgate", None)
    with pytest.raises(MetrosyncError, match="light-gate"):
        compare_experiment(_layout(tmp_path), _simulated())


def _write_log(path, offsets, period_s, duration_s, tick=64e-6):
    """Seven gates, each passed twice a period at an off-centre point (short/long gaps)."""
    events = []
    for gate, offset in enumerate(offsets):
        t = offset
        while t < duration_s:
            for shift in (0.0, 0.35 * period_s):
                events.append((t + shift, gate, 1))
                events.append((t + shift + 0.01, gate, 0))
            t += period_s
    events.sort()
    state = [0] * len(offsets)
    lines = []
    for t, gate, value in events:
        state[gate] = value
        lines.append("-".join(map(str, state)) + f" {int(round(t / tick))}")
    path.write_text("\n".join(lines) + "\n")


def test_real_pipeline_sees_synchronized_logs_as_synchronized(tmp_path):
    pytest.importorskip("metrosync.lightgate")
    for bpm in (160, 192):
        folder = tmp_path / "exp" / str(bpm)
        folder.mkdir(parents=True)
        period = 120.0 / bpm
        for k in range(2):
            _write_log(folder / f"run{k}.txt", [0.1 * period] * 7, period, 120.0)
    ds = compare_experiment(tmp_path / "exp", _simulated())
    assert np.all((ds.r_exp > 0.9) & (ds.r_exp <= 1.0 + 1e-9))
