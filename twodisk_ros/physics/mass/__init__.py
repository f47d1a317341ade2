"""Mass models: where the mass of a body is and its inertia about G.

See docs/physics.md#mass-models. :mod:`.models` builds the mass properties of each model
(two laminae of uniform density, the solid convex hull, given principal moments) and
:mod:`.record` holds and checks them; :mod:`.hull` integrates the hull of two ellipses as a
closed ruled surface and :mod:`.hull_laminae` the solid hull of any two laminae.
"""
