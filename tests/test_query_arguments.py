"""Every public query says what is wrong with its arguments (issue 24, item 4).

Found by a crafted-input sweep: ``in_collision`` of a batch answered for row 0 alone;
``forward_batch(q, out=...)`` with ``out`` over ``q``'s memory overwrote configurations before
reading them; a complex batch lost its imaginary part in silence; object, complex and longdouble
arrays were blamed for "NaN or infinite values" they did not hold; ``margin=inf`` and
``threads="4"`` raised bare ValueError and TypeError. Each is now a RobotSpecError (KinematicsError
for a configuration, CollisionError for the checker's own arguments) that names the problem.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from robotspec.collision import CollisionRules, SelfCollisionChecker
from robotspec.description.urdf import load_urdf
from robotspec.errors import CollisionError, KinematicsError, RobotSpecError
from robotspec.model.kinematics import Kinematics

from .conftest import erd_robots

#: Three boxes: 'slider' moves along x towards 'post' (touching from x = -0.8), 'arm' turns
#: about z over the base. Pairs checked: (post, slider), (arm, slider), (arm, post).
URDF = """<?xml version="1.0"?>
<robot name="sliders">
  <link name="base"/>
  <link name="post"><collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <link name="slider">
    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>
  </link>
  <link name="arm">
    <collision><origin xyz="0.5 0 0"/><geometry><box size="0.4 0.05 0.05"/></geometry></collision>
  </link>
  <joint name="base_post" type="fixed"><parent link="base"/><child link="post"/></joint>
  <joint name="slide" type="prismatic">
    <parent link="base"/><child link="slider"/><origin xyz="1 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="turn" type="revolute">
    <parent link="base"/><child link="arm"/><origin xyz="0 0 1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
</robot>
"""

FREE = [0.0, 0.0]  # slide, turn
HIT = [-0.9, 0.0]  # the slider 10 cm into the post


@pytest.fixture
def checker(tmp_path: Path) -> SelfCollisionChecker:
    path = tmp_path / "sliders.urdf"
    path.write_text(URDF)
    world = load_urdf(path)
    return SelfCollisionChecker(world, CollisionRules.for_world(world, adjacency=False))


@pytest.fixture(autouse=True)
def _no_silent_conversion() -> Iterator[None]:
    """A ComplexWarning (numpy dropping an imaginary part) fails the test: nothing is cast."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        yield


def _single_queries(c: SelfCollisionChecker) -> dict[str, Callable[[Any], object]]:
    kin = c.kinematics
    chain = kin.chain("base", "slider")
    return {
        "forward": kin.forward,
        "pose": lambda q: kin.pose(q, "slider", "arm"),
        "chain.fk": chain.fk,
        "chain.jacobian": chain.jacobian,
        "in_collision": c.in_collision,
        "colliding_pairs": c.colliding_pairs,
        "buffer_violations": c.buffer_violations,
        "distances": c.distances,
    }


def _batch_queries(c: SelfCollisionChecker) -> dict[str, Callable[[Any], object]]:
    kin = c.kinematics
    return {
        "forward_batch": kin.forward_batch,
        "chain.fk_batch": kin.chain("base", "slider").fk_batch,
        "in_collision_batch": c.in_collision_batch,
        "collisions_batch": c.collisions_batch,
        "ever_colliding": c.ever_colliding,
        "distances_batch": c.distances_batch,
    }


def test_single_configuration_queries_refuse_a_batch(checker: SelfCollisionChecker) -> None:
    batch = np.array([FREE, HIT])
    assert checker.in_collision_batch(batch).tolist() == [False, True]  # answered whole
    assert checker.collisions_batch(batch).any(axis=1).tolist() == [False, True]
    for name, query in _single_queries(checker).items():
        with pytest.raises(KinematicsError, match=r"shape \(D,\).*got \(2, 2\)") as err:
            query(batch)
        if name in ("in_collision", "colliding_pairs", "buffer_violations", "distances"):
            assert "_batch" in str(err.value), name  # points to the batch method
    with pytest.raises(KinematicsError, match="use SelfCollisionChecker.in_collision_batch"):
        checker.in_collision(batch[::-1])  # row 0 collides: once True, for row 0 alone
    with pytest.raises(KinematicsError, match="use SelfCollisionChecker.distances_batch"):
        checker.distances([FREE])


