"""Serve a robotspec driver over Robot Raconteur, so real clients can drive it.

Needs the optional extra: ``pip install 'robotspec[robotraconteur]'``. Modules:

* :mod:`~robotspec.service.node` -- the Robot Raconteur boundary, nodes with safe defaults
  (loopback, no discovery, state in a user folder);
* :mod:`~robotspec.service.convert` -- driver values to and from the standard robdef structures;
* :mod:`~robotspec.service.robot_service` -- the ``com.robotraconteur.robotics.robot.Robot``
  service object, an adapter over :class:`~robotspec.driver.robot_driver.RobotDriver`;
* :mod:`~robotspec.service.server` -- :class:`~robotspec.service.server.RobotServer`, which owns
  the node, the service and the driver loop;
* :mod:`~robotspec.service.calls` -- driver errors as RR exceptions, blocking calls answered
  asynchronously, the generators clients drive;
* :mod:`~robotspec.service.publisher` -- the thread that packs and sends each step's state;
* :mod:`~robotspec.service.serve` -- ``robotspec drive --sim ROBOTINFO --serve``.

Nothing here is imported by ``robotspec`` itself, and importing this package does not import
Robot Raconteur: that happens when a node is started.
"""

from __future__ import annotations
