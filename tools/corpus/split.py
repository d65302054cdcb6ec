"""Which half of the blind corpus a robot belongs to: decided once, at random, before any truth.

Why a salted hash and not a list: robots join the corpus one source at a time, and each must
fall into a half that nobody chose and that never changes. The salt below was drawn once
(``secrets.token_hex(16)``) and committed before the first truth file was written; a robot's
half is the first bit of ``sha256(salt:id)``. Changing the salt re-deals the halves and voids
every measurement on the held-out half: never change it.

    python -m tools.corpus.split ROBOT_ID ...     # prints each id's half

``tune``: the drafter may be tuned on these robots (their drafts may be looked at).
``holdout``: nobody looks at their drafts until a measurement; they are scored, never tuned on.
"""

from __future__ import annotations

import hashlib
import sys

__all__ = ["SALT", "half"]

#: Drawn once, 2026-11-27, before any truth of the blind corpus was written. Never change it.
SALT = "eb08eb32c45bf9ae4ab129f8b8efa586"


def half(robot_id: str) -> str:
    """``"tune"`` or ``"holdout"``, fixed for ``robot_id`` by the salt."""
    digest = hashlib.sha256(f"{SALT}:{robot_id}".encode()).digest()
    return "tune" if digest[0] < 128 else "holdout"


def main(argv: list[str]) -> int:
    for robot_id in argv:
        sys.stdout.write(f"{robot_id}\t{half(robot_id)}\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
