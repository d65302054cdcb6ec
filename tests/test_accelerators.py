"""The C accelerators against their pure-Python fallbacks, and robotspec without them.

Why: ``_kincore.c`` and ``_meshcore.c`` are optional (a user without a compiler installs
without them), so the fallbacks must give the C cores' answers on real robots (FK, frames,
Jacobians, batches, broad-phase candidates, collision answers), refuse bad arguments the same
way, and every command must run when the compiled modules cannot be imported at all.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from types import ModuleType
from typing import Any, TypeVar

import numpy as np
import pytest

from robotspec import robots
from robotspec.accel import using
from robotspec.collision import SelfCollisionChecker, meshcore, random_configurations
from robotspec.collision import _meshcore_py as mesh_py
from robotspec.errors import KinematicsError
from robotspec.model import _kincore_py as kin_py
from robotspec.model import kincore
from robotspec.model.kinematics import Kinematics
from tests.conftest import erd_robots

T = TypeVar("T")


def _compiled(name: str) -> ModuleType:
    """A compiled core, or skip: these tests compare it with its fallback."""
    if kincore.accelerators_disabled():
        pytest.skip("compares the C cores with the fallbacks; ROBOTSPEC_NO_ACCEL turns C off")
    return pytest.importorskip(name, reason=f"{name} is not built (no compiler at install)")


@pytest.fixture(scope="module")
def kin_c() -> ModuleType:
    return _compiled("robotspec.model._kincore")


@pytest.fixture(scope="module")
def mesh_c() -> ModuleType:
    return _compiled("robotspec.collision._meshcore")


@contextmanager
def _using(kin: ModuleType, mesh: ModuleType) -> Iterator[None]:
    """Run with the given cores (the dispatch's choice, restored after)."""
    with using((kincore.CHOICE, kin), (meshcore.CHOICE, mesh)):
        yield


class _Both:
    """One robot's kinematics and checker built twice: on the C cores and on the fallbacks."""

    def __init__(self, robot: Any, kin_c: ModuleType, mesh_c: ModuleType) -> None:
        self.robot = robot
        self.c = (kin_c, mesh_c)
        self.py = (kin_py, mesh_py)
        with _using(*self.c):
            self.kin_c = Kinematics(robot.world)
            self.chk_c = SelfCollisionChecker.from_robot(robot)
        with _using(*self.py):
            self.kin_py = Kinematics(robot.world)
            self.chk_py = SelfCollisionChecker.from_robot(robot)

    def both(self, fn: Callable[[Kinematics, SelfCollisionChecker], T]) -> tuple[T, T]:
        """``fn`` on the C side, then on the fallback side (each under its own cores)."""
        with _using(*self.c):
            a = fn(self.kin_c, self.chk_c)
        with _using(*self.py):
            b = fn(self.kin_py, self.chk_py)
        return a, b


@pytest.fixture(scope="module", params=["PR2", "Tiago", "B1UR5Allegro"])
def both(request: pytest.FixtureRequest, kin_c: ModuleType, mesh_c: ModuleType) -> _Both:
    erd_robots()
    return _Both(getattr(robots, request.param).load(), kin_c, mesh_c)


def _configs(both: _Both, n: int, seed: int = 0) -> np.ndarray:
    return np.asarray(random_configurations(both.robot.world, n, seed=seed), dtype=np.float64)


def test_fk_frames_and_jacobians_agree(both: _Both) -> None:
    qs = _configs(both, 12)
    chains = [(c.root.name, c.tip.name) for c in both.robot.manipulator_chains]
    assert chains
    for q in qs:
        a, b = both.both(lambda k, _, q=q: k.forward(q))
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)
        for root, tip in chains:
            a, b = both.both(lambda k, _, q=q, tip=tip: k.pose(q, tip))
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)
            a, b = both.both(lambda k, _, q=q, r=root, t=tip: k.chain(r, t).fk(q))
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)
            a, b = both.both(lambda k, _, q=q, r=root, t=tip: k.chain(r, t).jacobian(q))
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)
    root, tip = chains[0]
    a, b = both.both(lambda k, _: k.chain(root, tip).fk_batch(qs))
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)


