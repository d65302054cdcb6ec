"""Robots handed to other libraries (pinocchio), built from the world model."""
