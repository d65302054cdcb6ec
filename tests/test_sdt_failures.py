"""SDT's own failures while it builds a world are reported as SDT's, naming the file.

An empty mesh (a real STL file with no triangles, which robotspec loads) gives SDT's V-HACD
decomposition nothing, and SDT then fails to export no parts. The CLI must say that, with the
mesh's path, and exit 1, not call it a bug in robotspec. SDT caches a mesh before it
decomposes it, so a second run would not fail: the child process gets a cache folder of its
own (``XDG_CACHE_HOME``) and the failure is the same on every run.
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

from tests.sdt_support import STAND_INS, require_sdt

#: Bound on a child process that imports SDT (seconds at rest, much more on a loaded machine);
#: it only catches a hang.
CHILD_WAIT = 600

URDF = """<robot name="flat">
  <link name="base"><collision><geometry><mesh filename="empty.stl"/></geometry></collision></link>
</robot>
"""


def test_a_mesh_sdt_cannot_decompose_is_named_with_sdts_step(tmp_path: Path) -> None:
    require_sdt()
    (tmp_path / "empty.stl").write_text("solid empty\nendsolid empty\n", encoding="ascii")
    (tmp_path / "flat.urdf").write_text(URDF, encoding="utf-8")
    env = dict(os.environ, XDG_CACHE_HOME=str(tmp_path / "cache"))
    real = importlib.util.find_spec("giskardpy")
    if real is None or str(real.origin).startswith(str(STAND_INS)):
        env["PYTHONPATH"] = str(STAND_INS)  # SDT imports giskardpy's one helper (docs/sdt.md)
    code = (
        "import sys; from robotspec.cli import main; "
        "sys.exit(main(['migrate', 'sdt', 'semantic_digital_twin.robots.pr2:PR2', "
        "'--urdf', 'flat.urdf']))"
    )
    child = subprocess.run(
        [sys.executable, "-c", code],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=CHILD_WAIT,
        check=False,
    )
    err = child.stderr
    assert child.returncode == 1, err
    assert "bug in robotspec" not in err and "Traceback" not in err
    mesh = (tmp_path / "empty.stl").resolve()
    assert (
        f"error: SDT's convex decomposition (VHACDMeshDecomposer) of mesh '{mesh}' (0 faces) "
        "failed with ValueError: Can't export empty scenes!; fix or replace the mesh (SDT has "
        f"already cached it undecomposed as {tmp_path / 'cache'}/semantic_digital_twin/"
        "convex_decompositions/"
    ) in err.replace("\n", " ")
