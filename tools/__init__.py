"""Developer tools of the robotspec repository (not part of the package or its wheel)."""
