"""SDT's own failures while it builds a world, named as SDT's, with the file they concern.

Why: SDT turns every mesh of a world into Bullet collision shapes, decomposing the non-convex
ones (V-HACD by default) as the world is built. When that fails (an empty mesh gives V-HACD
nothing to decompose, and SDT then fails to export no parts: ``ValueError: Can't export empty
scenes!``), the exception names neither SDT's step nor the mesh, and robotspec's CLI reported
it as "a bug in robotspec". :func:`mesh_failure` reads SDT's own frames of the traceback for
the mesh and the step, so the user learns which file to fix, and that SDT's cache now holds the
mesh undecomposed (SDT writes it there before it decomposes, and takes it as done next time).
"""

from __future__ import annotations

from types import TracebackType

from robotspec.errors import RobotSpecError

__all__ = ["mesh_failure"]

#: SDT 26.7's functions (collision_checking/pybullet_collision_detector.py) that turn one mesh
#: into a Bullet shape; each has the SDT ``Mesh`` as its local ``mesh``.
_DECOMPOSE = "convert_to_decomposed_obj_and_save_in_tmp"
_LOAD = "load_convex_mesh_shape"


def _sdt_frames(tb: TracebackType | None) -> list[tuple[str, dict[str, object]]]:
    """(function name, locals) of SDT's mesh steps in the traceback, outermost first."""
    out = []
    while tb is not None:
        code = tb.tb_frame.f_code
        if "semantic_digital_twin" in code.co_filename and code.co_name in (_DECOMPOSE, _LOAD):
            out.append((code.co_name, dict(tb.tb_frame.f_locals)))
        tb = tb.tb_next
    return out


def _faces(mesh: object) -> int | None:
    try:
        return len(mesh.mesh.faces)  # type: ignore[attr-defined]
    except Exception:  # noqa: BLE001 - a count for the message only; SDT's error is the news
        return None


def mesh_failure(exc: BaseException) -> RobotSpecError | None:
    """A RobotSpecError naming SDT's failed step and the mesh file, or None if not a mesh's."""
    frames = _sdt_frames(exc.__traceback__)
    if not frames:
        return None
    step, local = frames[-1]
    mesh = local.get("mesh")
    filename = getattr(mesh, "filename", None) or "(a mesh without a file)"
    faces = _faces(mesh)
    shape = f" ({faces} faces)" if faces is not None else ""
    cause = f"{type(exc).__name__}: {str(exc).strip()}"
    if step == _DECOMPOSE:
        decomposer = type(local.get("mesh_decomposer")).__name__
        message = (
            f"SDT's convex decomposition ({decomposer}) of mesh '{filename}'{shape} failed "
            f"with {cause}; fix or replace the mesh"
        )
        cached = local.get("obj_file_name")
        if cached:
            message += (
                f" (SDT has already cached it undecomposed as {cached}, and would load that "
                "as it is next time: delete the file)"
            )
    else:
        message = f"SDT cannot load mesh '{filename}'{shape} as a Bullet shape: {cause}"
    return RobotSpecError(message, kind="mesh", name=str(filename))