@pytest.mark.parametrize(
    ("dtype", "why"),
    [
        (np.complex128, "complex"),
        (np.clongdouble, "complex"),
        (object, "object"),
        (np.longdouble, "float64 would round it"),
        ("U8", "not numbers"),
    ],
)
def test_arrays_float64_cannot_hold_are_refused_by_dtype(
    checker: SelfCollisionChecker, dtype: Any, why: str
) -> None:
    if np.dtype(dtype) == np.dtype(np.float64):  # a platform whose longdouble is float64
        pytest.skip("longdouble is float64 here")
    one = np.array(FREE).astype(dtype)
    many = np.array([FREE, HIT]).astype(dtype)
    queries = [(q, one) for q in _single_queries(checker).values()]
    queries += [(q, many) for q in _batch_queries(checker).values()]
    for query, arg in queries:
        with pytest.raises(KinematicsError) as err:
            query(arg)
        message = str(err.value)
        assert str(np.dtype(dtype)) in message and why in message, message
        assert "NaN" not in message


def test_complex_configuration_is_not_read_as_its_real_part(
    checker: SelfCollisionChecker,
) -> None:
    kin = checker.kinematics
    with pytest.raises(KinematicsError, match="complex128"):
        kin.forward_batch(np.array([HIT, FREE]) + 1j)
    with pytest.raises(KinematicsError, match="complex128"):
        kin.forward([complex(-0.9), 0.0])  # a list: the dtype numpy finds is checked too
    with pytest.raises(KinematicsError, match="object"):
        kin.forward([None, 0.0])


def test_numbers_float64_holds_answer_as_float64(checker: SelfCollisionChecker) -> None:
    kin = checker.kinematics
    want = kin.forward(np.array([1.0, 0.0]))
    for q in (np.array([1, 0]), np.array([True, False]), np.array([1, 0], dtype=np.float32)):
        np.testing.assert_array_equal(kin.forward(q), want)
        np.testing.assert_array_equal(kin.forward_batch(q[None, :])[0], want)
        assert not checker.in_collision(q)
    assert checker.in_collision_batch(np.array([[-1, 0], [0, 0]], dtype=np.int32)).tolist() == [
        True,
        False,
    ]


def test_non_finite_configuration_names_the_value_and_where(
    checker: SelfCollisionChecker,
) -> None:
    with pytest.raises(KinematicsError, match=r"NaN or infinite values \(nan at index 1\)"):
        checker.in_collision([0.0, np.nan])
    with pytest.raises(KinematicsError, match=r"\(inf at index \(1, 0\)\)"):
        checker.distances_batch([FREE, [np.inf, 0.0]])
    with pytest.raises(KinematicsError, match=r"\(-inf at index 0\)"):
        checker.kinematics.forward([-np.inf, 0.0])


def test_ragged_and_wrong_length_configurations(checker: SelfCollisionChecker) -> None:
    with pytest.raises(KinematicsError, match="rectangular"):
        checker.collisions_batch([FREE, [0.0]])
    with pytest.raises(KinematicsError, match=r"D = 2 degrees of freedom .* got \(3,\)"):
        checker.in_collision([0.0, 0.0, 0.0])
    with pytest.raises(KinematicsError, match=r"got \(\)"):
        checker.colliding_pairs(0.0)


