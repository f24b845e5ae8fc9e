"""Pixels of a `Scene`: a pinhole camera, the static background, and the moving rods.

Pixel coordinates: x to the right, y down, in the stored (sensor) frame; the centre
of pixel [row, col] is at (x, y) = (col, row). Every shape is drawn with an antialiased
edge: a pixel's coverage is clip(0.5 + signed distance inside, 0, 1).

What never moves (wall, clutter, table, platform, bodies) is drawn once, as float32
RGB in [0, 1]. What moves (rod and bob) is drawn per frame inside each metronome's
swept box only, by `rod_coverage`, a compiled kernel over float arrays: for each row
of the box and each sub-exposure sample it gets the projected tip and bob centre, so
that motion blur (several samples in the exposure) and the rolling shutter (each row
at its own time) cost nothing more than a longer list of positions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np
from scipy import ndimage

from ._scene import Metronome, Scene

#: Widest swing a swept box is made for, rad, when the trajectory does not say more.
MIN_SWEEP = 0.35


@dataclass(frozen=True)
class Pinhole:
    """A pinhole camera: position and axes in world coordinates, focal length in pixels.

    project maps world points (..., 3) to pixels (..., 2); depth gives the distance
    along the viewing axis (..., ).
    """

    position: np.ndarray
    right: np.ndarray
    up: np.ndarray
    forward: np.ndarray
    focal_px: float
    width: int
    height: int

    @classmethod
    def aimed(cls, target, distance, *, yaw_deg, pitch_deg, roll_deg, hfov_deg, width, height):
        """A camera ``distance`` m from ``target``, turned by yaw (to the right of the
        metronomes' axis), pitch (looking down) and roll (about the view axis)."""
        yaw, pitch, roll = np.radians([yaw_deg, pitch_deg, roll_deg])
        forward = np.array(
            [-math.sin(yaw) * math.cos(pitch), -math.sin(pitch), math.cos(yaw) * math.cos(pitch)]
        )
        right = np.cross([0.0, 1.0, 0.0], forward)
        right /= np.linalg.norm(right)
        up = np.cross(forward, right)
        c, s = math.cos(roll), math.sin(roll)
        right, up = c * right + s * up, -s * right + c * up
        focal = 0.5 * width / math.tan(0.5 * math.radians(hfov_deg))
        position = np.asarray(target, float) - distance * forward
        return cls(position, right, up, forward, float(focal), int(width), int(height))

    def camera_coordinates(self, points) -> np.ndarray:
        d = np.asarray(points, float) - self.position
        return np.stack([d @ self.right, d @ self.up, d @ self.forward], axis=-1)

    def depth(self, points) -> np.ndarray:
        return (np.asarray(points, float) - self.position) @ self.forward

    def project(self, points) -> np.ndarray:
        c = self.camera_coordinates(points)
        z = c[..., 2]
        x = 0.5 * (self.width - 1) + self.focal_px * c[..., 0] / z
        y = 0.5 * (self.height - 1) - self.focal_px * c[..., 1] / z
        return np.stack([x, y], axis=-1)

    def project_clipped(self, polygon, near: float = 0.02) -> np.ndarray:
        """A planar world polygon (K, 3) cut at the near plane, then projected (M, 2)."""
        c = self.camera_coordinates(polygon)
        out = []
        for i in range(len(c)):
            a, b = c[i], c[(i + 1) % len(c)]
            if a[2] >= near:
                out.append(a)
            if (a[2] >= near) != (b[2] >= near):
                s = (near - a[2]) / (b[2] - a[2])
                out.append(a + s * (b - a))
        if not out:
            return np.empty((0, 2))
        c = np.array(out)
        x = 0.5 * (self.width - 1) + self.focal_px * c[:, 0] / c[:, 2]
        y = 0.5 * (self.height - 1) - self.focal_px * c[:, 1] / c[:, 2]
        return np.column_stack([x, y])


def rod_points(m: Metronome, theta) -> tuple[np.ndarray, np.ndarray]:
    """World positions (..., 3) of the rod's tip and the bob's centre at angles θ."""
    theta = np.asarray(theta, float)
    direction = np.stack([np.sin(theta), np.cos(theta), np.zeros_like(theta)], axis=-1)
    return m.pivot + m.rod_length * direction, m.pivot + m.bob_position * direction


def body_faces(m: Metronome, camera: Pinhole) -> list[tuple[np.ndarray, float]]:
    """The body's faces that the camera sees, far ones first: (world polygon, shade)."""
    hb, wb, wt, d = m.body_height, 0.5 * m.base_width, 0.5 * m.top_width, m.body_depth
    z0, z1 = m.z, m.z + d
    front = np.array([[-wb, 0, z0], [wb, 0, z0], [wt, hb, z0], [-wt, hb, z0]])
    back = front.copy()
    back[:, 2] = z1
    back[:, 0] *= 0.9  # a truncated pyramid, narrowing to the back as well
    front[:, 0] += m.x
    back[:, 0] += m.x
    faces = [
        (np.array([front[1], back[1], back[2], front[2]]), 0.75),  # right side
        (np.array([front[0], back[0], back[3], front[3]]), 0.75),  # left side
        (np.array([front[3], front[2], back[2], back[3]]), 0.9),  # top
        (front, 1.0),
    ]
    inner = np.vstack([front, back]).mean(axis=0)
    seen = []
    for poly, shade in faces:
        centre = poly.mean(axis=0)
        normal = np.cross(poly[1] - poly[0], poly[2] - poly[0])
        if np.dot(normal, centre - inner) < 0:
            normal = -normal  # outward
        if np.dot(normal, camera.position - centre) > 0:
            seen.append((poly, shade))
    return seen


def convex_coverage(poly: np.ndarray, x0: int, y0: int, h: int, w: int) -> np.ndarray:
    """(h, w) antialiased coverage of a convex image polygon (K, 2) over the pixels
    [y0, y0+h) × [x0, x0+w)."""
    if len(poly) < 3:
        return np.zeros((h, w), np.float32)
    area = np.sum(poly[:, 0] * np.roll(poly[:, 1], -1) - np.roll(poly[:, 0], -1) * poly[:, 1])
    if area < 0:
        poly = poly[::-1]
    ys = np.arange(y0, y0 + h, dtype=np.float32)[:, None]
    xs = np.arange(x0, x0 + w, dtype=np.float32)[None, :]
    inside = np.full((h, w), np.inf, np.float32)
    for i in range(len(poly)):
        (ax, ay), (bx, by) = poly[i], poly[(i + 1) % len(poly)]
        length = math.hypot(bx - ax, by - ay)
        if length < 1e-9:
            continue
        # Image y points down, so a polygon of positive area in (x, y) is clockwise on
        # screen and its inside lies to the right of each edge.
        d = ((xs - ax) * (by - ay) - (ys - ay) * (bx - ax)) / length
        np.minimum(inside, -d, out=inside)
    return np.clip(inside + 0.5, 0.0, 1.0)


def paint(image: np.ndarray, poly: np.ndarray, colour) -> None:
    """Draw a convex image polygon (K, 2) of ``colour`` onto ``image`` (H, W, 3) in place."""
    if len(poly) < 3:
        return
    height, width = image.shape[:2]
    x0 = max(0, int(math.floor(poly[:, 0].min())) - 1)
    x1 = min(width, int(math.ceil(poly[:, 0].max())) + 2)
    y0 = max(0, int(math.floor(poly[:, 1].min())) - 1)
    y1 = min(height, int(math.ceil(poly[:, 1].max())) + 2)
    if x1 <= x0 or y1 <= y0:
        return
    cov = convex_coverage(poly, x0, y0, y1 - y0, x1 - x0)[..., None]
    region = image[y0:y1, x0:x1]
    region *= 1.0 - cov
    region += cov * np.asarray(colour, np.float32)


def ellipse(cx, cy, rx, ry, angle=0.0, k: int = 48) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, k, endpoint=False)
    x, y = rx * np.cos(t), ry * np.sin(t)
    c, s = math.cos(angle), math.sin(angle)
    return np.column_stack([cx + c * x - s * y, cy + s * x + c * y])


