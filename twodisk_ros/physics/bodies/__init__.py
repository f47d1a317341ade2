"""Rolling bodies: two congruent laminae in perpendicular planes, and their whole cycle.

:mod:`.protocol` is what the rest of the physics reads of a body (:class:`RollingBody`);
:mod:`.ellipse` implements it for two ellipses with the closed forms of the paper
(:mod:`.ellipse_batch`: the same closed forms for many bodies at once);
:mod:`.contact_solver` solves the contact geometry of any two laminae from their support
functions, and :mod:`.lamina_body` makes that a rolling body (:mod:`.regular_phase`: its
phase u solved exactly at nodes). :mod:`.orientation` gives the body's orientation as a
quaternion continuous in u, and :mod:`.cycle` the poses and contact traces over whole
cycles in the world (docs/physics.md#rolling-kinematics-and-the-contact-traces).
"""
