"""The reach envelope: where the mobile base stands relative to what the arm works on.

One table for the two places that decide it: the scene builder checks that some free base pose has
the hazard within reach (``scene/layout.py::Layout.fit_base``; the robot starts at its dock, not
there, unless ``build.start = "reach"``), and the :class:`~anomalygen.robot.driver.Driver` moves the
base before a skill acts (``place_base_near``). The builder's bands are wide (the check only has to
find the hazard within reach); the Driver tries a few exact distances, nearest first. Both sit
inside what the arm reaches from its home pose: the cup hangs 0.3 m ahead of the base centre, and the
arm reaches about 0.95 m out with the cup pointing down.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Reach:
    """Distances in metres, horizontal, from the base centre unless said otherwise."""

    # ---- the builder's reachability check (scene/layout.py), and the start pose with build.start = reach
    object_band: tuple[float, float] = (0.35, 0.85)  # to a loose object's centre
    furniture_band: tuple[float, float] = (0.45, 0.9)  # to a piece of furniture's footprint (doors swept
    # open included): the home pose clears it and the arm still reaches a door edge or handle
    inside_max: float = 1.05  # to an object inside furniture
    max_height: float = 1.45  # m above the floor: a loose object higher than this is out of reach
    # ---- the Driver's base placement (robot/driver.py)
    stay_band: tuple[float, float] = (0.4, 0.62)  # the base stays put for a target this far away
    # (nearer than 0.4: base radius 0.22 plus the hand; beyond 0.62 the arm is stretched)
    ring: tuple[float, ...] = (0.55, 0.45, 0.65, 0.75)  # distances tried, in this order
    headings: int = 24  # candidate base positions on each ring


REACH = Reach()