def background(scene: Scene, camera: Pinhole) -> np.ndarray:
    """(H, W, 3) float32 RGB of everything that does not move."""
    h, w = camera.height, camera.width
    rng = np.random.default_rng(scene.seed)
    image = np.empty((h, w, 3), np.float32)
    image[:] = np.asarray(scene.wall_colour, np.float32)
    n_wall = int(round(0.8 * scene.clutter))
    for _ in range(n_wall):
        _clutter_shape(image, rng)
    ms = scene.metronomes
    back = max(m.z + m.body_depth for m in ms) + rng.uniform(0.15, 0.5)
    xs = [m.x for m in ms]
    table = np.array([[-6.0, 0, back], [6.0, 0, back], [6.0, 0, back - 8], [-6.0, 0, back - 8]])
    table[:, 0] += 0.5 * (min(xs) + max(xs))
    paint(image, camera.project_clipped(table), scene.table_colour)
    if scene.disk:
        radius = 0.5 * (max(xs) - min(xs)) + max(m.base_width for m in ms) + 0.05
        zc = 0.5 * (min(m.z for m in ms) + max(m.z + m.body_depth for m in ms))
        t = np.linspace(0, 2 * np.pi, 96, endpoint=False)
        rim = np.column_stack(
            [0.5 * (min(xs) + max(xs)) + radius * np.cos(t), np.full_like(t, 0.004),
             zc + radius * np.sin(t)]
        )  # fmt: skip
        shade = np.clip(np.asarray(scene.table_colour) * rng.uniform(0.6, 1.4, 3), 0, 1)
        paint(image, camera.project_clipped(rim), shade)
    for _ in range(scene.clutter - n_wall):
        _clutter_shape(image, rng, scale=0.5)
    _texture(image, rng, scene.texture)
    for m in sorted(ms, key=lambda m: -camera.depth(m.pivot)):
        for poly, shade in body_faces(m, camera):
            paint(image, camera.project_clipped(poly), np.asarray(m.body_colour) * shade)
        centre = camera.project(m.pivot)
        r = max(1.0, 1.5 * camera.focal_px * m.rod_width / camera.depth(m.pivot))
        paint(image, ellipse(centre[0], centre[1], r, r, k=16), np.asarray(m.body_colour) * 0.5)
    _vignette(image, rng)
    return np.clip(image, 0.0, 1.0, out=image)


