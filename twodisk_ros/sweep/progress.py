"""The progress of a sweep as a tqdm bar, and its summary line.

The bar counts bodies (resumed ones included from the start, so the rate and the time left
are this run's; counts in k and M from 100 000 bodies on), on the given stream only when that
stream is a terminal: in a log file or a pipe a redrawn bar is noise, so there the sweep is
silent until its summary.
"""

from tqdm import tqdm

__all__ = ['SweepProgress', 'summary_line']


class SweepProgress:
    """A tqdm bar over ``total`` bodies, ``done`` of them already (resumed).

    Parameters
    ----------
    stream : file or None
        Where to draw (None, or a stream that is not a terminal: no bar at all).
    total, done : int
        Bodies of the sweep, and those taken from the resume state.
    """

    def __init__(self, stream, total, done=0):
        tty = stream is not None and bool(getattr(stream, 'isatty', lambda: False)())
        self.bar = tqdm(total=total, initial=done, unit='body', unit_scale=total >= 100_000,
                        desc='twodisk-sweep', file=stream, disable=not tty, smoothing=0.05,
                        dynamic_ncols=True, leave=True)

    def update(self, bodies):
        """``bodies`` more are done."""
        self.bar.update(bodies)

    def close(self):
        self.bar.close()


def summary_line(run):
    """One line for the end of a sweep: what was written, bodies, masked, time and rate.

    ``run`` is a :class:`~twodisk_ros.sweep.run.SweepRun`."""
    rate = run.bodies_computed / run.seconds if run.seconds > 0 else float('nan')
    where = f'wrote {run.output}' if run.output else 'computed'
    return (f'{where} ({run.bodies} bodies, {run.masked} masked; {run.computed} chunks '
            f'computed, {run.resumed} resumed; {run.seconds:.1f} s, {rate:.1f} bodies/s)')
