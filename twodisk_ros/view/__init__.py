"""``twodisk-view``: a live 3D view of the rolling body in Foxglove, without ROS.

The library's motion in real time (the node's parameters) or a recording of the node,
served over the Foxglove WebSocket protocol by ``foxglove-sdk`` (subprotocol
``foxglove.sdk.v1``). Nothing here imports rclpy or matplotlib.

- :mod:`~twodisk_ros.view.sources`: the samples: :class:`LiveSource` (the node's
  :class:`~twodisk_ros.run.simulation.Simulation`, block by block) and
  :class:`ReplaySource` (a recording, as recorded);
- :mod:`~twodisk_ros.view.scene`: samples → Foxglove messages (frame transforms, the body's
  mesh and rims, the contact segment, the force arrows, the traces);
- :mod:`~twodisk_ros.view.server`: the WebSocket server, its channels and parameters;
- :mod:`~twodisk_ros.view.player`: the loop that shows each sample when it is due;
- :mod:`~twodisk_ros.view.cli`: the command line and its exit codes.
"""
