"""Drafting a small hand-written layout in a test, as ``robotspec init`` would, valid as written.

Why one place: the draft tests build URDFs of a rule's shape (numbered links, a few joints) and
each needs the same three steps: draft the file, render the spec, check it validates.
"""

from __future__ import annotations

from pathlib import Path

from robotspec.compiler import check_spec
from robotspec.spec.draft import Draft, render_draft
from robotspec.spec.draft.run import draft_from_files


def joint_xml(
    name: str,
    parent: str,
    child: str,
    kind: str = "revolute",
    xyz: str = "0 0 0.15",
    axis: str = "0 1 0",
    mimic: str | None = None,
    multiplier: float | None = None,
    limit: tuple[float, float] = (-0.5, 0.5),
) -> str:
    """A layout's ``<joint>``: a moving one gets ``axis`` and ``limit``; ``mimic`` its leader."""
    lo, hi = limit
    moving = (
        ""
        if kind == "fixed"
        else f'<axis xyz="{axis}"/><limit lower="{lo}" upper="{hi}" effort="1" velocity="1"/>'
    )
    tag = ""
    if mimic is not None:
        times = "" if multiplier is None else f' multiplier="{multiplier}"'
        tag = f'<mimic joint="{mimic}"{times}/>'
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}"/>{moving}{tag}</joint>'
    )


def draft_layout(tmp_path: Path, name: str, parts: list[str]) -> Draft:
    """The draft of ``<robot name=NAME>`` + ``parts``, whose rendered spec must validate."""
    urdf = tmp_path / f"{name}.urdf"
    urdf.write_text(f'<robot name="{name}">' + "".join(parts) + "</robot>")
    draft, _ = draft_from_files(str(urdf), None, folder=tmp_path, base_folder=tmp_path)
    spec = tmp_path / f"{name}.yaml"
    spec.write_text(render_draft(draft))
    assert check_spec(spec).robot is not None  # valid as written
    return draft