def test_batches_agree_whatever_the_threads(both: _Both) -> None:
    qs = _configs(both, 700, seed=1)
    one, _ = both.both(lambda k, _: k.forward_batch(qs, threads=1))
    for threads in (1, 3):
        a, b = both.both(lambda k, _, n=threads: k.forward_batch(qs, threads=n))
        np.testing.assert_array_equal(a, one)  # the split never changes a bit
        np.testing.assert_allclose(b, one, rtol=0, atol=1e-12)
    out = np.full_like(one, np.nan)
    a, b = both.both(lambda k, _: k.forward_batch(qs, threads=2, out=out).copy())
    np.testing.assert_array_equal(a, one)
    np.testing.assert_allclose(b, one, rtol=0, atol=1e-12)


def test_broad_phase_keeps_the_same_candidates(both: _Both, kin_c: ModuleType) -> None:
    qs = _configs(both, 300, seed=2)
    with _using(*both.c):
        bodies = both.kin_c.forward_batch(qs)
        geoms_c = both.chk_c._build().broad
    with _using(*both.py):
        geoms_py = both.chk_py._build().broad
    n_pairs = len(both.chk_c._build().pair_geom1)
    mask = (np.arange(n_pairs) % 3 != 0).astype(np.uint8)
    for margin, m in ((0.0, None), (0.02, None), (0.01, mask)):
        rc, kc, pc = kin_c.broad(geoms_c, bodies, margin, m)
        rp, kp, pp = kin_py.broad(geoms_py, bodies, margin, m)
        assert len(rc) > 0
        np.testing.assert_array_equal(rp, rc)
        np.testing.assert_array_equal(kp, kc)
        np.testing.assert_allclose(pp, pc, rtol=0, atol=1e-15)
    rc, kc, pc = kin_c.broad(geoms_c, bodies[0], 0.0, None)  # one sample (B, 4, 4)
    rp, kp, pp = kin_py.broad(geoms_py, bodies[0], 0.0, None)
    np.testing.assert_array_equal(rp, rc)
    np.testing.assert_array_equal(kp, kc)
    assert pp.shape == pc.shape


def test_collision_answers_agree(both: _Both) -> None:
    qs = _configs(both, 50, seed=3)
    for margin in (0.0, 0.02):
        a, b = both.both(lambda _, c, m=margin: c.collisions_batch(qs, margin=m))
        np.testing.assert_array_equal(a, b)
        a, b = both.both(lambda _, c, m=margin: c.in_collision_batch(qs, margin=m))
        np.testing.assert_array_equal(a, b)
    a, b = both.both(lambda _, c: c.ever_colliding(qs))
    np.testing.assert_array_equal(a, b)
    for q in qs[:4]:
        a, b = both.both(lambda _, c, q=q: (c.in_collision(q), c.colliding_pairs(q)))
        assert a == b
    # Distances: the C core lets hull distances stand, the fallback asks coal for the meshes'.
    a, b = both.both(lambda _, c: c.distances_batch(qs[:3]))
    np.testing.assert_allclose(a, b, rtol=0, atol=2e-6)


# ------------------------------------------------------------------------ argument checks
@pytest.fixture(params=["c", "py"])
def kin(request: pytest.FixtureRequest) -> ModuleType:
    return kin_py if request.param == "py" else _compiled("robotspec.model._kincore")


@pytest.fixture(params=["c", "py"])
def mesh(request: pytest.FixtureRequest) -> ModuleType:
    return mesh_py if request.param == "py" else _compiled("robotspec.collision._meshcore")


def _tree(kin: ModuleType, parent: list[int], child: list[int], n_slots: int, n_out: int) -> object:
    n = len(parent)
    return kin.tree(
        np.array(parent, dtype=np.int64),
        np.array(child, dtype=np.int64),
        np.ones(n, dtype=np.int64),
        np.tile(np.eye(4), (n, 1, 1)),
        np.tile([0.0, 0.0, 1.0], (n, 1)),
        np.zeros(n, dtype=np.int64),
        np.ones(n),
        np.zeros(n),
        n_slots,
        n_out,
        1,
    )


