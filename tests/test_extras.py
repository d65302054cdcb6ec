"""Optional extras are fenced one way (robotspec/extras.py): the module, or one located error.

A missing extra is a RobotSpecError of kind ``dependency`` naming the pip package and the command
that installs it (the CLI prints it as one line, exit code 1); a present one is imported as is.
"""

from __future__ import annotations

import json

import pytest

from robotspec.errors import CollisionError, RobotSpecError
from robotspec.extras import Extra, require, require_present

#: A module that no environment has (the name is reserved for this test).
ABSENT = Extra("robotspec_absent_extra_for_tests", "robotspec-absent", "view")


def test_a_missing_extra_names_the_feature_and_the_command() -> None:
    with pytest.raises(RobotSpecError) as info:
        require(ABSENT, "--plot")
    assert str(info.value) == (
        "error: --plot needs the 'robotspec-absent' package; install it with "
        "`pip install 'robotspec[view]'`"
    )
    assert info.value.detail.kind == "dependency"
    assert info.value.detail.name == "robotspec-absent"


def test_presence_is_checked_without_importing_and_the_error_class_is_the_callers() -> None:
    bare = Extra("robotspec_absent_extra_for_tests", "absent-pkg", label="AbsentLib")
    with pytest.raises(
        CollisionError, match=r"needs AbsentLib; install it with `pip install 'absent-pkg'`"
    ):
        require_present(bare, "collision checking", CollisionError)


def test_a_present_extra_is_the_module_itself() -> None:
    assert require(Extra("json", "json"), "reading") is json
    require_present(Extra("json", "json"), "reading")
