"""Every entry point of both cores refuses the same bad arguments with the same error (issue 31).

Why: the C cores (``_kincore.c``, ``_meshcore.c``) and their numpy fallbacks are chosen at run
time (``ROBOTSPEC_NO_ACCEL=1``, or no compiler at install). The fallbacks read arguments with
``int()``, ``float()`` and ``np.asarray``, so under ``ROBOTSPEC_NO_ACCEL=1`` some raised a bare
``OverflowError`` or accepted ``float("1e-3")`` where the C core gives a TypeError or ValueError.
Each case below is run on the fallback (it must raise the listed exception type) and, where the
C core is built, on the C core too (the same type and the same message).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np
import pytest

from robotspec.collision import _meshcore_py as mesh_py
from robotspec.model import _kincore_py as kin_py

EYE2 = np.tile(np.eye(4), (2, 1, 1))
Z_AXES = np.tile([0.0, 0.0, 1.0], (2, 1))
I2 = np.zeros(2, dtype=np.int64)
V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
F = np.array([[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])
POSES = np.tile(np.eye(4), (1, 2, 1, 1))  # (N=1, G=2, 4, 4)
NAN_V = V.copy()
NAN_V[3, 0] = np.nan


def tree_args(**change: Any) -> list[Any]:
    """A valid two-row tree program (two revolute joints on one DOF), with ``change`` applied."""
    args = {
        "parent": np.array([0, 1]),
        "child": np.array([1, 2]),
        "kind": np.ones(2, dtype=np.int64),
        "origin": EYE2,
        "axis": Z_AXES,
        "dof": I2,
        "mul": np.ones(2),
        "off": np.zeros(2),
        "n_slots": 3,
        "n_out": 3,
        "n_dof": 1,
    }
    args.update(change)
    return list(args.values())


def chain_args(**change: Any) -> list[Any]:
    """A valid two-motion chain program, with ``change`` applied."""
    args = {
        "pre": EYE2,
        "post": np.eye(4),
        "kind": np.ones(2, dtype=np.int64),
        "axis": Z_AXES,
        "dof": I2,
        "mul": np.ones(2),
        "off": np.zeros(2),
        "col": I2,
        "n_cols": 1,
        "n_dof": 1,
    }
    args.update(change)
    return list(args.values())


def geoms_args(**change: Any) -> list[Any]:
    """Two geometries on two bodies and the pair of them, with ``change`` applied."""
    args = {
        "body": np.array([0, 1]),
        "body_to_geom": EYE2,
        "center": np.zeros((2, 3)),
        "half": np.full((2, 3), 0.1),
        "g1": np.array([0]),
        "g2": np.array([1]),
        "n_body": 2,
    }
    args.update(change)
    return list(args.values())


@dataclass(frozen=True)
class Tables:
    """One core's valid tables, the arguments every query case starts from."""

    tree: object
    chain: object
    geoms: object
    meshes: object


def tables(kin: ModuleType, mesh: ModuleType) -> Tables:
    return Tables(
        kin.tree(*tree_args()),
        kin.chain(*chain_args()),
        kin.geoms(*geoms_args()),
        mesh.mesh_set([(V, F), (V + 5.0, F)]),
    )


Call = Callable[[ModuleType, ModuleType, Tables], object]