def test_tree_programs_that_would_corrupt_memory_are_refused(kin: ModuleType) -> None:
    with pytest.raises(ValueError, match="counts out of range"):
        _tree(kin, [0], [1], 2, 0)  # no output slot: the root pose was written past the end
    with pytest.raises(ValueError, match="counts out of range"):
        _tree(kin, [0], [1], 1000, 2)  # scratch slots no row writes
    with pytest.raises(ValueError, match="before a row writes it"):
        _tree(kin, [2, 0], [1, 2], 3, 3)
    with pytest.raises(ValueError, match="unset"):
        _tree(kin, [0], [1], 3, 3)
    with pytest.raises(ValueError, match="out of range"):
        kin.chain(np.zeros((0, 4, 4)), np.eye(4), [], [], [], [], [], [], -1, 1)
    fixed = kin.tree([0], [1], [0], np.eye(4)[None], np.zeros((1, 3)), [0], [0.0], [0.0], 2, 2, 0)
    np.testing.assert_array_equal(kin.fk(fixed, np.zeros(0)), np.tile(np.eye(4), (2, 1, 1)))
    t = _tree(kin, [0, 1], [1, 2], 3, 3)
    assert kin.tree_size(t) == (3, 1)
    np.testing.assert_allclose(kin.fk(t, [np.pi / 2])[2][:2, :2], [[-1, 0], [0, -1]], atol=1e-15)


def test_foreign_byte_order_is_converted_or_refused(kin: ModuleType) -> None:
    t = _tree(kin, [0, 1], [1, 2], 3, 3)
    q = np.array([[0.3], [-1.2]])
    want = kin.fk_batch(t, q)
    np.testing.assert_array_equal(kin.fk_batch(t, q.astype(">f8")), want)  # read as numbers
    np.testing.assert_allclose(kin.fk(t, q[0].astype(">f8")), want[0], rtol=0, atol=1e-15)
    swapped = np.zeros(want.shape, dtype=">f8")
    with pytest.raises(TypeError, match="native-order"):
        kin.fk_batch(t, q, swapped, True)
    buf = np.zeros(want.size * 8 + 1, dtype=np.uint8)
    unaligned = buf[1:].view(np.float64).reshape(want.shape)
    assert not unaligned.flags.aligned
    with pytest.raises(TypeError, match="aligned"):
        kin.fk_batch(t, q, unaligned, True)
    with pytest.raises(ValueError, match="out must be"):
        kin.fk_batch(t, q, np.zeros((3, 3, 4, 4)), True)


