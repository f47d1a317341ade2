"""Equilibria of a body on the plane and their stability.

See docs/physics.md#equilibria-and-their-stability. :mod:`.equilibria` finds every
equilibrium of a body (the extrema of the height of G over one cycle) and computes
the stability map; :mod:`.certified` finds every root of dz_G/du with a certificate that none
was missed; :mod:`.symmetric` gives the stability of the symmetric equilibria in closed
form; :mod:`.wells` models a well of the potential around a stable equilibrium, which the
motion uses where the phase speed vanishes.
"""
