"""The offscreen picture: a scene at a configuration, rasterized, overlaid, with a legend.

Why supersampling: the rasterizer samples pixel centres, so edges would be jagged; rendering at
twice the size and averaging 2x2 blocks smooths them (and the overlay lines drawn at that size)
for four times the fragments, still well under a second for a PR2.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from robotspec.arrays import F64
from robotspec.extras import PILLOW, require_present
from robotspec.render.raster import ViewCamera, flat_shade, rasterize
from robotspec.render.scene import LegendEntry, RobotScene, Segment

__all__ = ["BACKGROUND", "Picture", "RenderOptions", "render_scene"]

U8 = NDArray[np.uint8]

BACKGROUND = (255, 255, 255)
_OUTLINE = 0.6


@dataclass(frozen=True)
class RenderOptions:
    """How to draw: image size, named view, supersampling, and which overlays."""

    width: int = 800
    height: int = 600
    view: str = "front"
    supersample: int = 2
    overlays: bool = True
    legend: bool = True
    title: str | None = None


@dataclass(frozen=True)
class Picture:
    """A rendered image (H, W, 3) and the camera that maps world points to its pixels."""

    image: U8 = field(repr=False, compare=False)
    camera: ViewCamera
    legend: tuple[LegendEntry, ...]
    options: RenderOptions

    def save(self, path: Path, *, force: bool = True, inputs: Iterable[Path] = ()) -> None:
        """Write the image as PNG; the view and scale go into its text chunks.

        Through :func:`robotspec.files.writing.write_file`: never through a link, never over
        one of ``inputs`` (the robot's own files), whole or not at all; ``force=False`` keeps an
        existing file.
        """
        from robotspec.files.writing import write_file

        write_file(path, self.png(), force=force, inputs=inputs)

    def png(self) -> bytes:
        """The image as PNG bytes, the view and scale in its text chunks."""
        import io

        from PIL import Image, PngImagePlugin

        info = PngImagePlugin.PngInfo()
        info.add_text("Software", "robotspec render")
        info.add_text("robotspec:view", self.options.view)
        info.add_text("robotspec:scale", f"{self.camera.scale:.6g}")
        info.add_text(
            "robotspec:legend", "; ".join(f"{e.name}=#{_hex(e.colour)}" for e in self.legend)
        )
        buffer = io.BytesIO()
        Image.fromarray(self.image, "RGB").save(buffer, format="PNG", pnginfo=info)
        return buffer.getvalue()


def _hex(c: tuple[int, int, int]) -> str:
    return "".join(f"{v:02x}" for v in c)


def render_scene(scene: RobotScene, q: F64, options: RenderOptions | None = None) -> Picture:
    """Draw ``scene`` at configuration ``q`` (needs Pillow, the ``view`` extra)."""
    require_present(PILLOW, "render")
    opts = options or RenderOptions()
    poses = scene.poses(q)
    verts, faces, colours, bodies = _world_triangles(scene, poses)
    segments = scene.overlays(q, poses) if opts.overlays else ()
    pts = [verts] + [np.array([s.start, s.end]) for s in segments]
    legend_w = _legend_width(scene.legend, opts) if opts.legend else 0
    robot = scene.robot
    facing = poses[robot.root.index][:3, :3] @ np.asarray(robot.forward_axis)
    camera = ViewCamera.fit(
        opts.view,
        np.concatenate(pts),
        opts.width,
        opts.height,
        left_reserve=legend_w,
        facing=(float(facing[0]), float(facing[1]), float(facing[2])),
    )
    s = max(1, int(opts.supersample))
    big = camera.scaled(s)
    tri = verts[faces]
    screen = big.project(tri.reshape(-1, 3)).reshape(-1, 3, 3)
    ids, _ = rasterize(screen, big.width, big.height)
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    shade = flat_shade(normals, camera.axes)
    rgb = colours * shade[:, None]
    img = np.empty((big.height, big.width, 3))
    img[:] = BACKGROUND
    hit = ids >= 0
    img[hit] = rgb[ids[hit]]
    body_ids = np.full(ids.shape, -1, dtype=np.int64)
    body_ids[hit] = bodies[ids[hit]]  # (a robot whose meshes are all missing draws nothing)
    _outline(img, body_ids)
    big_img = np.clip(img, 0, 255).astype(np.uint8)
    image = _finish(big_img, big, segments, s, scene.legend, opts)
    return Picture(image=image, camera=camera, legend=scene.legend, options=opts)


def _world_triangles(scene: RobotScene, poses: F64) -> tuple[F64, NDArray[np.int64], F64, Any]:
    verts: list[F64] = []
    faces: list[NDArray[np.int64]] = []
    colours: list[F64] = []
    bodies: list[NDArray[np.int64]] = []
    n = 0
    for part in scene.parts:
        t = part.triangles.transformed(poses[part.body_index])
        verts.append(t.vertices)
        faces.append(t.faces + n)
        colours.append(np.broadcast_to(np.asarray(part.colour, dtype=np.float64), (t.count, 3)))
        bodies.append(np.full(t.count, part.body_index, dtype=np.int64))
        n += len(t.vertices)
    if not verts:
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64), np.zeros((0, 3)), np.zeros(0, np.int64)
    return (
        np.concatenate(verts),
        np.concatenate(faces),
        np.concatenate(colours),
        np.concatenate(bodies),
    )


def _outline(img: F64, body: NDArray[np.int64]) -> None:
    """Darken pixels where the body changes (part edges and the silhouette), in place."""
    edge = np.zeros(body.shape, dtype=bool)
    edge[:, 1:] |= body[:, 1:] != body[:, :-1]
    edge[1:, :] |= body[1:, :] != body[:-1, :]
    edge &= body >= 0
    img[edge] *= _OUTLINE


def _finish(
    big_img: U8,
    big: ViewCamera,
    segments: tuple[Segment, ...],
    s: int,
    legend: tuple[LegendEntry, ...],
    opts: RenderOptions,
) -> U8:
    from PIL import Image, ImageDraw

    im = Image.fromarray(big_img, "RGB")
    if segments:
        draw = ImageDraw.Draw(im)
        a = big.project(np.array([seg.start for seg in segments]))
        b = big.project(np.array([seg.end for seg in segments]))
        for seg, p, r in zip(segments, a, b, strict=True):
            draw.line(
                [(float(p[0]), float(p[1])), (float(r[0]), float(r[1]))],
                fill=seg.colour,
                width=max(1, round(s * (1.2 if seg.width == 1 else 2.4))),
            )
    if s > 1:
        im = im.reduce(s)
    if opts.legend:
        _draw_legend(im, legend, opts)
    return np.asarray(im, dtype=np.uint8).copy()


def _font(size: int) -> Any:
    from PIL import ImageFont

    try:
        return ImageFont.load_default(size=size)
    except (OSError, ValueError, TypeError):  # pragma: no cover - Pillow without FreeType
        return ImageFont.load_default()


def _font_size(opts: RenderOptions) -> int:
    return max(10, min(22, round(min(opts.width, opts.height) / 42)))


def _legend_width(legend: tuple[LegendEntry, ...], opts: RenderOptions) -> int:
    from PIL import Image, ImageDraw

    font = _font(_font_size(opts))
    draw = ImageDraw.Draw(Image.new("RGB", (4, 4)))
    texts = [e.name for e in legend] + ([opts.title] if opts.title else [])
    widest = max((draw.textlength(t, font=font) for t in texts), default=0.0)
    size = _font_size(opts)
    return int(widest + 2.8 * size + 12)


def _draw_legend(im: Any, legend: tuple[LegendEntry, ...], opts: RenderOptions) -> None:
    from PIL import ImageDraw

    size = _font_size(opts)
    font = _font(size)
    draw = ImageDraw.Draw(im)
    x, y = 10, 10
    line = round(size * 1.45)
    if opts.title:
        draw.text((x, y), opts.title, fill=(0, 0, 0), font=font)
        y += line + 4
    for e in legend:
        box = (x, y + 2, x + size, y + size + 2)
        if e.kind == "overlay":
            mid = y + 2 + size // 2
            draw.line([(x, mid), (x + size, mid)], fill=e.colour, width=max(2, size // 5))
        else:
            draw.rectangle(box, fill=e.colour, outline=(60, 60, 60))
        indent = round(size * 0.8) if e.kind == "manipulator" else 0
        draw.text((x + size + 8 + indent, y), e.name, fill=(20, 20, 20), font=font)
        y += line
