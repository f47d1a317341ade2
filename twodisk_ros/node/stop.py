"""Signals end the ``roller`` process cleanly (standard library only).

Imported first by the entry point, before numpy, scipy and rclpy, so that a signal during
start-up is already handled.
"""

import os
import signal

__all__ = ['StopNow', 'StopRequest']


class StopNow(BaseException):
    """A second SIGINT or SIGTERM during start-up: stop the start-up work at once.

    A BaseException, as KeyboardInterrupt, so that no ``except Exception`` swallows it.
    """


class StopRequest:
    """SIGINT and SIGTERM set a flag; the loops end at a sample boundary.

    During start-up a signal ends the process at once (nothing has been recorded then):
    while the entry point still imports (before :meth:`allow_abort`) the first one sets the
    flag, which ``main`` checks before any work, and a second exits 0 on the spot, nothing
    having been created yet; from :meth:`allow_abort` to :meth:`forbid_abort` (table
    building can take seconds) the first one raises :class:`StopNow` in the main thread,
    which ``main`` catches after discarding what was built. Later a
    repeated signal changes nothing: the run still ends cleanly and the recording is
    finished. SIGXFSZ (a file-size limit) is ignored so that writing past the limit is an
    I/O error the recorder reports, not a killed process.
    """

    def __init__(self):
        self.requested = None
        self.abortable = False
        self.importing = True     # until main() starts: nothing exists that needs cleaning up
        self.install()

    def install(self):
        """(Re)install the handlers: rclpy's shutdown resets SIGINT and SIGTERM to default."""
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, self._handle)
        if hasattr(signal, 'SIGXFSZ'):
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)

    def _handle(self, signum, frame):
        name = signal.Signals(signum).name
        if self.abortable:
            # start-up work (tables can take seconds): nothing is recorded yet, so even the
            # first signal ends it at once
            self.requested = self.requested or name
            self.abortable = False      # one StopNow only: the clean-up is not cut short
            raise StopNow(name)
        if self.requested is None:
            self.requested = name
        elif self.importing:
            # the entry point is still importing numpy, scipy and rclpy: no file, no node
            # exists yet, so the process ends here, exit 0. Not SystemExit: raised inside an
            # extension module's initialisation (scipy.optimize's HiGHS) it becomes
            # "ImportError: initialization failed" with a traceback.
            self.ignore_from_now()
            os.write(2, f'roller: stopped by {self.requested} during start-up: no recording '
                        'written\n'.encode())
            os._exit(0)

    def __bool__(self):
        return self.requested is not None

    def allow_abort(self):
        """From now on a signal raises :class:`StopNow` (start-up work)."""
        self.importing = False
        self.abortable = True

    def forbid_abort(self):
        """From now on a repeated signal only keeps the flag set (the run, its clean-up)."""
        self.abortable = False

    def ignore_from_now(self):
        """Ignore further SIGINT and SIGTERM: the run is over and its recording finished.

        Python's finalization resets signals that have Python handlers to their default
        action (a SIGTERM would then kill the exiting process); ignored ones stay ignored.
        """
        self.importing = self.abortable = False
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, signal.SIG_IGN)
