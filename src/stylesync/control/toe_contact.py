"""A rear sole on its toes: the contact of a foot whose heel has left the ground, and when a foot goes onto it.

Walking, a person's rear heel rises before the rear foot lifts (heel-off, late in the stance): the foot turns about
the line of its toes, the leg is the foot's length longer, and the pelvis need not come down as the body passes over
the front foot. A flat sole contact (contacts.py) holds the whole sole on the ground: a rear leg stretched to its
full length then pins the pelvis to the arc of a straight leg about the rear ankle. Traced on the development
suite's walk with ``--follow-path`` (seed 2): the rear leg straight (hip to ankle 1.00 of its length) from 2.77 s to
the lift-off at 3.04 s while the pelvis went 0.21 m forward over it and came down from 0.81 m to 0.67 m, and stayed
there, on a bent front leg, through the next single stance (docs/decisions.md, "A rear foot on its toes").

:class:`ToeContact` passes forces at the sole's two front corners only (their friction pyramids, as contacts.py's)
and keeps the toe line where it is: the toe line's midpoint does not move (3 rows) and the sole does not turn about
its forward axis or the vertical (2 rows); its turn about the toe line (its lateral axis) is free, so the heel rises
as the leg asks. :func:`toe_off_sides` decides which supporting foot stands so: on two feet, the foot behind the
body whose leg is stretched to ``stretch_share`` of its length (hip to ankle) or whose heel is raised already.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from stylesync.control.contacts import SOLE_CORNERS_IN_SOLE, SoleContact
from stylesync.model.sole import sole_corners_world

TOE_CORNERS = 2  # the sole's front-left and front-right corners (SOLE_CORNERS_IN_SOLE's first two rows)
FORCES_PER_TOE = 4 * TOE_CORNERS  # 4 pyramid edges per corner
CONSTRAINT_ROWS = 5  # the toe line's midpoint (3) and the sole's turn about its forward axis and the vertical (2)
# The toe line's midpoint relative to the sole's centre, in the foot's canonical frame (x forward, y left, z up) [m]
_TOE_MID_IN_SOLE = SOLE_CORNERS_IN_SOLE[:TOE_CORNERS].mean(axis=0)
# A heel this much higher than the toes (the sole's rear corners against its front ones) is raised [m]
HEEL_RAISED_M = 0.005
# The COM at least this far ahead of an ankle, along that foot's own forward axis, puts the foot behind the body [m]
BEHIND_BODY_M = 0.1


class ToeContact(SoleContact):
    """A sole standing on the line of its toes: forces at its two front corners (the pyramids of contacts.py), its
    turn about that line free."""

    corners_in_sole = SOLE_CORNERS_IN_SOLE[:TOE_CORNERS]
    n_forces = FORCES_PER_TOE
    n_rows = CONSTRAINT_ROWS
    _rotation = np.eye(3)  # the sole's axes at the last update (world from foot), replaced at each

    def _update_forces(self, placement: pin.SE3) -> None:
        super()._update_forces(placement)
        self._rotation = placement.rotation.copy()  # the sole's axes, for its rows

    def constraint_rows(self, velocity_gain: float) -> tuple[np.ndarray, np.ndarray]:
        """The toe line stays: its midpoint p = o + r does not move (``a_p = a_o + α × r + ω × (ω × r)``, world axes)
        and the sole does not turn about its forward axis or the vertical; each with its residual velocity damped at
        ``velocity_gain``. (5, nv) rows and (5,) right-hand sides."""
        rotation = self._rotation
        r_world = rotation @ _TOE_MID_IN_SOLE
        j_lin, j_ang = self.jacobian[:3], self.jacobian[3:]
        omega = self.velocity[3:]
        j_point = j_lin - pin.skew(r_world) @ j_ang  # v_p = v_o + ω × r = v_o - [r]× ω
        drift_point = self.drift[:3] + np.cross(self.drift[3:], r_world) + np.cross(omega, np.cross(omega, r_world))
        vel_point = self.velocity[:3] + np.cross(omega, r_world)
        axes = np.array([rotation[:, 0], [0.0, 0.0, 1.0]])  # the sole's forward axis and the vertical
        rows = np.vstack([j_point, axes @ j_ang])
        rhs = np.concatenate([-drift_point - velocity_gain * vel_point,
                              -(axes @ self.drift[3:]) - velocity_gain * (axes @ omega)])
        return rows, rhs


def heel_raised(corners_world: np.ndarray) -> bool:
    """Whether a sole's heel is higher than its toes by more than HEEL_RAISED_M: its rear corners against its front
    ones, ``corners_world`` (4, 3) in sole_corners_world's order [m]."""
    z = corners_world[:, 2]
    return bool(0.5 * (z[2] + z[3]) - 0.5 * (z[0] + z[1]) > HEEL_RAISED_M)


def toe_off_sides(support: list[str], stretch: dict[str, float], com_world: np.ndarray,
                  ankles_world: dict[str, np.ndarray], feet_quat_wxyz: dict[str, np.ndarray],
                  stretch_share: float) -> set[str]:
    """The supporting feet that stand on their toes this tick: only on two feet, the foot behind the body (the COM at
    least BEHIND_BODY_M ahead of its ankle along the foot's forward axis) whose leg is stretched to ``stretch_share``
    of its length or more (``stretch``: hip to ankle over the leg's length) or whose heel is raised already."""
    if len(support) != 2:
        return set()
    out = set()
    for s in support:
        ankle = ankles_world[s]
        corners = sole_corners_world(ankle, feet_quat_wxyz[s])
        ahead = 0.5 * (corners[0] + corners[1]) - 0.5 * (corners[2] + corners[3])  # the sole's forward axis, scaled
        ahead_xy = ahead[:2] / max(float(np.hypot(ahead[0], ahead[1])), 1e-9)
        if float((com_world[:2] - ankle[:2]) @ ahead_xy) < BEHIND_BODY_M:
            continue
        if stretch[s] >= stretch_share or heel_raised(corners):
            out.add(s)
    return out
