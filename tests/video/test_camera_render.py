"""The drawing kernels and the pinhole: exact areas, invariance, cost, and projection."""

from __future__ import annotations

import math

import numpy as np
import pytest

from metrosync.video._scene_render import Pinhole, convex_coverage, rod_coverage


def draw(angles, *, length=120.0, rod_hw=1.5, bob_at=60.0, bob_hl=6.0, bob_hw=5.0):
    """Coverage of a rod from (100.3, 150.7) at the angles (h = 1 row each, K samples)."""
    box = (0, 0, 200, 200)
    h, w = box[3], box[2]
    pivot = np.array([100.3, 150.7])
    angles = np.asarray(angles, float)
    direction = np.stack([np.sin(angles), -np.cos(angles)], axis=-1)  # up the picture
    tips = np.broadcast_to(pivot + length * direction, (h, angles.size, 2)).copy()
    bobs = np.broadcast_to(pivot + bob_at * direction, (h, angles.size, 2)).copy()
    rod = np.zeros((h, w), np.float32)
    bob = np.zeros_like(rod)
    span = np.empty((h, 2), np.int64)
    rod_coverage(rod, bob, span, 0, 0, pivot[0], pivot[1], tips, bobs, rod_hw, bob_hl, bob_hw)
    return rod, bob, span


EXPECTED_AREA = 120.0 * 3.0 - 12.0 * 3.0 + 12.0 * 10.0  # rod, less what the bob hides, + bob


@pytest.mark.parametrize("angle", [0.0, 0.4, -0.7])
def test_drawn_area_is_the_rod_s_and_the_bob_s_at_any_angle(angle):
    rod, bob, _ = draw([angle])
    assert float(rod.sum() + bob.sum()) == pytest.approx(EXPECTED_AREA, rel=0.01)
    assert float(bob.sum()) == pytest.approx(120.0, rel=0.01)
    assert rod.max() <= 1.0 + 1e-6 and (rod + bob).max() <= 1.0 + 1e-6


def test_motion_blur_keeps_the_area_and_spreads_it():
    sharp, _, _ = draw([0.2])
    rod, bob, _ = draw(np.linspace(0.1, 0.3, 9))
    assert float(rod.sum() + bob.sum()) == pytest.approx(EXPECTED_AREA, rel=0.01)
    assert np.count_nonzero(rod > 0.01) > 3 * np.count_nonzero(sharp > 0.01)
    # Near the pivot the rod hardly moves; 70 px up it sweeps 14 px, 3 px wide.
    assert sharp[:80].max() == pytest.approx(1.0)
    assert rod[:80].max() < 0.5


def test_only_pixels_near_the_rod_are_visited():
    _, _, span = draw([0.3])
    widths = span[:, 1] - span[:, 0]
    reach = 6.0 + 1.5  # the bob's half length, and a margin
    slope = math.tan(0.3)
    # A row's columns: a band about the rod, as wide as `reach` makes it at this slope.
    assert widths.max() <= 2 * reach * (1 + slope) / math.cos(0.3) + 5
    assert widths.sum() < 0.1 * 200 * 200


def test_convex_coverage_is_the_polygon_s_area():
    square = np.array([[10.2, 10.2], [40.7, 10.2], [40.7, 30.5], [10.2, 30.5]])
    assert float(convex_coverage(square, 0, 0, 50, 50).sum()) == pytest.approx(
        30.5 * 20.3, rel=0.01
    )
    triangle = square[[0, 1, 3]]
    assert float(convex_coverage(triangle[::-1], 0, 0, 50, 50).sum()) == pytest.approx(
        0.5 * 30.5 * 20.3, rel=0.02
    )


def test_pinhole_square_on_projects_as_x_over_depth():
    camera = Pinhole.aimed([0.0, 0.0, 0.0], 2.0, yaw_deg=0.0, pitch_deg=0.0, roll_deg=0.0,
                           hfov_deg=90.0, width=640, height=480)  # fmt: skip
    assert camera.focal_px == pytest.approx(320.0)
    xy = camera.project(np.array([[0.5, 0.25, 0.0], [0.0, 0.0, 2.0]]))
    assert xy[0] == pytest.approx([319.5 + 320 * 0.5 / 2, 239.5 - 320 * 0.25 / 2])
    assert xy[1] == pytest.approx([319.5, 239.5])
    turned = Pinhole.aimed([0.0, 0.0, 0.0], 2.0, yaw_deg=30.0, pitch_deg=20.0, roll_deg=5.0,
                           hfov_deg=60.0, width=640, height=480)  # fmt: skip
    assert turned.project(np.zeros(3)) == pytest.approx([319.5, 239.5])  # aimed at it
    assert np.linalg.norm(turned.position) == pytest.approx(2.0)
    assert turned.position[0] > 0 and turned.position[1] > 0  # to the right and above
