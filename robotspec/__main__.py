"""``python -m robotspec`` runs the command line."""

from __future__ import annotations

from robotspec.cli import main

if __name__ == "__main__":
    main()
