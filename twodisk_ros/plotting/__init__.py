"""Every figure of the package (matplotlib); nothing else imports matplotlib.

- :mod:`~twodisk_ros.plotting.figures`: the paper's figures, height of G, stability map;
- :mod:`~twodisk_ros.plotting.inspection`: the figure of ``twodisk-inspect --plot``.
"""