def _clutter_shape(image: np.ndarray, rng, scale: float = 1.0) -> None:
    h, w = image.shape[:2]
    colour = rng.uniform(0.0, 1.0, 3) ** rng.uniform(0.6, 1.6)
    cx, cy = rng.uniform(-0.1, 1.1) * w, rng.uniform(-0.1, 1.1) * h
    size = scale * rng.uniform(0.02, 0.3) * w
    kind = rng.integers(4)
    if kind == 0:  # a poster or a book: a tilted rectangle
        a, b, angle = size, size * rng.uniform(0.3, 1.5), rng.normal(0, 0.15)
        corners = np.array([[-a, -b], [a, -b], [a, b], [-a, b]]) * 0.5
        c, s = math.cos(angle), math.sin(angle)
        poly = corners @ np.array([[c, s], [-s, c]]) + [cx, cy]
    elif kind == 1:  # a round thing
        poly = ellipse(cx, cy, 0.5 * size, 0.5 * size * rng.uniform(0.4, 1.0), rng.uniform(0, 3))
    elif kind == 2:  # a cable or a shelf edge: long and thin
        angle = rng.uniform(0, np.pi)
        length, width = size * rng.uniform(2, 5), rng.uniform(1.5, 0.01 * w + 3)
        c, s = math.cos(angle), math.sin(angle)
        corners = np.array([[-length, -width], [length, -width], [length, width], [-length, width]])
        poly = 0.5 * corners @ np.array([[c, s], [-s, c]]) + [cx, cy]
    else:  # an irregular convex blob: points on an ellipse at random angles
        t = np.sort(rng.uniform(0, 2 * np.pi, rng.integers(3, 8)))
        poly = np.column_stack([cx + 0.5 * size * np.cos(t), cy + 0.3 * size * np.sin(t)])
    paint(image, poly, colour)


