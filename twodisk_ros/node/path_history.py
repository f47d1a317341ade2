"""The recent samples the node's ``path_a``, ``path_b``, ``path_g`` topics are drawn from."""

import numpy as np

__all__ = ['PathHistory']


class PathHistory:
    """The last ``length`` samples of A, B and G (stamps in ns, world positions in m)."""

    def __init__(self, length):
        self.length = length
        self.clear()

    def clear(self):
        self._stamps = np.zeros(0, dtype=np.int64)
        self._points = {key: np.zeros((0, 3)) for key in 'abg'}

    def tail(self, key, stamps, points):
        """The last ``length`` stamps and points of ``key`` followed by the given ones."""
        n = self.length
        return (np.concatenate([self._stamps, stamps])[-n:],
                np.concatenate([self._points[key], points])[-n:])

    def extend(self, stamps, a, b, g):
        self._stamps = np.concatenate([self._stamps, stamps])[-self.length:]
        for key, points in zip('abg', (a, b, g)):
            self._points[key] = np.concatenate([self._points[key], points])[-self.length:]
