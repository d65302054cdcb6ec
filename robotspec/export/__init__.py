"""Writers of other tools' formats: one URDF, MoveIt SRDF, Robot Raconteur RobotInfo."""
