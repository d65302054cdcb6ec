"""The array types of the package's signatures, named once (float64 and int64 numpy arrays).

Shapes are documented where arrays are used (``(n, 4, 4)`` poses, ``(dof,)`` configurations).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["F64", "I64"]

#: A float64 numpy array: poses, configurations, Jacobians, joint commands.
F64 = NDArray[np.float64]
#: An int64 numpy array: indices (geometry to body, pair lists).
I64 = NDArray[np.int64]
