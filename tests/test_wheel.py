"""An installed wheel carries both C cores, on the limited API, and they answer.

Why: CI's wheel stage (``.ci/wheel``) builds the wheel, repairs it to a manylinux tag, installs
it into a fresh environment with ``CC=false`` (no compiler could have built anything there) and
runs these tests with ``ROBOTSPEC_EXPECT_WHEEL=1``, from a copy of the tests outside the
checkout so that ``import robotspec`` finds the installed package. Anywhere else they skip:
an editable install's cores are not the wheel's.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

#: Set by CI's wheel stage, in the environment the wheel was installed into.
EXPECT_WHEEL_ENV = "ROBOTSPEC_EXPECT_WHEEL"

pytestmark = pytest.mark.skipif(
    os.environ.get(EXPECT_WHEEL_ENV) != "1",
    reason=f"checks an installed wheel; CI's wheel stage sets {EXPECT_WHEEL_ENV}=1 (.ci/wheel)",
)


def test_robotspec_comes_from_the_installed_wheel() -> None:
    import robotspec

    where = Path(robotspec.__file__).resolve()
    assert "site-packages" in where.parts, where


def test_both_cores_are_stable_abi_builds_that_answer() -> None:
    from robotspec import accel

    rows = accel.report()
    assert accel.accelerated(), rows
    for row in rows:
        loaded = row.reason.removeprefix("loaded from ")
        assert loaded.endswith(".abi3.so") or loaded.endswith(".pyd"), row
        assert "site-packages" in Path(loaded).parts, row


def test_doctor_requires_the_c_cores_and_finds_them() -> None:
    done = subprocess.run(
        [sys.executable, "-m", "robotspec", "doctor", "--require-c"],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "fallback" not in done.stdout
