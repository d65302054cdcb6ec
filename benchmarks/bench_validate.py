"""What the kinematic and cross-part checks cost validate, against the compile without them.

robotspec: ``check_spec("pr2")`` (what ``robotspec validate pr2`` runs after its imports) with
every check; peer: the same call with ``check_kinematics`` and ``check_parts`` replaced by no-ops
(the compiler as it was before issue 16). Calls take turns, so a slow spell of this shared machine
hits both sides alike. Also: the wall time of the whole ``robotspec validate pr2`` command (a new
process each time: interpreter start and imports included), with and without the checks.
Target: ``validate pr2`` stays under 1.5 times its time without the kinematic checks.

Run: ``python benchmarks/bench_validate.py [--repeat N]`` (needs example-robot-data). Prints
medians and the ratio without / with the checks (below 1: the checks cost time).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from collections.abc import Callable

from rows import Row, add_json_flag, median_times, print_rows

_NO_CHECKS = """
import sys
import robotspec.compiler.build as build
build.check_kinematics = lambda *a, **k: None
build.check_parts = lambda *a, **k: None
from robotspec.cli.app import main
main(sys.argv[1:])
"""
_WITH_CHECKS = "import sys\nfrom robotspec.cli.app import main\nmain(sys.argv[1:])\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=15)
    add_json_flag(parser)
    args = parser.parse_args()
    say = (lambda *a, **k: None) if args.json else print

    import robotspec.compiler.build as build
    from robotspec.compiler import check_spec

    kinematic, parts = build.check_kinematics, build.check_parts

    def with_checks() -> None:
        build.check_kinematics, build.check_parts = kinematic, parts
        check_spec("pr2")

    def without_checks() -> None:
        build.check_kinematics = lambda *a, **k: None  # type: ignore[assignment]
        build.check_parts = lambda *a, **k: None  # type: ignore[assignment]
        check_spec("pr2")

    new, old = median_times([with_checks, without_checks], args.repeat)
    build.check_kinematics, build.check_parts = kinematic, parts
    say(
        f"compile pr2 (validate's work): with checks {new * 1e3:.1f} ms, without "
        f"{old * 1e3:.1f} ms, ratio {old / new:.2f}"
    )

    env = {**os.environ, "NO_COLOR": "1"}

    def cli(code: str) -> Callable[[], object]:
        return lambda: subprocess.run(
            [sys.executable, "-c", code, "validate", "pr2"],
            check=True,
            capture_output=True,
            env=env,
        )

    rounds = max(3, args.repeat // 3)
    new_cli, old_cli = median_times([cli(_WITH_CHECKS), cli(_NO_CHECKS)], rounds)
    say(
        f"robotspec validate pr2 (new process): with checks {new_cli:.2f} s, without "
        f"{old_cli:.2f} s, ratio {old_cli / new_cli:.2f}"
    )
    if args.json:
        print_rows(
            [
                Row("compile pr2 as validate does, with the checks", new, "without them", old),
                Row(
                    "robotspec validate pr2, a new process", new_cli, "without the checks", old_cli
                ),
            ],
            True,
        )


if __name__ == "__main__":
    main()
