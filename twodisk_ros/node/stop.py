"""Signals end the ``roller`` process cleanly: they only set a flag (standard library only).

Imported first by the entry point, before numpy, scipy and rclpy, so that a signal during
start-up is already handled.
"""

import signal

__all__ = ['StopRequest']


class StopRequest:
    """SIGINT and SIGTERM set a flag and nothing else; the loops end at a sample boundary.

    A repeated signal, also during start-up or while the recording is being finished,
    changes nothing: the run still ends cleanly. SIGXFSZ (a file-size limit) is ignored so
    that writing past the limit is an I/O error the recorder reports, not a killed process.
    """

    def __init__(self):
        self.requested = None
        self.install()

    def install(self):
        """(Re)install the handlers: rclpy's shutdown resets SIGINT and SIGTERM to default."""
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, self._handle)
        if hasattr(signal, 'SIGXFSZ'):
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)

    def _handle(self, signum, frame):
        self.requested = signal.Signals(signum).name

    def __bool__(self):
        return self.requested is not None

    def ignore_from_now(self):
        """Ignore further SIGINT and SIGTERM: the run is over and its recording finished.

        Python's finalization resets signals that have Python handlers to their default
        action (a SIGTERM would then kill the exiting process); ignored ones stay ignored.
        """
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, signal.SIG_IGN)
