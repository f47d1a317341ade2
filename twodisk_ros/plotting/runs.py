"""Moved to :mod:`twodisk_ros.runs` (runs are loaded and simulated there; nothing here plots).

Kept so that ``from twodisk_ros.plotting.runs import ...`` keeps working.
"""

from ..runs import (LIBRARY_RATE, Run, RunError, library_run, recorded_run,  # noqa: F401
                    rotation_matrices, settings_from)

__all__ = ['LIBRARY_RATE', 'Run', 'RunError', 'library_run', 'recorded_run', 'settings_from',
           'rotation_matrices']
