"""The results of an inspection: checks with values and tolerances, the verdict
(:mod:`~twodisk_ros.inspector.status`), the report.
"""

from dataclasses import dataclass, field
import math

import numpy as np

from .status import EXIT_STATUS, EXIT_UNUSABLE, FAIL, INCOMPLETE, PASS

__all__ = ['Check', 'EXIT_STATUS', 'EXIT_UNUSABLE', 'FAIL', 'INCOMPLETE', 'Inspection', 'PASS',
           'json_ready']


@dataclass
class Check:
    """One check: a value compared with a tolerance.

    Attributes
    ----------
    name : str
        Short identifier (``'ground'``, ``'no_slip'``, ...).
    title : str
        What is checked, in words.
    passed : bool
    value, tolerance : float or None
        The measured value and the largest allowed; None if it could not be evaluated.
    unit : str
        Unit of both (``''`` for relative values).
    detail : list of str
        How it was measured (where the worst sample is, the estimated FD error, ...).
    """

    name: str
    title: str
    passed: bool
    value: float | None
    tolerance: float | None
    unit: str = ''
    detail: list = field(default_factory=list)

    @property
    def status(self):
        """``'PASS'`` or ``'FAIL'``."""
        return 'PASS' if self.passed else 'FAIL'

    def as_dict(self):
        """The check as a JSON-ready dict."""
        return {'name': self.name, 'title': self.title, 'status': self.status,
                'passed': bool(self.passed), 'value': json_ready(self.value),
                'tolerance': json_ready(self.tolerance), 'unit': self.unit,
                'detail': list(self.detail)}


@dataclass
class Inspection:
    """Summary, checks and the series used for plots of one recording.

    Attributes
    ----------
    summary : dict
        JSON-ready: file, truncation, duration, topics, parameters, samples, and ``run``
        (:func:`~twodisk_ros.inspector.completeness.run_completeness`: the share of the run
        recovered).
    checks : list of Check
    series : dict of str to numpy.ndarray
        Time series for :func:`twodisk_ros.inspector.figure.plot_inspection` (times in s
        from the first stamp).
    samples : Samples or None
        The joined samples (:func:`~twodisk_ros.inspector.series.join_samples`).
    sources : dict of str to Series
        The recorded series by role (``'pose'``, ``'wrench_a'``, ...), for the export.
    """

    summary: dict
    checks: list
    series: dict = field(default_factory=dict)
    samples: object = None
    sources: dict = field(default_factory=dict)

    @property
    def passed(self):
        """True if every check passed (on what was recovered: see :attr:`verdict`)."""
        return bool(self.checks) and all(check.passed for check in self.checks)

    @property
    def complete(self):
        """True if the run is all there (summaries without ``run`` count as complete)."""
        return bool(self.summary.get('run', {}).get('complete', True))

    @property
    def verdict(self):
        """``'PASS'``, ``'FAIL'`` (a check fails) or ``'INCOMPLETE'`` (checks pass, run cut)."""
        if not self.passed:
            return FAIL
        return PASS if self.complete else INCOMPLETE

    @property
    def exit_status(self):
        """0 PASS, 1 FAIL, 4 INCOMPLETE (:data:`EXIT_STATUS`)."""
        return EXIT_STATUS[self.verdict]

    def as_dict(self):
        """One JSON-ready document: summary, checks, verdict and exit status.

        ``passed`` is True only for the verdict PASS; ``checks_passed`` says whether every
        check passed on what was recovered.
        """
        return {'summary': self.summary, 'checks': [c.as_dict() for c in self.checks],
                'verdict': self.verdict, 'passed': self.verdict == PASS,
                'checks_passed': self.passed, 'complete': self.complete,
                'exit_status': self.exit_status}


def json_ready(value):
    """A JSON-ready copy: numpy scalars and arrays as Python, NaN and infinities as None."""
    if isinstance(value, dict):
        return {str(k): json_ready(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [json_ready(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        value = float(value)
        return value if math.isfinite(value) else None
    return value
