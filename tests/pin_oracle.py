"""pinocchio as an independent oracle for forward kinematics (tests and benchmarks only)."""

from __future__ import annotations

import numpy as np

from robotspec.model.world import World


class PinOracle:
    """A pinocchio model of the same URDF, with a map from robotspec configurations."""

    def __init__(self, urdf: str, world: World) -> None:
        import pinocchio as pin

        self.pin = pin
        self.model = pin.buildModelFromUrdf(urdf)
        self.data = self.model.createData()
        self.world = world
        self._joints = []
        for j in range(1, self.model.njoints):
            c = world.get_connection_by_name(self.model.names[j])
            jm = self.model.joints[j]
            mul = c.mimic.multiplier if c.mimic else 1.0
            off = c.mimic.offset if c.mimic else 0.0
            self._joints.append((jm.idx_q, jm.nq, c.dofs[0], mul, off))

    def q(self, q: np.ndarray) -> np.ndarray:
        qp = self.pin.neutral(self.model)
        for idx, nq, dof, mul, off in self._joints:
            v = q[dof] * mul + off
            if nq == 2:
                qp[idx : idx + 2] = (np.cos(v), np.sin(v))
            else:
                qp[idx] = v
        return qp

    def poses(self, q: np.ndarray) -> dict[str, np.ndarray]:
        self.pin.forwardKinematics(self.model, self.data, self.q(q))
        self.pin.updateFramePlacements(self.model, self.data)
        out = {}
        for b in self.world.bodies:
            # A link's frame (some URDFs name a joint like a link: ANYmal's LF_HAA).
            fid = self.model.getFrameId(b.name, self.pin.FrameType.BODY)
            out[b.name] = self.data.oMf[fid].homogeneous.copy()
        return out