@pytest.mark.parametrize(
    ("margin", "match"),
    [
        (np.inf, "margin must be finite, got inf"),
        (np.nan, "margin must be finite, got nan"),
        (-0.1, "margin must be >= 0, got -0.1"),
        ("0.1", "margin must be a real number, got str"),
        (True, "margin must be a real number, got bool"),
        (0.1j, "margin must be a real number, got complex"),
        (None, "margin must be a real number, got NoneType"),
    ],
)
def test_margin_must_be_a_finite_number(
    checker: SelfCollisionChecker, margin: Any, match: str
) -> None:
    for query in (
        lambda: checker.in_collision(FREE, margin=margin),
        lambda: checker.colliding_pairs(FREE, margin=margin),
        lambda: checker.in_collision_batch([FREE], margin=margin),
        lambda: checker.collisions_batch([FREE], margin=margin),
        lambda: checker.ever_colliding([FREE], margin=margin),
    ):
        with pytest.raises(CollisionError, match=match):
            query()
    near = checker.colliding_pairs([-0.75, 0.0], margin=np.float32(0.1))  # type: ignore[arg-type]
    assert near == (("post", "slider"),)


def test_pair_mask_must_be_one_boolean_per_pair(checker: SelfCollisionChecker) -> None:
    assert len(checker.active_pairs) == 3
    for bad in (np.ones(2, dtype=bool), np.ones(3, dtype=int), [[True] * 3], "yes"):
        with pytest.raises(CollisionError, match=r"pair_mask must be booleans of shape \(3,\)"):
            checker.collisions_batch([HIT], pair_mask=bad)  # type: ignore[arg-type]
    mask = np.array([True, False, False])
    assert checker.collisions_batch([HIT], pair_mask=mask).tolist() == [[True, False, False]]
    assert checker.ever_colliding([HIT], pair_mask=~mask).tolist() == [False, False, False]


@pytest.mark.parametrize("threads", ["4", 2.0, True, 0, 65, None])
def test_forward_batch_threads_must_be_an_integer(
    checker: SelfCollisionChecker, threads: Any
) -> None:
    qs = np.array([FREE, HIT])
    if threads is None:  # the default
        assert checker.kinematics.forward_batch(qs, threads=threads).shape[0] == 2
        return
    with pytest.raises(KinematicsError, match=r"threads must be an integer between 1 and 64"):
        checker.kinematics.forward_batch(qs, threads=threads)


def test_forward_batch_refuses_an_out_over_its_configurations(
    checker: SelfCollisionChecker,
) -> None:
    kin = checker.kinematics
    n, bodies = 1000, len(checker.world.bodies)
    qs = np.random.default_rng(5).uniform(-1, 1, (n, 2))
    want = kin.forward_batch(qs)
    buffer = np.zeros(n * bodies * 16 + n * 2)
    out = buffer[: n * bodies * 16].reshape(n, bodies, 4, 4)
    for alias in (
        out.reshape(n, -1)[:, :2],  # q inside out: each row of poses overwrites its q
        out.reshape(n, -1)[:, -2:],
        buffer[n * bodies * 16 - 1 :][: n * 2].reshape(n, 2),  # overlaps by one value
    ):
        alias[...] = qs
        for threads in (1, 4):
            with pytest.raises(KinematicsError, match="out must not share memory"):
                kin.forward_batch(alias, out=out, threads=threads)
    # A separate part of the same buffer is not shared memory: accepted, and right.
    apart = buffer[n * bodies * 16 :].reshape(n, 2)
    apart[...] = qs
    assert kin.forward_batch(apart, out=out) is out
    np.testing.assert_array_equal(out, want)
    # An integer q is converted into a new array, which out cannot overlap.
    ints = np.zeros((n, 2), dtype=np.int64)
    kin.forward_batch(ints, out=out)
    np.testing.assert_array_equal(out, kin.forward_batch(np.zeros((n, 2))))


