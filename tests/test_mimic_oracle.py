"""Forward kinematics of robots with mimic joints against pinocchio's own mimic joints.

Why a second oracle: ``pin_oracle.PinOracle`` builds pinocchio's model *without* mimic joints and
sets each follower from robotspec's own reading of ``<mimic>``, so a misread multiplier or offset
would agree with itself. Here pinocchio reads ``<mimic>`` (``JointModelMimic``, pinocchio 3.4+)
and only the leaders are set; every body must land where robotspec puts it. The robots come from
example-robot-data, so the test runs in any clone (no ``../shared``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robotspec.description.urdf import world_from_urdf_xml
from robotspec.files.xmlsafe import parse_xml_file
from robotspec.model.kinematics import Kinematics
from robotspec.model.world import World

from .conftest import erd_robots

pin = pytest.importorskip("pinocchio")

MIMIC_ROBOTS = [
    "pr2_description/urdf/pr2.urdf",
    "panda_description/urdf/panda.urdf",
    "baxter_description/urdf/baxter.urdf",
    "tiago_pro_description/robots/tiago_pro.urdf",
]
# Left out: Romeo (pinocchio refuses its mimic of a joint outside the tree), Alex with Psyonic
# hands (its <mimic> names joints that do not exist; robotspec refuses the file, located), the
# Talos URDFs (their <mimic> lines are commented out).


class MimicOracle:
    """pinocchio's model with mimic joints; robotspec's leaders set its configuration."""

    def __init__(self, path: Path, world: World) -> None:
        self.model = pin.buildModelFromUrdf(str(path), mimic=True)
        self.data = self.model.createData()
        self.world = world
        self.leaders: list[tuple[int, int, int]] = []  # pinocchio idx_q, nq, robotspec dof
        self.n_mimic = 0
        for j in range(1, self.model.njoints):
            joint = self.model.joints[j]
            if joint.shortname() == "JointModelMimic":
                self.n_mimic += 1
                continue
            conn = world.get_connection_by_name(self.model.names[j])
            assert not conn.is_mimic, conn.name
            self.leaders.append((joint.idx_q, joint.nq, conn.dofs[0]))

    def poses(self, q: np.ndarray) -> dict[str, np.ndarray]:
        qp = pin.neutral(self.model)
        for idx, nq, dof in self.leaders:
            if nq == 2:  # continuous joint: cos, sin
                qp[idx : idx + 2] = (np.cos(q[dof]), np.sin(q[dof]))
            else:
                qp[idx] = q[dof]
        pin.framesForwardKinematics(self.model, self.data, qp)
        return {
            b.name: self.data.oMf[self.model.getFrameId(b.name, pin.FrameType.BODY)].homogeneous
            for b in self.world.bodies
        }


@pytest.fixture(scope="module", params=MIMIC_ROBOTS, ids=lambda p: Path(p).stem)
def robot(request: pytest.FixtureRequest) -> tuple[World, Kinematics, MimicOracle]:
    path = erd_robots() / request.param
    world = world_from_urdf_xml(parse_xml_file(path), str(path))
    oracle = MimicOracle(path, world)
    assert oracle.n_mimic > 0 and any(c.is_mimic for c in world.connections)
    return world, Kinematics(world), oracle


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_every_body_where_pinocchio_s_mimic_joints_put_it(
    robot: tuple[World, Kinematics, MimicOracle], seed: int
) -> None:
    world, kinematics, oracle = robot
    rng = np.random.default_rng(seed)
    q = world.configuration()
    for dof in world.degrees_of_freedom:
        lo, hi = dof.lower, dof.upper  # within limits: mimic followers stay sane
        lo = -np.pi if not np.isfinite(lo) else lo
        hi = np.pi if not np.isfinite(hi) else hi
        q[dof.index] = rng.uniform(lo, hi)
    mine = kinematics.forward(q)
    ref = oracle.poses(q)
    for body in world.bodies:
        np.testing.assert_allclose(mine[body.index], ref[body.name], atol=1e-9, err_msg=body.name)
