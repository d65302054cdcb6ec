"""xacro tags written without their prefix (``<macro>``), as ROS 1's xacro read them.

Why: ROS 1's xacro accepted ``<macro>``, ``<property>``, ``<include>``, ``<insert_block>``,
``<if>`` and ``<unless>`` without the ``xacro:`` prefix (with a deprecation warning) unless
``--xacro-ns`` was given, and descriptions written for it are still shipped (TRI's
``hsr_description``: ``<macro name="hsrb_position_joint_transmission" ...>``). The xacro on
PyPI reads them as plain XML and fails on the first ``${...}`` inside one. A document that
declares the xacro namespace gets these six tags prefixed before xacro parses it, which is what
ROS 1's xacro did with them; nothing else in the text changes.
"""

from __future__ import annotations

import re

__all__ = ["prefix_legacy_tags"]

#: The xacro tags ROS 1's xacro read without a prefix (no URDF or Gazebo tag has these names).
_TAG = re.compile(rb"<(/?)(macro|property|include|insert_block|if|unless)(?=[\s/>])")


def prefix_legacy_tags(data: bytes) -> bytes:
    """``data`` with unprefixed xacro tags prefixed, when it declares the xacro namespace."""
    if b"xmlns:xacro" not in data:
        return data
    return _TAG.sub(rb"<\1xacro:\2", data)
