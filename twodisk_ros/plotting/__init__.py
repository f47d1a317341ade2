"""The package's figures and animations (matplotlib), in the colours of
:mod:`twodisk_ros.model.palette`; the inspector draws its own (:mod:`twodisk_ros.inspector.figure`).

- :mod:`~twodisk_ros.plotting.figures`: the paper's figures, height of G, stability map;
- :mod:`~twodisk_ros.plotting.contact_forces`: contact forces over a cycle and against speed;
- :mod:`~twodisk_ros.plotting.sweep_maps`: the maps of ``twodisk-sweep --plot``;
- :mod:`~twodisk_ros.plotting.animation`: GIF/MP4 animations and PNG frames of a run
  (:mod:`twodisk_ros.runs`), the command line in
  :mod:`~twodisk_ros.plotting.animate_cli` (``twodisk-animate``).
"""
