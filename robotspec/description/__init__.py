"""Robot description files (URDF, SRDF) read once into the world model, with line numbers."""
