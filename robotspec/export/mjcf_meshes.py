"""The mesh files of an MJCF export, in a format MuJoCo reads.

Why convert at all: MuJoCo reads binary STL, OBJ and its own MSH, not COLLADA (``.dae``, the
visual meshes of most ROS robots) nor ASCII STL; its URDF reader drops every such mesh. Each
mesh the compiled robot resolved is read with robotspec's own reader (the triangles the
collision checker uses, under the same size caps) and written as a binary STL; a file that is
already a binary STL is copied as it is. One file per source, named after it, numbered when two
sources share a name. A mesh robotspec did not resolve (outside the allowed folders, missing)
is not exported: the caller leaves its geom out and says so.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import numpy.typing as npt

from robotspec.errors import RobotSpecError
from robotspec.files.meshes import read_mesh_bytes, read_triangles

__all__ = ["MeshAssets", "binary_stl"]


def binary_stl(vertices: npt.NDArray[np.float64], faces: npt.NDArray[np.int64]) -> bytes:
    """A binary STL of the triangles (float32, as the format and MuJoCo store them)."""
    tri = vertices[faces].astype(np.float32)  # (n, 3, 3)
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    lengths = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, lengths, out=np.zeros_like(normals), where=lengths > 0)
    record = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rows = np.zeros(len(faces), dtype=record)
    rows["n"], rows["v"] = normals, tri
    header = b"robotspec export mjcf".ljust(80, b"\0")
    return header + struct.pack("<I", len(faces)) + rows.tobytes()


def _is_binary_stl(data: bytes) -> bool:
    if len(data) < 84:
        return False
    (count,) = struct.unpack_from("<I", data, 80)
    return bool(len(data) == 84 + 50 * count and count > 0)


#: MuJoCo's STL reader takes at most this many triangles per file.
MAX_FACES = 200_000


def _stl_pieces(path: str) -> list[bytes]:
    """The mesh at ``path`` as binary STL files of at most ``MAX_FACES`` triangles each.

    A larger mesh (a scanned base, a detailed shell) is cut into consecutive runs of its
    triangles: the pieces draw the same surface, and MuJoCo collides each piece's hull, which
    is closer to the mesh than one hull of the whole.
    """
    if path.lower().endswith(".stl"):
        data = read_mesh_bytes(path)
        if _is_binary_stl(data) and struct.unpack_from("<I", data, 80)[0] <= MAX_FACES:
            return [data]
    vertices, faces = read_triangles(path, RobotSpecError)
    return [
        binary_stl(vertices, faces[start : start + MAX_FACES])
        for start in range(0, len(faces), MAX_FACES)
    ]


@dataclass
class MeshAssets:
    """Mesh sources met while the MJCF is built: asset names, files and their bytes.

    ``folder`` is the mesh folder's name relative to the MJCF file (its ``meshdir``). Each
    source is read once, when first met (a broken file is a ``RobotSpecError`` naming it, before
    anything is written); the bytes are kept until the export is written.
    """

    folder: str
    _files: dict[str, list[str]] = field(default_factory=dict)  # source path -> file names
    _bytes: dict[str, bytes] = field(default_factory=dict)  # file name -> its bytes
    _assets: dict[tuple[str, tuple[float, float, float]], list[str]] = field(default_factory=dict)
    _taken: set[str] = field(default_factory=set)

    def assets(self, path: str, scale: tuple[float, float, float]) -> list[str]:
        """The asset names of ``path`` at ``scale`` (one per piece, see ``_stl_pieces``)."""
        key = (str(Path(path).resolve()), scale)
        if key in self._assets:
            return self._assets[key]
        source = key[0]
        if source not in self._files:
            pieces = _stl_pieces(source)
            names = []
            for i, data in enumerate(pieces):
                stem = Path(source).stem or "mesh"
                stem = stem if len(pieces) == 1 else f"{stem}_part{i + 1}"
                name, n = stem, 1
                while name.lower() in self._taken:
                    n += 1
                    name = f"{stem}_{n}"
                self._taken.add(name.lower())
                names.append(f"{name}.stl")
                self._bytes[f"{name}.stl"] = data
            self._files[source] = names
        suffix = "" if scale == (1.0, 1.0, 1.0) else "@" + "_".join(repr(s) for s in scale)
        found = [f"{file[:-4]}{suffix}" for file in self._files[source]]
        self._assets[key] = found
        return found

    def declarations(self) -> list[tuple[str, str, tuple[float, float, float]]]:
        """``(asset name, file name, scale)`` of every asset, in the order they were met."""
        return [
            (asset, file, scale)
            for (src, scale), names in self._assets.items()
            for asset, file in zip(names, self._files[src], strict=True)
        ]

    def files(self) -> list[tuple[str, Callable[[], bytes]]]:
        """``(path relative to the MJCF, producer of its bytes)`` of every mesh file."""
        return [(f"{self.folder}/{name}", _producer(data)) for name, data in self._bytes.items()]


def _producer(data: bytes) -> Callable[[], bytes]:
    return lambda: data
