"""Reading mesh files (STL, OBJ, DAE, ...) into triangles, for collision geometry and pictures.

One reader so that the collision checker and the renderer see the same triangles and refuse a
broken file with the same message; each caller names the error type its users expect.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from robotspec.errors import RobotSpecError

__all__ = ["read_triangles"]


def read_triangles(
    path: str, error_type: type[RobotSpecError] = RobotSpecError
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]:
    """Vertices and faces as the file stores them (unscaled); a bad file is ``error_type``."""
    import trimesh

    suffix = path.rsplit(".", 1)[-1].lower() if "." in path else ""
    try:
        with open(path, "rb") as f:
            mesh = trimesh.load(f, file_type=suffix, force="mesh", process=False)
    except FileNotFoundError:
        raise error_type("mesh file not found", file=path, kind="mesh") from None
    except OSError as exc:
        raise error_type(f"cannot read mesh: {exc.strerror}", file=path, kind="mesh") from None
    except Exception as exc:  # noqa: BLE001 - trimesh's readers raise anything on a corrupt file
        raise error_type(
            f"cannot read mesh: {type(exc).__name__}: {exc}", file=path, kind="mesh"
        ) from None
    vertices = np.asarray(getattr(mesh, "vertices", np.zeros((0, 3))), dtype=np.float64)
    faces = np.asarray(getattr(mesh, "faces", np.zeros((0, 3))), dtype=np.int64)
    if faces.ndim != 2 or len(faces) == 0 or faces.shape[1] != 3:
        raise error_type("mesh has no triangles", file=path, kind="mesh")
    if not np.all(np.isfinite(vertices)):
        raise error_type("mesh has non-finite vertices", file=path, kind="mesh")
    return vertices, faces
