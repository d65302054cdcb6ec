"""The user's MJCF as MuJoCo reads it: names, joints, poses, and the few elements added to it.

Why a wrapper: the annotation reads their model (compiled, for forward kinematics) and edits it
(``MjSpec``, MuJoCo's own model editor, so what they wrote is kept as MuJoCo understands it),
and both sides go through MuJoCo's API, which nothing else of robotspec imports. Every added
element gets a name not yet taken (``_robotspec`` appended, with a note), so nothing of theirs
is replaced.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from robotspec.arrays import F64
from robotspec.errors import RobotSpecError, missing_file
from robotspec.export.mjcf_bodies import nums
from robotspec.extras import MUJOCO, require_present
from robotspec.interop.mujoco_files import check_model_files
from robotspec.interop.mujoco_fit import FrameFit, inverse, pose_error
from robotspec.interop.mujoco_xml import Edit, site_edit, write_edits
from robotspec.model.rotations import matrix_to_quat_wxyz

if TYPE_CHECKING:
    from robotspec.semantic import AbstractRobot

__all__ = ["MUJOCO_INSTALL", "TheirModel", "read_model"]

#: What a user without MuJoCo is told to run (the same words as the physics driver's).
MUJOCO_INSTALL = MUJOCO.command

_SUFFIX = "_robotspec"


def read_model(path: Path) -> TheirModel:
    """Read and compile ``path`` with MuJoCo; its complaint becomes a RobotSpecError."""
    require_present(MUJOCO, "robotspec annotate mjcf")
    import mujoco  # type: ignore[import-untyped, unused-ignore]

    if not Path(path).is_file():
        raise missing_file(path)
    check_model_files(Path(path))  # before MuJoCo opens what the model names
    try:
        spec = mujoco.MjSpec.from_file(str(path))
        model = spec.compile()
    except ValueError as exc:
        raise _complaint(exc, path) from exc
    return TheirModel(Path(path), spec, model)


def _complaint(exc: ValueError, path: Path) -> RobotSpecError:
    """MuJoCo's complaint as one line at the line it names.

    Why: MuJoCo says what is wrong, then on a second line where (``Element name 'x', id 3,
    line 11``); printed as it is, the second line came out as an escaped line break.
    """
    lines = [t.strip() for t in str(exc).splitlines() if t.strip()]
    what = (lines[0] if lines else "no reason given").removeprefix("Error: ")
    where = re.search(r"Element name '([^']*)'", " ".join(lines[1:]))
    line = re.search(r"\bline (\d+)", " ".join(lines[1:]))
    if where is not None:
        what += f" (element '{where.group(1)}')"
    elif len(lines) > 1:
        what += f" ({'; '.join(lines[1:])})"
    return RobotSpecError(
        f"MuJoCo cannot load it: {what}",
        file=str(path),
        line=int(line.group(1)) if line is not None else None,
        kind="model",
    )


class TheirModel:
    """Their MJCF: the editable ``MjSpec``, its compiled model, and name tables read from it."""

    def __init__(self, path: Path, spec: Any, model: Any) -> None:
        import mujoco

        self.mj = mujoco
        self.path, self.spec, self.model = path, spec, model
        self.shown = str(path)
        obj = mujoco.mjtObj
        name = mujoco.mj_id2name
        self.body_names = [name(model, obj.mjOBJ_BODY, i) or "" for i in range(model.nbody)]
        self.bodies = [n for n in self.body_names if n]
        self.body_parent = {
            n: self.body_names[int(model.body_parentid[i])]
            for i, n in enumerate(self.body_names)
            if n and i > 0
        }
        kinds = {
            int(mujoco.mjtJoint.mjJNT_HINGE): "hinge",
            int(mujoco.mjtJoint.mjJNT_SLIDE): "slide",
        }
        self.joints: list[str] = []
        self.joint_kind: dict[str, str] = {}
        self.joint_body: dict[str, str] = {}
        self.joint_qpos: dict[str, int] = {}
        for j in range(model.njnt):
            jn = name(model, obj.mjOBJ_JOINT, j)
            if not jn:
                continue
            self.joints.append(jn)
            self.joint_kind[jn] = kinds.get(int(model.jnt_type[j]), "free or ball")
            self.joint_body[jn] = self.body_names[int(model.jnt_bodyid[j])]
            self.joint_qpos[jn] = int(model.jnt_qposadr[j])
        self.qpos0 = np.array(model.qpos0, dtype=np.float64)
        self._data = mujoco.MjData(model)
        self._ctrl_noted = False
        self.edits: list[Edit] = []

    # ------------------------------------------------------------------ reading
    def body_poses(self, qpos: F64, model: Any = None, data: Any = None) -> dict[str, F64]:
        """Every named body's world pose at ``qpos`` (MuJoCo's own kinematics)."""
        model = model or self.model
        data = data or self._data
        data.qpos[:] = qpos
        self.mj.mj_kinematics(model, data)
        out: dict[str, F64] = {}
        for i, n in enumerate(self.body_names):
            if n:
                pose = np.eye(4)
                pose[:3, :3] = np.asarray(data.xmat[i]).reshape(3, 3)
                pose[:3, 3] = data.xpos[i]
                out[n] = pose
        return out

    def _free(self, kind: str, wanted: str, taken: Sequence[str], notes: list[str]) -> str:
        if wanted not in taken:
            return wanted
        n = f"{wanted}{_SUFFIX}"
        i = 2
        while n in taken:
            n, i = f"{wanted}{_SUFFIX}{i}", i + 1
        notes.append(f"the model already has a {kind} named '{wanted}': added as '{n}'")
        return n

    def _body(self, name: str) -> Any:
        return self.spec.worldbody if name == "world" else self.spec.body(name)

    # ------------------------------------------------------------------ adding
    def add_site(self, wanted: str, body: str, pose: F64, notes: list[str]) -> str:
        """A site named after ``wanted`` at ``pose`` in their ``body``."""
        n = self._free("site", wanted, [s.name for s in self.spec.sites], notes)
        quat = matrix_to_quat_wxyz(pose[:3, :3])
        self._body(body).add_site(name=n, pos=pose[:3, 3], quat=quat)
        self.edits.append(site_edit("site", body, n, pose[:3, 3], quat))
        return n

    def add_camera(self, wanted: str, body: str, pose: F64, fovy: float, notes: list[str]) -> str:
        """A camera (MuJoCo's look along -z) at ``pose`` in ``body``, ``fovy`` in degrees."""
        n = self._free("camera", wanted, [c.name for c in self.spec.cameras], notes)
        quat = matrix_to_quat_wxyz(pose[:3, :3])
        self._body(body).add_camera(name=n, pos=pose[:3, 3], quat=quat, fovy=fovy)
        self.edits.append(site_edit("camera", body, n, pose[:3, 3], quat, fovy=fovy))
        return n

    def servo_ctrl(self, qpos: F64, notes: list[str] | None) -> F64:
        """Each position servo's target at ``qpos``; other actuators 0 (noted once)."""
        m, mj = self.model, self.mj
        ctrl = np.zeros(m.nu)
        others: list[str] = []
        for a in range(m.nu):
            gain, bias = m.actuator_gainprm[a], m.actuator_biasprm[a]
            servo = (
                int(m.actuator_trntype[a]) == int(mj.mjtTrn.mjTRN_JOINT)
                and int(m.actuator_biastype[a]) == int(mj.mjtBias.mjBIAS_AFFINE)
                and gain[0] != 0.0
                and bias[1] == -gain[0]
                and bias[0] == 0.0
            )
            if servo:
                value = float(qpos[int(m.jnt_qposadr[int(m.actuator_trnid[a, 0])])])
                if m.actuator_ctrllimited[a]:
                    value = float(np.clip(value, *m.actuator_ctrlrange[a]))
                ctrl[a] = value
            else:
                others.append(mj.mj_id2name(m, mj.mjtObj.mjOBJ_ACTUATOR, a) or f"#{a}")
        if others and notes is not None:
            notes.append(
                f"{', '.join(repr(n) for n in others)}: not a position servo on one joint, "
                "so ctrl is 0 in the added keyframes"
            )
        return ctrl

    def add_key(self, wanted: str, qpos: F64, notes: list[str]) -> str:
        """A keyframe with their qpos layout and each position servo holding it."""
        n = self._free("keyframe", wanted, [k.name for k in self.spec.keys], notes)
        ctrl = self.servo_ctrl(qpos, None if self._ctrl_noted else notes)
        self._ctrl_noted = True
        key = self.spec.add_key(name=n, qpos=qpos)
        attrib = [("name", n), ("qpos", nums(qpos))]
        if self.model.nu:
            key.ctrl = ctrl
            attrib.append(("ctrl", nums(ctrl)))
        self.edits.append(Edit("key", None, tuple(attrib)))
        return n

    def add_exclude(self, first: str, second: str) -> bool:
        """An ``<exclude>`` between two of their bodies, unless one exists or they are one."""
        if first == second:
            return False
        for e in self.spec.excludes:
            if {e.bodyname1, e.bodyname2} == {first, second}:
                return False
        self.spec.add_exclude(bodyname1=first, bodyname2=second)
        self.edits.append(Edit("exclude", None, (("body1", first), ("body2", second))))
        return True

    # ------------------------------------------------------------------ checking, writing
    def site_error(
        self,
        targets: Sequence[tuple[str, str, int, F64]],
        qs: Sequence[F64],
        qpos: Callable[[F64], F64],
        robot: AbstractRobot,
        our_root: int,
        their_root: str,
        fit: FrameFit,
        model: Any = None,
    ) -> float:
        """The largest misfit (m, or rad) of an added site or camera from where the spec puts it.

        ``model``: a compiled model to measure (the written file, read back); by default the
        edited ``MjSpec`` compiled.
        """
        try:
            model = model or self.spec.compile()
        except ValueError as exc:  # pragma: no cover - MuJoCo accepted the model before
            raise RobotSpecError(
                f"MuJoCo refuses the annotated model: {exc}", file=self.shown
            ) from exc
        data = self.mj.MjData(model)
        back = inverse(fit.root)
        worst = 0.0
        for q in qs:
            fk = robot.kinematics.forward(q)
            theirs = self.body_poses(qpos(q), model, data)
            t_root = inverse(theirs[their_root])
            o_root = inverse(fk[our_root])
            self.mj.mj_camlight(model, data)  # camera poses (mj_kinematics leaves them out)
            for kind, name, body, frame in targets:
                pose = np.eye(4)
                if kind == "site":
                    i = self.mj.mj_name2id(model, self.mj.mjtObj.mjOBJ_SITE, name)
                    pose[:3, :3] = np.asarray(data.site_xmat[i]).reshape(3, 3)
                    pose[:3, 3] = data.site_xpos[i]
                else:
                    i = self.mj.mj_name2id(model, self.mj.mjtObj.mjOBJ_CAMERA, name)
                    pose[:3, :3] = np.asarray(data.cam_xmat[i]).reshape(3, 3)
                    pose[:3, 3] = data.cam_xpos[i]
                want = back @ o_root @ fk[body] @ frame
                worst = max(worst, pose_error(t_root @ pose, want))
        return worst

    def to_xml(self, output: Path | None, notes: list[str]) -> str:
        """Their file's text with the added elements (see :mod:`robotspec.interop.mujoco_xml`)."""
        return write_edits(self.path, self.edits, output, notes)
