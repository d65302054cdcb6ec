"""Reading mesh files (STL, OBJ, DAE, ...) into triangles, for collision geometry and pictures.

One reader so that the collision checker and the renderer see the same triangles and refuse a
broken file with the same message; each caller names the error type its users expect.
"""

from __future__ import annotations

import io
import re
import struct
from pathlib import Path

import numpy as np
import numpy.typing as npt

from robotspec.errors import RobotSpecError
from robotspec.files.limits import env_name, limits
from robotspec.files.reading import read_bounded

__all__ = ["declared_triangles", "read_mesh_bytes", "read_triangles", "read_vertices"]

_PLY_FACES = re.compile(rb"^element\s+face\s+(\d+)\s*$", re.MULTILINE)


def declared_triangles(data: bytes, suffix: str) -> int | None:
    """How many triangles (at least) a mesh file holds, told before it is parsed; None: unknown.

    Why before: parsing costs about 500 bytes of memory per triangle whatever the file's size
    (a 256 MB binary STL holds 5.3 million triangles), so a file over the triangle cap must be
    refused from what it declares. A binary STL states its count in its header (bytes 80-84,
    exact when the file's size agrees); a PLY in its ``element face`` line; an ASCII STL and an
    OBJ are counted by their ``endfacet`` and ``f`` lines (an OBJ polygon makes at least one
    triangle). Other formats are counted once parsed.
    """
    if suffix == "stl":
        if len(data) >= 84:
            (count,) = struct.unpack_from("<I", data, 80)
            if len(data) == 84 + 50 * count:
                return int(count)
        return data.count(b"endfacet")
    if suffix == "obj":
        return data.count(b"\nf ") + data.count(b"\nf\t") + int(data[:2] in (b"f ", b"f\t"))
    if suffix == "ply":
        head, _, _ = data[:65536].partition(b"end_header")
        found = _PLY_FACES.search(head)
        return int(found.group(1)) if found else None
    return None


def _check_triangles(
    count: int, path: str, error_type: type[RobotSpecError], *, declared: bool
) -> None:
    cap = limits().max_mesh_triangles
    if count > cap:
        says = "declares" if declared else "has"
        raise error_type(
            f"mesh {says} {count:,} triangles, more than {cap:,} (the cap on one mesh; "
            f"set {env_name('max_mesh_triangles')} to raise it)",
            file=path,
            kind="size",
        )


def read_mesh_bytes(path: str | Path) -> bytes:
    """A mesh file's bytes, bounded by ``max_mesh_bytes`` (to copy it, as ``export bundle``)."""
    return read_bounded(
        path, cap=limits().max_mesh_bytes, cap_name="max_mesh_bytes", what="a mesh file"
    )


def read_triangles(
    path: str, error_type: type[RobotSpecError] = RobotSpecError
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]:
    """Vertices and faces as the file stores them (unscaled); a bad file is ``error_type``.

    Two caps bound the work: ``max_mesh_bytes`` on the file and ``max_mesh_triangles`` on its
    triangles, checked on what the file declares before it is parsed and on what was parsed.
    """
    import trimesh

    suffix = path.rsplit(".", 1)[-1].lower() if "." in path else ""
    try:
        data = read_bounded(
            path,
            cap=limits().max_mesh_bytes,
            cap_name="max_mesh_bytes",
            what="a mesh file",
            error_type=error_type,
        )
    except RobotSpecError as exc:
        if exc.detail.kind == "file" and exc.message.startswith("file not found"):
            raise error_type("mesh file not found", file=path, kind="mesh") from None
        raise
    declared = declared_triangles(data, suffix)
    if declared is not None:
        _check_triangles(declared, path, error_type, declared=True)
    try:
        mesh = trimesh.load(io.BytesIO(data), file_type=suffix, force="mesh", process=False)
    except Exception as exc:  # noqa: BLE001 - trimesh's readers raise anything on a corrupt file
        raise error_type(
            f"cannot read mesh: {type(exc).__name__}: {exc}", file=path, kind="mesh"
        ) from None
    vertices = np.asarray(getattr(mesh, "vertices", np.zeros((0, 3))), dtype=np.float64)
    faces = np.asarray(getattr(mesh, "faces", np.zeros((0, 3))), dtype=np.int64)
    if faces.ndim != 2 or len(faces) == 0 or faces.shape[1] != 3:
        raise error_type("mesh has no triangles", file=path, kind="mesh")
    # Checked again once parsed: a format that declares nothing (COLLADA), a polygon that made
    # several triangles, a header that lied. Before anything larger (trees, hulls) is built.
    _check_triangles(len(faces), path, error_type, declared=False)
    if not np.all(np.isfinite(vertices)):
        raise error_type("mesh has non-finite vertices", file=path, kind="mesh")
    return vertices, faces


_STL_VERTEX = re.compile(rb"vertex\s+(\S+)\s+(\S+)\s+(\S+)")


def read_vertices(path: str) -> npt.NDArray[np.float64]:
    """A mesh file's vertices (unscaled); an STL read here, other formats by ``read_triangles``.

    Why a reader of its own for STL: a caller that needs only the vertices (where a drafted
    finger or arm ends) should not pay trimesh's import, about 0.7 s of CPU for ``init``; STL,
    the usual collision format, is read with numpy under the same caps (file size, triangles)
    and refusals (non-finite vertices).
    """
    if not path.lower().endswith(".stl"):
        return read_triangles(path)[0]
    data = read_mesh_bytes(path)
    cap = limits().max_mesh_triangles
    if len(data) >= 84:
        (count,) = struct.unpack_from("<I", data, 80)
        if len(data) == 84 + 50 * count:  # binary: 12 floats and 2 bytes a triangle
            if count > cap:
                raise RobotSpecError("mesh has too many triangles", file=path, kind="mesh")
            rows = np.frombuffer(data, dtype=np.uint8, offset=84).reshape(count, 50)
            floats = rows[:, :48].copy().view("<f4").reshape(count, 12)
            vertices = floats[:, 3:].reshape(-1, 3).astype(np.float64)
            return _finite(vertices, path)
    found = _STL_VERTEX.findall(data)
    if len(found) > 3 * cap:
        raise RobotSpecError("mesh has too many triangles", file=path, kind="mesh")
    try:
        vertices = np.array(found, dtype=np.float64).reshape(-1, 3)
    except ValueError:
        raise RobotSpecError("cannot read mesh: a vertex is no number", file=path) from None
    return _finite(vertices, path)


def _finite(vertices: npt.NDArray[np.float64], path: str) -> npt.NDArray[np.float64]:
    if not len(vertices) or not np.all(np.isfinite(vertices)):
        raise RobotSpecError("mesh has no finite vertices", file=path, kind="mesh")
    return vertices
