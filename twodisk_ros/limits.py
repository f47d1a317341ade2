"""How much memory a command may use, and sizes in words (standard library only).

The commands that can be asked for runaway work (``twodisk-sweep`` with a huge grid,
``twodisk-animate`` with a huge span) estimate the memory a request needs *before* allocating
anything and refuse, in one line, what exceeds :func:`memory_limit`: half of the physical
memory of the machine (``os.sysconf``), or half of the process's address-space limit
(``RLIMIT_AS``, ``ulimit -v``) when that is lower. Half, because the estimates are rough
(measured peaks, see each command's constants) and the machine runs other things too.
"""

import math
import os

__all__ = ['LimitError', 'memory_limit', 'describe_bytes', 'check_memory']

#: The share of the machine's (or the address-space limit's) memory a request may need.
MEMORY_SHARE = 0.5


class LimitError(ValueError):
    """A request that needs more memory or work than allowed; the message is one line."""


def _physical_memory():
    """Bytes of physical memory, or None if the system does not say."""
    try:
        pages, size = os.sysconf('SC_PHYS_PAGES'), os.sysconf('SC_PAGE_SIZE')
    except (AttributeError, ValueError, OSError):
        return None
    return pages * size if pages > 0 and size > 0 else None


def _address_space_limit():
    """The soft RLIMIT_AS in bytes, or None if unlimited or unknown."""
    try:
        import resource
        soft = resource.getrlimit(resource.RLIMIT_AS)[0]
    except (ImportError, AttributeError, OSError, ValueError):
        return None
    return None if soft == resource.RLIM_INFINITY or soft <= 0 else soft


def memory_limit():
    """(bytes a request may need, one-line reason): see the module docstring."""
    physical = _physical_memory()
    address = _address_space_limit()
    if address is not None and (physical is None or address < physical):
        return (int(MEMORY_SHARE * address),
                f'half of the address-space limit of {describe_bytes(address)}')
    if physical is not None:
        return (int(MEMORY_SHARE * physical),
                f'half of the {describe_bytes(physical)} of memory of this machine')
    fallback = 4 * 2**30
    return fallback, f'{describe_bytes(fallback)} (the memory of this machine is unknown)'


def describe_bytes(count):
    """``count`` bytes in words: '512 B', '3.2 MiB', '74.5 GiB', '1.46 TiB'."""
    count = float(count)
    if not math.isfinite(count):
        return 'an unbounded amount'
    for unit in ('B', 'KiB', 'MiB', 'GiB', 'TiB', 'PiB'):
        if count < 1024 or unit == 'PiB':
            if unit == 'B':
                return f'{count:.0f} B'
            return f'{count:.3g} {unit}'
        count /= 1024
    return f'{count:.3g} PiB'   # pragma: no cover (the loop returns)


def check_memory(needed, what):
    """Raise :class:`LimitError` if ``needed`` bytes exceed :func:`memory_limit`.

    ``what`` describes the request (e.g. 'the grid of 10 × 10 bodies'); the message says
    how much it would need and what is allowed.
    """
    limit, reason = memory_limit()
    if needed > limit:
        raise LimitError(f'{what} would need ~{describe_bytes(needed)} of memory; allowed: '
                         f'{describe_bytes(limit)} ({reason})')
