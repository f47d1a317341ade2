"""Numerical tools the physics shares, each for the smooth 2π-periodic functions of the cycle.

:mod:`.analytic` (functions analytic in their argument, as the closed forms of u are),
:mod:`.spectral` (Fourier interpolation, derivatives and integrals of functions sampled at
u_j = 2πj/N), :mod:`.tables` (uniform-grid quintic Hermite tables, read in the right-hand
sides of the equations of motion), :mod:`.dense` (DOP853's dense output read at many
times in one pass) and :mod:`.vectors` (small-vector helpers for per-call
paths). They know nothing of bodies: numpy and scipy only.
"""
