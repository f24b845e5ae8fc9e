"""The consistency table's predictions agree with what the model does."""

from __future__ import annotations

import math

import numpy as np
import pytest

from metrosync import PRESETS
from metrosync.paper.consistency import consistency_table, markdown_table


@pytest.fixture(scope="module")
def table():
    return consistency_table([160.0, 192.0, 208.0])


def test_predicted_and_measured_overturning_agree(table):
    assert list(table.overturns_predicted.values) == list(table.overturns_measured.values)
    assert not bool(table.overturns_measured.sel(preset="default"))
    assert bool(table.overturns_measured.sel(preset="boda2013"))
    # energy balance predicts the default swing to within 2 %
    default = table.sel(preset="default")
    assert float(default.amplitude_measured) == pytest.approx(
        float(default.steady_amplitude), rel=0.02
    )
    assert float(table.steady_amplitude.sel(preset="boda2013")) == pytest.approx(
        2 * 6e-4 / (math.pi * 5e-5)
    )


def test_l2_inverts_the_model_and_shows_the_range_discrepancy(table):
    design = PRESETS["default"].metronome
    np.testing.assert_allclose(
        table.l2.sel(preset="default"), design.l2_for_bpm([160.0, 192.0, 208.0])
    )
    text = markdown_table(table)
    assert "| 160 | 0.0619 | no |" in text  # 160 BPM needs a slider beyond the paper's 0.049 m
    assert "| 208 | 0.0352 | yes |" in text
    assert "(rotating)" in text
