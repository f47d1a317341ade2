"""The motion of a body on a level plane: the equation of motion in the phase u and u(t).

:mod:`.dynamics` builds the one-degree-of-freedom equation of motion (mass, potential, their
tables) from a body and a mass model; :mod:`.solvers` holds the solutions u(t), each a dense
output; :mod:`.simulate` is the public API (:func:`simulate`) and the node's stream of
samples; :mod:`.sundman` integrates bodies other than the ellipse in the chart (u, w) with a
Sundman time, regular where u stops; :mod:`.turning` gives oscillations between turning
points in closed form; :mod:`.startup` says what a body's tables will cost before they are
built (docs/physics.md#dynamics).
"""
