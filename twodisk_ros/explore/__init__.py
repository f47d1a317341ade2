"""``twodisk-explore``: the family in a browser (a viser page), no ROS needed.

- :mod:`~twodisk_ros.explore.motion`: the node's run from its settings (restarted on every
  accepted change, refused with the node's reason otherwise) or a recording; no viser here;
- :mod:`~twodisk_ros.explore.scene3d`: the body, ground, traces, contact segment and force
  arrows as viser scene nodes;
- :mod:`~twodisk_ros.explore.page`: the controls, plots and the paced loop;
- :mod:`~twodisk_ros.explore.client`: viser's client served with a script of its own (in
  software GL, WebGL without multisampling);
- :mod:`~twodisk_ros.explore.cli`: the command (serve, replay, ``--export``).
"""