def test_mesh_arguments_are_checked_alike(mesh: ModuleType) -> None:
    v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    f = np.array([[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])
    s = mesh.mesh_set([(v, f), (v + 5.0, f)])
    poses = np.array([[np.eye(4), np.eye(4)]])
    assert mesh.apart_one(s, poses, 0, 0, 1, 1e-5) in (0, 1)
    with pytest.raises(TypeError, match="native-order"):
        mesh.apart_one(s, poses.astype(">f8"), 0, 0, 1, 1e-5)
    with pytest.raises(TypeError, match="native-order"):
        mesh.on_surface(s, poses, 0, 0, np.zeros(3, dtype=">f8"), 1e-9)
    buf = np.zeros(poses.size * 8 + 1, dtype=np.uint8)
    unaligned = buf[1:].view(np.float64).reshape(poses.shape)
    with pytest.raises(TypeError, match="aligned"):
        mesh.on_surface(s, unaligned, 0, 0, np.zeros(3), 1e-9)
    with pytest.raises(TypeError, match="float64"):
        mesh.apart_one(s, poses.astype(np.float32), 0, 0, 1, 1e-5)
    with pytest.raises(ValueError, match="wrong shape"):
        mesh.apart_one(s, poses[:, :1].copy(), 0, 0, 1, 1e-5)
    with pytest.raises(ValueError, match="out of range"):
        mesh.apart_one(s, poses, 1, 0, 1, 1e-5)
    with pytest.raises(ValueError, match="eps"):
        mesh.apart(s, poses, [0], [0], [0], [1], 0.0)
    with pytest.raises(TypeError, match="vertices, triangles"):
        mesh.mesh_set([[v, f]])
    with pytest.raises(ValueError, match="out of range"):
        mesh.mesh_set([(v, f + 4)])
    assert mesh.apart(s, poses, [0], [0], [0], [1], 1e-5).dtype == np.uint8


_FAILING_CALLOC = r"""
#include <stdlib.h>
#include <string.h>
/* calloc, except that (12347, sizeof(void *)) fails: mesh_set's table of 12347 trees. */
void *calloc(size_t n, size_t size) {
    if (n == 12347 && size == sizeof(void *)) return NULL;
    if (size != 0 && n > (size_t)-1 / size) return NULL;
    void *p = malloc(n * size);
    if (p != NULL) memset(p, 0, n * size);
    return p;
}
"""


def test_mesh_set_survives_a_failed_allocation(mesh_c: ModuleType, tmp_path: Path) -> None:
    """An allocation failure is a MemoryError (it freed the set twice: a crash)."""
    cc = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    if not sys.platform.startswith("linux") or cc is None:
        pytest.skip("needs Linux (LD_PRELOAD) and a C compiler to inject the failure")
    (tmp_path / "shim.c").write_text(_FAILING_CALLOC)
    shim = tmp_path / "shim.so"
    subprocess.run([cc, "-shared", "-fPIC", "-o", str(shim), str(tmp_path / "shim.c")], check=True)
    code = (
        "from robotspec.collision import _meshcore\n"
        "try:\n"
        "    _meshcore.mesh_set([None] * 12347)\n"
        "except MemoryError:\n"
        "    print('MemoryError')\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "LD_PRELOAD": str(shim)},
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "MemoryError"


def test_a_batch_split_over_threads_checks_everything_first() -> None:
    erd_robots()
    w = robots.PR2.load().world
    k = Kinematics(w)
    qs = np.zeros((64, len(w.degrees_of_freedom)))
    qs[-1, 0] = np.nan  # in the last slice
    out = np.full((64, len(w.bodies), 4, 4), 7.0)
    with pytest.raises(ValueError, match="NaN"):
        kincore.fk_batch(k._tree, qs, 4, out)
    assert (out == 7.0).all()  # no slice ran
    with pytest.raises(ValueError, match="threads"):
        kincore.fk_batch(k._tree, qs, 65)
    # The public call names the array at fault (not the configuration the core was given).
    buf = np.zeros(out.size * 8 + 1, dtype=np.uint8)
    for bad in (out.astype(">f8"), buf[1:].view(np.float64).reshape(out.shape)):
        with pytest.raises(KinematicsError, match="out must be a writeable, aligned"):
            k.forward_batch(np.zeros_like(qs), out=bad)


# ---------------------------------------------------------------------- without the C cores
_WITHOUT_C = (
    "import sys, runpy; "
    "sys.modules['robotspec.model._kincore'] = None; "
    "sys.modules['robotspec.collision._meshcore'] = None; "
    "sys.argv = ['robotspec', *sys.argv[1:]]; "
    "runpy.run_module('robotspec', run_name='__main__')"
)


@pytest.mark.parametrize("args", [["validate", "pr2"], ["inspect", "chains", "pr2"]])
def test_commands_run_without_the_compiled_modules(args: list[str]) -> None:
    erd_robots()
    done = subprocess.run(
        [sys.executable, "-c", _WITHOUT_C, *args], capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "ImportError" not in done.stdout + done.stderr


def test_queries_fall_back_when_the_compiled_modules_are_missing() -> None:
    erd_robots()
    code = (
        "import sys; "
        "sys.modules['robotspec.model._kincore'] = None; "
        "sys.modules['robotspec.collision._meshcore'] = None; "
        "import numpy as np; "
        "from robotspec.robots import PR2; "
        "from robotspec.collision import SelfCollisionChecker, meshcore; "
        "from robotspec.model import kincore; "
        "r = PR2.load(); c = SelfCollisionChecker.from_robot(r); "
        "q = np.zeros(len(r.world.degrees_of_freedom)); "
        "print(c.in_collision(q), c.kinematics.forward(q).shape[0] == len(r.world.bodies), "
        "kincore.accelerated(), meshcore.accelerated())"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["False", "True", "False", "False"]


def test_the_switch_turns_the_accelerators_off(kin_c: ModuleType, mesh_c: ModuleType) -> None:
    code = (
        "from robotspec.model import kincore; from robotspec.collision import meshcore; "
        "print(kincore.accelerated(), meshcore.accelerated())"
    )
    for env, want in (("1", "False False"), ("0", "True True"), ("", "True True")):
        done = subprocess.run(
            [sys.executable, "-c", code],
            capture_output=True,
            text=True,
            timeout=120,
            env={**os.environ, kincore.NO_ACCEL_ENV: env},
            check=True,
        )
        assert done.stdout.strip() == want, env
