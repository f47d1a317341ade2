"""Every figure of the package (matplotlib); nothing else imports matplotlib.

- :mod:`~twodisk_ros.plotting.palette`: the colours of every picture and of the markers
  (plain hex strings, no matplotlib);
- :mod:`~twodisk_ros.plotting.figures`: the paper's figures, height of G, stability map;
- :mod:`~twodisk_ros.plotting.contact_forces`: contact forces over a cycle and against speed;
- :mod:`~twodisk_ros.plotting.sweep_maps`: the maps of ``twodisk-sweep --plot``;
- :mod:`~twodisk_ros.plotting.inspection`: the figure of ``twodisk-inspect --plot``;
- :mod:`~twodisk_ros.plotting.animation`: GIF/MP4 animations and PNG frames of a run
  (:mod:`twodisk_ros.runs`), the command line in
  :mod:`~twodisk_ros.plotting.animate_cli` (``twodisk-animate``).
"""
