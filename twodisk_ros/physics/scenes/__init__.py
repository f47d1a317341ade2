"""Scenes: the ground plane, gravity, drive and dissipation a body rolls in (ROS-free).

:mod:`.scene` describes a scene (slope, heading, drive, damping, rolling resistance,
friction); :mod:`.terms` the functions of u its equation of motion needs; :mod:`.motion`
integrates a scene's motion over the phase u (:mod:`.closed`: the closed forms of a
conservative scene; :mod:`.samples`: a motion at sample times); :mod:`.events` finds when a
motion comes to rest or first stops rolling (docs/physics.md#scenes).
"""