#: (what is wrong, the call, the exception both cores raise). ``k``: the kinematics core,
#: ``m``: the mesh core, ``t``: that core's valid tables.
CASES: list[tuple[str, Call, type[Exception]]] = [
    # --- tree(): counts are indices (n), arrays one dimension (int64) or any (float64)
    ("tree: a float count", lambda k, m, t: k.tree(*tree_args(n_slots=3.0)), TypeError),
    ("tree: a count too large", lambda k, m, t: k.tree(*tree_args(n_out=2**70)), OverflowError),
    ("tree: a string count", lambda k, m, t: k.tree(*tree_args(n_dof="1")), TypeError),
    ("tree: no output slot", lambda k, m, t: k.tree(*tree_args(n_out=0)), ValueError),
    ("tree: parent None", lambda k, m, t: k.tree(*tree_args(parent=None)), TypeError),
    ("tree: parent 2-D", lambda k, m, t: k.tree(*tree_args(parent=np.zeros((2, 1)))), ValueError),
    (
        "tree: child of floats",
        lambda k, m, t: k.tree(*tree_args(child=np.array([1.0, 2.0]))),
        TypeError,
    ),
    (
        "tree: child of huge ints",
        lambda k, m, t: k.tree(*tree_args(child=[2**70, 1])),
        OverflowError,
    ),
    ("tree: dof None (no len)", lambda k, m, t: k.tree(*tree_args(dof=[None, None])), TypeError),
    ("tree: kind a nested list", lambda k, m, t: k.tree(*tree_args(kind=[[1], [1]])), ValueError),
    ("tree: origin too short", lambda k, m, t: k.tree(*tree_args(origin=np.eye(4))), ValueError),
    (
        "tree: complex multipliers",
        lambda k, m, t: k.tree(*tree_args(mul=np.ones(2, complex))),
        TypeError,
    ),
    ("tree: a row out of range", lambda k, m, t: k.tree(*tree_args(parent=[0, 5])), ValueError),
    ("tree: a kind out of range", lambda k, m, t: k.tree(*tree_args(kind=[1, 7])), ValueError),
    (
        "tree: a slot read unset",
        lambda k, m, t: k.tree(*tree_args(parent=[2, 0], child=[1, 2])),
        ValueError,
    ),
    # --- fk(), fk_batch(), tree_size(): a tree of this core; a configuration of finite floats
    ("fk: not a tree", lambda k, m, t: k.fk(t.chain, np.zeros(1)), TypeError),
    ("fk: a capsule-less object", lambda k, m, t: k.fk(None, np.zeros(1)), TypeError),
    ("tree_size: not a tree", lambda k, m, t: k.tree_size(t.geoms), TypeError),
    ("fk: a batch", lambda k, m, t: k.fk(t.tree, np.zeros((2, 1))), ValueError),
    ("fk: a scalar", lambda k, m, t: k.fk(t.tree, 0.5), ValueError),
    ("fk: a mapping", lambda k, m, t: k.fk(t.tree, {}), ValueError),
    ("fk: too many values", lambda k, m, t: k.fk(t.tree, np.zeros(2)), ValueError),
    ("fk: NaN", lambda k, m, t: k.fk(t.tree, np.array([np.nan])), ValueError),
    ("fk: complex", lambda k, m, t: k.fk(t.tree, np.zeros(1, complex)), TypeError),
    ("fk: long double", lambda k, m, t: k.fk(t.tree, np.zeros(1, np.longdouble)), TypeError),
    ("fk: a string", lambda k, m, t: k.fk(t.tree, "0"), ValueError),
    ("fk: a ragged list", lambda k, m, t: k.fk(t.tree, [[0.0], [0.0, 1.0]]), ValueError),
    ("fk: a nested list", lambda k, m, t: k.fk(t.tree, [[0.0]]), ValueError),
    ("fk_batch: one configuration", lambda k, m, t: k.fk_batch(t.tree, np.zeros(1)), ValueError),
    ("fk_batch: infinity", lambda k, m, t: k.fk_batch(t.tree, [[np.inf]]), ValueError),
    (
        "fk_batch: out a list",
        lambda k, m, t: k.fk_batch(t.tree, np.zeros((2, 1)), [0.0], True),
        TypeError,
    ),
    (
        "fk_batch: out of the wrong shape",
        lambda k, m, t: k.fk_batch(t.tree, np.zeros((2, 1)), np.zeros((1, 3, 4, 4)), True),
        ValueError,
    ),
    (
        "fk_batch: out non-contiguous",
        lambda k, m, t: k.fk_batch(t.tree, np.zeros((2, 1)), np.zeros((2, 3, 4, 8))[..., ::2]),
        TypeError,
    ),
    (
        "fk_batch: stream with no truth value",
        lambda k, m, t: k.fk_batch(t.tree, np.zeros((2, 1)), None, np.ones(2)),
        ValueError,
    ),
    # --- chain() and its queries
    ("chain: a float count", lambda k, m, t: k.chain(*chain_args(n_cols=1.5)), TypeError),
    ("chain: a count too large", lambda k, m, t: k.chain(*chain_args(n_dof=2**64)), OverflowError),
    ("chain: a negative count", lambda k, m, t: k.chain(*chain_args(n_cols=-1)), ValueError),
    ("chain: kind None", lambda k, m, t: k.chain(*chain_args(kind=None)), TypeError),
    ("chain: post too short", lambda k, m, t: k.chain(*chain_args(post=np.eye(3))), ValueError),
    ("chain: dof 2-D", lambda k, m, t: k.chain(*chain_args(dof=np.zeros((2, 1), int))), ValueError),
    ("chain: a fixed motion", lambda k, m, t: k.chain(*chain_args(kind=[1, 0])), ValueError),
    ("chain: a column out of range", lambda k, m, t: k.chain(*chain_args(col=[0, 1])), ValueError),
    ("chain_fk: not a chain", lambda k, m, t: k.chain_fk(t.tree, np.zeros(1)), TypeError),
    ("chain_fk: NaN", lambda k, m, t: k.chain_fk(t.chain, [np.nan]), ValueError),
    (
        "chain_fk_batch: one configuration",
        lambda k, m, t: k.chain_fk_batch(t.chain, [0.0]),
        ValueError,
    ),
    ("chain_fk_batch: not a chain", lambda k, m, t: k.chain_fk_batch("chain", [[0.0]]), TypeError),
    ("chain_jacobian: complex", lambda k, m, t: k.chain_jacobian(t.chain, [1j]), TypeError),
    ("chain_jacobian: too few values", lambda k, m, t: k.chain_jacobian(t.chain, []), ValueError),
    # --- geoms() and broad()
    ("geoms: a float body count", lambda k, m, t: k.geoms(*geoms_args(n_body=2.0)), TypeError),
    ("geoms: body None", lambda k, m, t: k.geoms(*geoms_args(body=None)), TypeError),
    ("geoms: g1 None", lambda k, m, t: k.geoms(*geoms_args(g1=None)), TypeError),
    ("geoms: g2 a scalar", lambda k, m, t: k.geoms(*geoms_args(g2=1)), ValueError),
    ("geoms: g1 2-D", lambda k, m, t: k.geoms(*geoms_args(g1=np.zeros((1, 1), int))), ValueError),
    ("geoms: a body out of range", lambda k, m, t: k.geoms(*geoms_args(n_body=1)), ValueError),
    ("geoms: a pair out of range", lambda k, m, t: k.geoms(*geoms_args(g2=[2])), ValueError),
    (
        "geoms: center too short",
        lambda k, m, t: k.geoms(*geoms_args(center=np.zeros(3))),
        ValueError,
    ),
    ("broad: not a table", lambda k, m, t: k.broad(t.tree, POSES, 0.0, None), TypeError),
    ("broad: a string margin", lambda k, m, t: k.broad(t.geoms, POSES, "0.1", None), TypeError),
    ("broad: a margin None", lambda k, m, t: k.broad(t.geoms, POSES, None, None), TypeError),
    ("broad: poses 2-D", lambda k, m, t: k.broad(t.geoms, np.eye(4), 0.0, None), ValueError),
    ("broad: poses 5-D", lambda k, m, t: k.broad(t.geoms, POSES[None], 0.0, None), ValueError),
    (
        "broad: poses of 3 bodies",
        lambda k, m, t: k.broad(t.geoms, np.zeros((3, 4, 4)), 0.0, None),
        ValueError,
    ),
    (
        "broad: complex poses",
        lambda k, m, t: k.broad(t.geoms, POSES.astype(complex), 0.0, None),
        TypeError,
    ),
    (
        "broad: an int64 mask",
        lambda k, m, t: k.broad(t.geoms, POSES, 0.0, np.ones(1, np.int64)),
        TypeError,
    ),
    (
        "broad: a 2-D mask",
        lambda k, m, t: k.broad(t.geoms, POSES, 0.0, np.ones((1, 1), np.uint8)),
        ValueError,
    ),
    ("broad: a mask too long", lambda k, m, t: k.broad(t.geoms, POSES, 0.0, [1, 1]), ValueError),
    # --- mesh_set()
    ("mesh_set: not a sequence", lambda k, m, t: m.mesh_set(5), TypeError),
    ("mesh_set: a list, not a tuple", lambda k, m, t: m.mesh_set([[V, F]]), TypeError),
    ("mesh_set: three items", lambda k, m, t: m.mesh_set([(V, F, 1)]), TypeError),
    ("mesh_set: vertices (V, 2)", lambda k, m, t: m.mesh_set([(V[:, :2], F)]), ValueError),
    ("mesh_set: vertices 3-D", lambda k, m, t: m.mesh_set([(V[None], F)]), ValueError),
    ("mesh_set: vertices a string", lambda k, m, t: m.mesh_set([("V", F)]), ValueError),
    ("mesh_set: complex vertices", lambda k, m, t: m.mesh_set([(V.astype(complex), F)]), TypeError),
    ("mesh_set: float triangles", lambda k, m, t: m.mesh_set([(V, F.astype(float))]), TypeError),
    ("mesh_set: no triangle", lambda k, m, t: m.mesh_set([(V, F[:0])]), ValueError),
    ("mesh_set: a vertex out of range", lambda k, m, t: m.mesh_set([(V, F + 1)]), ValueError),
    ("mesh_set: no vertex at all", lambda k, m, t: m.mesh_set([(V[:0], F)]), ValueError),
    ("mesh_set: a NaN vertex", lambda k, m, t: m.mesh_set([(NAN_V, F)]), ValueError),
    (
        "mesh_set: out of range before NaN",
        lambda k, m, t: m.mesh_set([(NAN_V, np.array([[0, 1, 9], [3, 1, 2]]))]),
        ValueError,
    ),
    (
        "mesh_set: NaN before out of range",
        lambda k, m, t: m.mesh_set([(NAN_V, np.array([[0, 3, 9]]))]),
        ValueError,
    ),
    # --- apart(), apart_one(), on_surface()
    (
        "apart: a string eps",
        lambda k, m, t: m.apart(t.meshes, POSES, [0], [0], [0], [1], "1e-5"),
        TypeError,
    ),
    ("apart: eps 0", lambda k, m, t: m.apart(t.meshes, POSES, [0], [0], [0], [1], 0.0), ValueError),
    (
        "apart: not a set",
        lambda k, m, t: m.apart(t.tree, POSES, [0], [0], [0], [1], 1e-5),
        TypeError,
    ),
    (
        "apart: poses 3-D",
        lambda k, m, t: m.apart(t.meshes, POSES[0], [0], [0], [0], [1], 1e-5),
        ValueError,
    ),
    (
        "apart: rows of floats",
        lambda k, m, t: m.apart(t.meshes, POSES, np.zeros(1), [0], [0], [1], 1e-5),
        TypeError,
    ),
    (
        "apart: rows 2-D",
        lambda k, m, t: m.apart(t.meshes, POSES, [[0]], [0], [0], [1], 1e-5),
        ValueError,
    ),
    (
        "apart: g2 None",
        lambda k, m, t: m.apart(t.meshes, POSES, [0], [0], [0], None, 1e-5),
        ValueError,
    ),
    (
        "apart: lengths differ",
        lambda k, m, t: m.apart(t.meshes, POSES, [0, 0], [0], [0], [1], 1e-5),
        ValueError,
    ),
    (
        "apart: a candidate out of range",
        lambda k, m, t: m.apart(t.meshes, POSES, [1], [0], [0], [1], 1e-5),
        ValueError,
    ),
    (
        "apart_one: a float row",
        lambda k, m, t: m.apart_one(t.meshes, POSES, 0.0, 0, 1, 1e-5),
        TypeError,
    ),
    (
        "apart_one: a row too large",
        lambda k, m, t: m.apart_one(t.meshes, POSES, 2**70, 0, 1, 1e-5),
        OverflowError,
    ),
    (
        "apart_one: a string eps",
        lambda k, m, t: m.apart_one(t.meshes, POSES, 0, 0, 1, "x"),
        TypeError,
    ),
    (
        "apart_one: poses a list",
        lambda k, m, t: m.apart_one(t.meshes, POSES.tolist(), 0, 0, 1, 1e-5),
        TypeError,
    ),
    (
        "apart_one: float32 poses",
        lambda k, m, t: m.apart_one(t.meshes, POSES.astype(np.float32), 0, 0, 1, 1e-5),
        TypeError,
    ),
    (
        "apart_one: swapped poses",
        lambda k, m, t: m.apart_one(t.meshes, POSES.astype(">f8"), 0, 0, 1, 1e-5),
        TypeError,
    ),
    (
        "apart_one: poses of one geometry",
        lambda k, m, t: m.apart_one(t.meshes, POSES[:, :1].copy(), 0, 0, 0, 1e-5),
        ValueError,
    ),
    (
        "apart_one: a geometry out of range",
        lambda k, m, t: m.apart_one(t.meshes, POSES, 0, 0, 2, 1e-5),
        ValueError,
    ),
    (
        "apart_one: eps NaN",
        lambda k, m, t: m.apart_one(t.meshes, POSES, 0, 0, 1, np.nan),
        ValueError,
    ),
    (
        "on_surface: a float geometry",
        lambda k, m, t: m.on_surface(t.meshes, POSES, 0, 1.0, np.zeros(3), 0.0),
        TypeError,
    ),
    (
        "on_surface: a string tolerance",
        lambda k, m, t: m.on_surface(t.meshes, POSES, 0, 0, np.zeros(3), "0"),
        TypeError,
    ),
    (
        "on_surface: the point a list",
        lambda k, m, t: m.on_surface(t.meshes, POSES, 0, 0, [0.0, 0, 0], 0.0),
        TypeError,
    ),
    (
        "on_surface: two values",
        lambda k, m, t: m.on_surface(t.meshes, POSES, 0, 0, np.zeros(2), 0.0),
        ValueError,
    ),
    (
        "on_surface: a negative tolerance",
        lambda k, m, t: m.on_surface(t.meshes, POSES, 0, 0, np.zeros(3), -1.0),
        ValueError,
    ),
    (
        "on_surface: a row out of range",
        lambda k, m, t: m.on_surface(t.meshes, POSES, 1, 0, np.zeros(3), 0.0),
        ValueError,
    ),
]


