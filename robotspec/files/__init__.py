"""Safe file readers: YAML with line marks, XML without entities, packages, xacro, meshes.

Nothing here knows about robots; every reader refuses what could reach outside the allowed roots.
"""
