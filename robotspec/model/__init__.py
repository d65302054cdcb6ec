"""The world model: bodies, connections, DOFs, limits, geometry and kinematics.

It knows no file format; descriptions build it, semantic objects are views over it.
"""
