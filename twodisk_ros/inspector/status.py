"""The verdicts of an inspection and the exit status of ``twodisk-inspect`` (no imports).

``PASS`` (0)
    every check passes and the run is all there (a run stopped early by a signal, whose file
    the node closed, is all there: :mod:`~twodisk_ros.inspector.completeness`);
``FAIL`` (1)
    a check fails (whatever else: it takes precedence);
``INCOMPLETE`` (4)
    every check passes on what was recovered, but the run is not all there: the file is cut
    (no footer) or damaged, or samples are missing inside it;

and exit status 2 (:data:`EXIT_UNUSABLE`) for a file that cannot be read, bad arguments, or
an output refused or that cannot be written. Light, so that the command line answers bad
arguments before it imports numpy.
"""

__all__ = ['EXIT_STATUS', 'EXIT_UNUSABLE', 'FAIL', 'INCOMPLETE', 'PASS', 'PROG']

#: The command's name, the prefix of every line it writes to stderr.
PROG = 'twodisk-inspect'
PASS, FAIL, INCOMPLETE = 'PASS', 'FAIL', 'INCOMPLETE'
#: Exit status of ``twodisk-inspect`` for each verdict.
EXIT_STATUS = {PASS: 0, FAIL: 1, INCOMPLETE: 4}
#: Exit status for a file that cannot be read, bad arguments or an output refused.
EXIT_UNUSABLE = 2
