"""Ground contact forces, and where the rolling model holds (docs/physics.md#contact-forces).

:mod:`.terms` holds the coefficients of the two contact forces over a cycle per unit of the
body's turn; :mod:`.contact` evaluates the forces and wrenches of a motion at A and B;
:mod:`.validity` finds where a contact would lift off or need more friction than μ.
"""