def _compiled() -> tuple[ModuleType, ModuleType] | None:
    """The C cores, or None where they are not built (the fallback is then checked alone)."""
    try:
        from robotspec.collision import _meshcore as mesh_c
        from robotspec.model import _kincore as kin_c
    except ImportError:
        return None
    return kin_c, mesh_c


def _raised(call: Call, kin: ModuleType, mesh: ModuleType) -> BaseException:
    t = tables(kin, mesh)
    with pytest.raises(Exception) as caught:  # the type is what is compared
        call(kin, mesh, t)
    return caught.value


@pytest.mark.parametrize(("case", "call", "kind"), CASES, ids=[c[0] for c in CASES])
def test_both_cores_refuse_alike(case: str, call: Call, kind: type[Exception]) -> None:
    fallback = _raised(call, kin_py, mesh_py)
    assert type(fallback) is kind, f"{case}: the fallback raised {fallback!r}"
    compiled = _compiled()
    if compiled is None:
        pytest.skip("the C cores are not built: only the fallback was checked")
    c = _raised(call, *compiled)
    assert (type(c), str(c)) == (type(fallback), str(fallback)), case


def test_every_entry_point_has_a_case() -> None:
    """A new entry point of either core needs its bad arguments here."""
    names = {"tree", "fk", "fk_batch", "tree_size", "chain", "chain_fk", "chain_fk_batch"}
    names |= {"chain_jacobian", "geoms", "broad", "mesh_set", "apart", "apart_one", "on_surface"}
    tested = {case.split(":")[0] for case, _, _ in CASES}
    assert tested == names
    public = {n for n in dir(kin_py) + dir(mesh_py) if not n.startswith("_") and n.islower()}
    public -= {"annotations", "dataclass", "np", "math", "any", "check_out"}
    public -= {"from_any", "index", "real", "table", "truth"}
    assert public == names, public ^ names


def test_valid_arguments_answer_alike() -> None:
    """The tables above are valid: both cores answer them (what each case then breaks)."""
    t = tables(kin_py, mesh_py)
    np.testing.assert_allclose(
        kin_py.fk(t.tree, [np.pi / 2])[2][:2, :2], [[-1, 0], [0, -1]], atol=1e-15
    )
    assert kin_py.tree_size(t.tree) == (3, 1)
    assert mesh_py.apart_one(t.meshes, POSES, 0, 0, 1, 1e-5) == 0
    compiled = _compiled()
    if compiled is not None:
        tc = tables(*compiled)
        np.testing.assert_allclose(
            compiled[0].fk(tc.tree, [0.3]), kin_py.fk(t.tree, [0.3]), rtol=0, atol=1e-15
        )
        assert compiled[1].apart_one(tc.meshes, POSES, 0, 0, 1, 1e-5) == 1  # proven apart