def test_every_refusal_is_a_robotspec_error(checker: SelfCollisionChecker) -> None:
    """The crafted inputs of the sweep, over every entry: never a bare ValueError or TypeError."""
    crafted: list[object] = [
        "01",
        None,
        {"slide": 0.0},
        [[0.0, 0.0], [0.0]],
        np.array([1 + 1j, 0]),
        np.zeros((2, 2, 2)),
        np.zeros(0),
        [np.nan, 0.0],
        object(),
    ]
    queries = {**_single_queries(checker), **_batch_queries(checker)}
    for name, query in queries.items():
        for arg in crafted:
            try:
                query(arg)
            except RobotSpecError:
                continue
            except Exception as exc:  # noqa: BLE001 - the failure to report
                pytest.fail(f"{name}({arg!r}) raised {type(exc).__name__}: {exc}")
            pytest.fail(f"{name}({arg!r}) was accepted")


def test_pr2_in_collision_of_a_batch(tmp_path: Path) -> None:
    """The real robot: a batch whose first configuration is free and second is not."""
    from robotspec.collision.sampling import random_configurations
    from robotspec.compiler import compile_robot

    erd_robots()
    pr2 = compile_robot("pr2")
    checker = SelfCollisionChecker.from_robot(pr2)
    qs = random_configurations(pr2.world, 40, seed=2)
    hits = checker.in_collision_batch(qs)
    free, hit = qs[~hits][0], qs[hits][0]
    assert [checker.in_collision(q) for q in (free, hit)] == [False, True]
    with pytest.raises(KinematicsError, match="in_collision_batch"):
        checker.in_collision(np.stack([free, hit]))
    kin = Kinematics(pr2.world)
    with pytest.raises(KinematicsError, match="complex128"):
        kin.forward_batch(qs.astype(np.complex128))
    # One state's name is that state, not its letters ('p' was not found).
    np.testing.assert_array_equal(checker.configuration("park"), checker.configuration(["park"]))
    with pytest.raises(CollisionError, match="joint 'r_elbow_flex_joint': value must be finite"):
        checker.configuration((), {"r_elbow_flex_joint": np.inf})
    with pytest.raises(CollisionError, match="value must be a real number, got str"):
        checker.configuration((), {"r_elbow_flex_joint": "-1"})  # type: ignore[dict-item]


def test_configurations_by_name_and_chain_ends_say_what_is_wrong(
    checker: SelfCollisionChecker,
) -> None:
    world, kin = checker.world, checker.kinematics
    assert world.configuration({"slide": -1}).tolist() == [-1.0, 0.0]
    for value, match in (
        ("a", "value of 'slide' must be a real number, got str"),
        (1j, "value of 'slide' must be a real number, got complex"),
        (np.inf, "value of 'slide' must be finite, got inf"),
    ):
        with pytest.raises(KinematicsError, match=match):
            world.configuration({"slide": value})  # type: ignore[dict-item]
    with pytest.raises(KinematicsError, match="values must be a mapping"):
        world.configuration([0.0, 0.0])  # type: ignore[arg-type]
    for bad in (5, None):
        with pytest.raises(KinematicsError, match="a chain end must be a body name"):
            kin.pose(FREE, bad)  # type: ignore[arg-type]
        with pytest.raises(KinematicsError, match="a chain end must be a body name"):
            kin.chain("base", bad)  # type: ignore[arg-type]
    with pytest.raises(CollisionError, match="on_missing_mesh must be 'error' or 'skip'"):
        SelfCollisionChecker(
            world,
            checker.rules,
            on_missing_mesh="ignore",  # type: ignore[arg-type]
        )


def test_pinocchio_configuration_refuses_what_float64_cannot_hold() -> None:
    from robotspec.model.pinocchio import PinocchioRobot

    robot = PinocchioRobot(model=None, collision_model=None, frames={}, q_index=(1, 0))
    assert robot.configuration([1, 2]).tolist() == [2.0, 1.0]
    for bad, match in (
        ([1 + 1j, 0.0], "complex128"),
        ([None, 0.0], "object"),
        ([np.nan, 0.0], r"nan at index 0"),
        ([0.0], r"shape \(2,\)"),
    ):
        with pytest.raises(KinematicsError, match=match):
            robot.configuration(bad)
