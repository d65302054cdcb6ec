"""The ``robotspec`` command line.

One typer app; each command group lives in its own module and imports the library inside the
command function, so ``robotspec --help`` starts fast. Errors of the package's hierarchy are
rendered here and only here (``file:line:col: error: message``), with exit code 1; typer's usage
errors keep exit code 2.
"""

from __future__ import annotations

from robotspec.cli.app import app, main

__all__ = ["app", "main"]
