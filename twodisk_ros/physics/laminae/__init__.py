"""The planar laminae a body is made of, each in its own plane.

See docs/physics.md#laminae-other-than-ellipses. :mod:`.shapes` holds the lamina protocol
(support function, boundary, curvature) and the ellipse, the superellipse and the egg;
:mod:`.fit` turns a user's outline into a smooth, strictly convex, symmetric lamina;
:mod:`.phase_map` re-spaces a lamina's boundary parameter for the regular phase used by the
motion. Nothing here knows about the second lamina, the ground or time.
"""
