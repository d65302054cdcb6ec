"""A z-buffered triangle rasterizer in numpy, and the orthographic camera it draws through.

Why software: the picture must come out on a headless CI box with no display and no GPU, from
pip-installable packages only; a robot has tens of thousands of triangles, which numpy fills in
well under a second. Why orthographic: a technical picture wants the left arm exactly as big as
the right one, and a point's pixel is then an affine function that tests can compute.

The rasterizer works on fragments: every pixel centre in a triangle's bounding box is a
candidate, tested with edge functions (both windings are inside: mesh files disagree on it),
interpolated for depth, and the nearest fragment per pixel wins across chunks of triangles.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from robotspec.arrays import F64, I64
from robotspec.errors import RobotSpecError

__all__ = ["VIEWS", "ViewCamera", "rasterize", "view_axes"]


#: Viewing direction (from the camera into the scene) and the world's up on screen, per view.
#: front: from the robot's front (+x), its left (+y) on the image's right; side: from its right
#: (-y), its front to the image's right; top: from above, its front up; iso: front-right-above.
VIEWS: dict[str, tuple[tuple[float, float, float], tuple[float, float, float]]] = {
    "front": ((-1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
    "side": ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
    "top": ((0.0, 0.0, -1.0), (1.0, 0.0, 0.0)),
    "iso": ((-1.0, 1.0, -0.8), (0.0, 0.0, 1.0)),
}

_FRAGMENT_CHUNK = 3_000_000


def view_axes(view: str, facing: tuple[float, float, float] = (1.0, 0.0, 0.0)) -> F64:
    """Rows right, up and forward (into the screen) of a named view, world frame (3, 3).

    ``facing`` is the direction the robot faces in the world (horizontal): the views are
    turned about the vertical so that "front" looks at the robot's face whichever way it was
    modelled.
    """
    if view not in VIEWS:
        from robotspec.errors import NotFoundError

        raise NotFoundError("view", view, VIEWS)
    fx, fy = facing[0], facing[1]
    n = float(np.hypot(fx, fy)) or 1.0
    c, s = fx / n, fy / n
    turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    fwd_t, up_t = (turn @ np.asarray(v) for v in VIEWS[view])
    fwd = np.asarray(fwd_t) / np.linalg.norm(fwd_t)
    up = np.asarray(up_t) - fwd * float(np.dot(up_t, fwd))
    up /= np.linalg.norm(up)
    right = np.cross(fwd, up)
    return np.stack([right, up, fwd])


@dataclass(frozen=True)
class ViewCamera:
    """An orthographic camera: world point ``center`` at the image centre, ``scale`` px per m.

    Pixel ``(u, v)`` has u to the right and v down, pixel ``i`` covering ``[i, i + 1)``; depth
    grows away from the viewer.
    """

    axes: F64 = field(repr=False, compare=False)
    center: F64 = field(repr=False, compare=False)
    scale: float
    width: int
    height: int

    def project(self, points: object) -> F64:
        """``(u, v, depth)`` rows for world points (N, 3)."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3) - self.center
        c = p @ self.axes.T
        out = np.empty_like(c)
        out[:, 0] = self.width / 2.0 + self.scale * c[:, 0]
        out[:, 1] = self.height / 2.0 - self.scale * c[:, 1]
        out[:, 2] = c[:, 2]
        return out

    def scaled(self, factor: int) -> ViewCamera:
        """The same view on an image ``factor`` times larger each way (for supersampling)."""
        return replace(
            self, scale=self.scale * factor, width=self.width * factor, height=self.height * factor
        )

    @classmethod
    def fit(
        cls,
        view: str,
        points: F64,
        width: int,
        height: int,
        *,
        margin: float = 0.05,
        left_reserve: int = 0,
        facing: tuple[float, float, float] = (1.0, 0.0, 0.0),
    ) -> ViewCamera:
        """The camera of ``view`` that shows every point with ``margin`` around them.

        ``left_reserve`` pixels on the left stay free (for the legend).
        """
        axes = view_axes(view, facing)
        c = np.asarray(points, dtype=np.float64).reshape(-1, 3) @ axes.T
        if len(c) == 0:
            c = np.zeros((1, 3))
        lo, hi = c.min(axis=0), c.max(axis=0)
        span = np.maximum(hi - lo, 1e-6)
        region_w = max(width - left_reserve, width // 3)
        scale = min(
            region_w * (1.0 - 2.0 * margin) / span[0], height * (1.0 - 2.0 * margin) / span[1]
        )
        mid = (lo + hi) / 2.0
        # The content's middle goes to the middle of the free region, right of the reserve.
        mid[0] -= (width - region_w) / 2.0 / scale
        return cls(axes=axes, center=mid @ axes, scale=float(scale), width=width, height=height)


def rasterize(screen: F64, width: int, height: int) -> tuple[I64, F64]:
    """Nearest triangle per pixel (-1 where none) and its depth, for (T, 3, 3) screen triangles.

    Each triangle row holds three ``(u, v, depth)`` vertices; pixel centres are sampled.
    """
    ids = np.full(height * width, -1, dtype=np.int64)
    zbuf = np.full(height * width, np.inf)
    if len(screen) == 0:
        return ids.reshape(height, width), zbuf.reshape(height, width)
    u, v, z = screen[:, :, 0], screen[:, :, 1], screen[:, :, 2]
    # Signed doubled area; degenerate (edge-on) triangles cover no pixel centre.
    area = (u[:, 1] - u[:, 0]) * (v[:, 2] - v[:, 0]) - (u[:, 2] - u[:, 0]) * (v[:, 1] - v[:, 0])
    x0 = np.clip(np.ceil(u.min(axis=1) - 0.5), 0, width).astype(np.int64)
    x1 = np.clip(np.floor(u.max(axis=1) - 0.5), -1, width - 1).astype(np.int64)
    y0 = np.clip(np.ceil(v.min(axis=1) - 0.5), 0, height).astype(np.int64)
    y1 = np.clip(np.floor(v.max(axis=1) - 0.5), -1, height - 1).astype(np.int64)
    bw, bh = x1 - x0 + 1, y1 - y0 + 1
    ok = (np.abs(area) > 1e-12) & (bw > 0) & (bh > 0) & np.all(np.isfinite(screen), axis=(1, 2))
    tri = np.flatnonzero(ok)
    counts = (bw * bh)[tri]
    inv_area = np.divide(1.0, area, out=np.zeros_like(area), where=ok)
    ends = np.cumsum(counts)
    start = 0
    while start < len(tri):
        # Chunks of triangles whose candidate pixels total about _FRAGMENT_CHUNK.
        base = ends[start - 1] if start else 0
        stop = int(np.searchsorted(ends, base + _FRAGMENT_CHUNK, side="right"))
        stop = max(stop, start + 1)
        _chunk(tri[start:stop], counts[start:stop], x0, y0, bw, u, v, z, inv_area, width, ids, zbuf)
        start = stop
    return ids.reshape(height, width), zbuf.reshape(height, width)


def _chunk(
    tri: I64,
    counts: I64,
    x0: I64,
    y0: I64,
    bw: I64,
    u: F64,
    v: F64,
    z: F64,
    inv_area: F64,
    width: int,
    ids: I64,
    zbuf: F64,
) -> None:
    total = int(counts.sum())
    rep = np.repeat(tri, counts)
    first = np.repeat(np.cumsum(counts) - counts, counts)
    off = np.arange(total, dtype=np.int64) - first
    w = bw[rep]
    px = x0[rep] + off % w
    py = y0[rep] + off // w
    cx, cy = px + 0.5, py + 0.5
    ua, ub, uc = u[rep, 0], u[rep, 1], u[rep, 2]
    va, vb, vc = v[rep, 0], v[rep, 1], v[rep, 2]
    ia = inv_area[rep]
    # Barycentric weights from edge functions, normalised by the signed area (any winding).
    l0 = ((ub - cx) * (vc - cy) - (uc - cx) * (vb - cy)) * ia
    l1 = ((uc - cx) * (va - cy) - (ua - cx) * (vc - cy)) * ia
    l2 = 1.0 - l0 - l1
    eps = -1e-9
    inside = (l0 >= eps) & (l1 >= eps) & (l2 >= eps)
    if not np.any(inside):
        return
    depth = (l0 * z[rep, 0] + l1 * z[rep, 1] + l2 * z[rep, 2])[inside]
    pix = (py * width + px)[inside]
    who = rep[inside]
    order = np.lexsort((depth, pix))
    pix, depth, who = pix[order], depth[order], who[order]
    head = np.ones(len(pix), dtype=bool)
    head[1:] = pix[1:] != pix[:-1]
    pix, depth, who = pix[head], depth[head], who[head]
    nearer = depth < zbuf[pix]
    zbuf[pix[nearer]] = depth[nearer]
    ids[pix[nearer]] = who[nearer]


def flat_shade(normals: F64, axes: F64) -> F64:
    """Lambert intensity per face (T,) for light from over the viewer's left shoulder.

    Two-sided (|cos|), since mesh windings are not reliable; an ambient floor keeps faces that
    are edge-on to the light readable.
    """
    light = -axes[2] + 0.6 * axes[1] - 0.35 * axes[0]
    light /= np.linalg.norm(light)
    n = normals / np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-12)
    out: F64 = 0.42 + 0.58 * np.abs(n @ light)
    return out


def parse_size(text: str) -> tuple[int, int]:
    """``WxH`` (e.g. ``800x600``) as two positive pixel counts, at most 8192 each."""
    w_text, sep, h_text = text.lower().partition("x")
    try:
        w, h = int(w_text), int(h_text)
    except ValueError:
        w = h = 0
    if not sep or not (16 <= w <= 8192 and 16 <= h <= 8192):
        raise RobotSpecError(
            f"--size '{text}': expected WIDTHxHEIGHT in pixels, each 16 to 8192 (e.g. 800x600)",
            kind="option",
            name="size",
        )
    return w, h