def _texture(image: np.ndarray, rng, amount: float) -> None:
    if amount <= 0:
        return
    h, w = image.shape[:2]
    coarse = rng.normal(0.0, 1.0, (max(2, h // 48), max(2, w // 48))).astype(np.float32)
    blotch = ndimage.zoom(coarse, (h / coarse.shape[0], w / coarse.shape[1]), order=1)[:h, :w]
    fine = rng.normal(0.0, 0.35, (h, w)).astype(np.float32)
    image *= (1.0 + amount * (blotch + fine))[..., None]


def _vignette(image: np.ndarray, rng) -> None:
    h, w = image.shape[:2]
    y = (np.arange(h, dtype=np.float32) - 0.5 * h) / (0.5 * h)
    x = (np.arange(w, dtype=np.float32) - 0.5 * w) / (0.5 * w)
    strength = np.float32(rng.uniform(0.05, 0.25))
    image *= (1.0 - strength * 0.5 * (x[None, :] ** 2 + y[:, None] ** 2))[..., None]


@nb.njit(cache=False, nogil=True)
def rod_coverage(rod, bob, span, x0, y0, pivot_x, pivot_y, tips, bobs, rod_hw, bob_hl, bob_hw):
    """Accumulate the mean coverage of the rod and of the bob over one frame's samples.

    rod, bob : (h, w) float32, zeroed, the box [y0, y0+h) × [x0, x0+w); filled in place.
    span : (h, 2) int64, set to each row's first and past-the-last column touched
        (0, 0 where none).
    tips, bobs : (h, K, 2) projected tip and bob centre for each box row and each of K
        samples in the exposure (a row's samples at that row's times).
    rod_hw : half width of the rod; bob_hl, bob_hw : half length along and half width
        across the rod of the bob, px. The bob hides the rod.
    """
    h, w = rod.shape
    k_samples = tips.shape[1]
    weight = 1.0 / k_samples
    reach = max(rod_hw, bob_hl, bob_hw) + 1.5
    for r in range(h):
        y = y0 + r
        lo = w
        hi = 0
        for k in range(k_samples):
            tx = tips[r, k, 0]
            ty = tips[r, k, 1]
            if y < min(pivot_y, ty) - reach or y > max(pivot_y, ty) + reach:
                continue
            dx = tx - pivot_x
            dy = ty - pivot_y
            length = math.sqrt(dx * dx + dy * dy)
            ux = dx / length
            uy = dy / length
            bx = bobs[r, k, 0]
            by = bobs[r, k, 1]
            # Only the columns of this row near the segment: a band of half width
            # `reach` about a line of slope dx/dy, clamped to the segment's span.
            c0 = int(math.floor(min(pivot_x, tx) - reach - x0))
            c1 = int(math.ceil(max(pivot_x, tx) + reach - x0)) + 1
            if abs(dy) > 1e-3:
                s = min(max((y - pivot_y) / dy, 0.0), 1.0)
                xc = pivot_x + s * dx - x0
                spread = reach * (length + abs(dx)) / abs(dy) + 1.0
                c0 = max(c0, int(math.floor(xc - spread)))
                c1 = min(c1, int(math.ceil(xc + spread)) + 1)
            c0 = max(c0, 0)
            c1 = min(c1, w)
            lo = min(lo, c0)
            hi = max(hi, c1)
            for c in range(c0, c1):
                px = x0 + c - pivot_x
                py = y - pivot_y
                along = px * ux + py * uy
                across = abs(py * ux - px * uy)
                cov_rod = min(min(along, length - along) + 0.5, rod_hw + 0.5 - across)
                qx = x0 + c - bx
                qy = y - by
                b_along = abs(qx * ux + qy * uy)
                b_across = abs(qy * ux - qx * uy)
                cov_bob = min(bob_hl - b_along, bob_hw - b_across) + 0.5
                cov_rod = min(max(cov_rod, 0.0), 1.0)
                cov_bob = min(max(cov_bob, 0.0), 1.0)
                rod[r, c] += weight * cov_rod * (1.0 - cov_bob)
                bob[r, c] += weight * cov_bob
        if hi > lo:
            span[r, 0] = lo
            span[r, 1] = hi
        else:
            span[r, 0] = 0
            span[r, 1] = 0


@nb.njit(cache=False, nogil=True)
def composite(y_plane, u_plane, v_plane, x0, y0, rod, bob, vis, span, rod_yuv, bob_yuv):
    """Lay a rod and its bob of coverages ``rod``, ``bob`` (h, w) seen through ``vis``
    (h, w) over the planes, in place, on the columns ``span`` (h, 2) of each box row.

    x0, y0 : the box's corner, even.   rod_yuv, bob_yuv : (3,) colours. Chroma, at half
    resolution, takes the mean of each 2 × 2 block's coverage.
    """
    h = rod.shape[0]
    for r in range(h):
        for c in range(span[r, 0], span[r, 1]):
            a = rod[r, c] * vis[r, c]
            b = bob[r, c] * vis[r, c]
            old = y_plane[y0 + r, x0 + c]
            y_plane[y0 + r, x0 + c] = old + a * (rod_yuv[0] - old) + b * (bob_yuv[0] - old)
    for rr in range(h // 2):
        r = 2 * rr
        lo, hi = _pair_span(span, r)
        for cc in range(lo // 2, (hi + 1) // 2):
            c = 2 * cc
            a = 0.0
            b = 0.0
            for dr in range(2):
                for dc in range(2):
                    a += rod[r + dr, c + dc] * vis[r + dr, c + dc]
                    b += bob[r + dr, c + dc] * vis[r + dr, c + dc]
            a *= 0.25
            b *= 0.25
            yy = y0 // 2 + rr
            xx = x0 // 2 + cc
            old = u_plane[yy, xx]
            u_plane[yy, xx] = old + a * (rod_yuv[1] - old) + b * (bob_yuv[1] - old)
            old = v_plane[yy, xx]
            v_plane[yy, xx] = old + a * (rod_yuv[2] - old) + b * (bob_yuv[2] - old)


@nb.njit(cache=False, nogil=True)
def _pair_span(span, r):
    """Columns [lo, hi) touched in box rows r and r + 1 (lo ≥ hi: none)."""
    lo = 1 << 30
    hi = 0
    for q in range(r, r + 2):
        if span[q, 1] > span[q, 0]:
            lo = min(lo, span[q, 0])
            hi = max(hi, span[q, 1])
    return lo, hi


@nb.njit(cache=False, nogil=True)
def restore(work, static, x0, y0, span, scale):
    """Copy ``static`` back over ``work`` on the columns ``span`` (h, 2) of a box's rows
    (``scale`` = 2 for a chroma plane: half the rows and columns)."""
    h = span.shape[0]
    for r in range(0, h, scale):
        if scale == 2:
            lo, hi = _pair_span(span, r)
        else:
            lo, hi = span[r, 0], span[r, 1]
        for c in range(lo // scale, (hi + scale - 1) // scale):
            work[(y0 + r) // scale, x0 // scale + c] = static[(y0 + r) // scale, x0 // scale + c]


@nb.njit(cache=False, nogil=True)
def finish_plane(out, plane, offset, gain, noise, dy, dx):
    """Write one plane of a frame: light gain per row, noise, rounding to 8 bits.

    out : (h, w) uint8, written.   plane : (h, w) float32 levels.
    offset : the level that the light does not scale (16 for luma, 128 for chroma).
    gain : (h,) the light of each row.   noise : (≥ h + dy, ≥ w + dx) float32, or (0, 0)
    for none; the frame's noise is its window at (dy, dx).
    """
    h, w = plane.shape
    noisy = noise.shape[0] > 0
    for r in range(h):
        g = gain[r]
        for c in range(w):
            v = offset + (plane[r, c] - offset) * g + 0.5
            if noisy:
                v += noise[r + dy, c + dx]
            if v <= 0.0:
                out[r, c] = 0
            elif v >= 255.0:
                out[r, c] = 255
            else:
                out[r, c] = np.uint8(v)
