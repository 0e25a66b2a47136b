"""A bound on the COM target's capture point: the character is not asked for a lean it cannot come back from.

A capture point ξ = c + ċ / ω (Eq. 21's pendulum) outside the soles a body stands on cannot be brought back by any
centre of pressure (recovery_step.py): following a COM target (c_d, ċ_d) of Eq. 19 whose capture point
ξ_d = c_d + ċ_d / ω lies there, the character accelerates towards a place it cannot stop at, and must step where
the operator does not. The retargeted target asks for that whenever the operator leans further over his feet than
the character's smaller, differently placed feet allow: a lunge, a punch, the crouch before a jump, a walk cut off
mid-stride. So the target's capture point is kept within the soles the character stands on:
* in the character's double stance, always: it leaves double stance only with the operator's step, and before that
  step there is nothing to catch a capture point outside both feet;
* in its single stance, while the operator's own capture point is within the soles he stands on (he balances on one
  leg, as in a kick, or has stopped while the character's foot is still in the air). Where his balance leans out of
  his support (a walk's single stance), the character's target is left as it is: the swing foot catches it.
  Opt-in (MotionConfig.landing_capture_bound): there too, the target's capture point is kept within the stance sole
  and the region the planned landing catches when the foot lands (:func:`landing_catch_region`), wholly or across
  the heading only; a slow single stance (a styled step held long) then keeps it over the stance foot.

Where ξ_d is outside, by d, the target's capture point becomes the nearest point ξ_d' of the (shrunk) support
polygon, and its velocity is cut to ċ_d' = ċ_d max(0, 1 - d / BAND_M): c_d' = ξ_d' - ċ_d' / ω. With the
capture-point gains of the COM task (kp = K ω², kd = (1 + K) ω, docs/decisions.md, "The COM force's gains"; exact
where the COM height gives their ω, about 3.4 1/s), the COM force is then the capture-point law aiming at ξ_d' with
ξ̇_d' = ċ_d': beyond the band, a body standing still over
ξ_d' (the centre of pressure brakes the body towards a capture point it can stand on); at the polygon's edge, the
unbounded target, so that the force does not jump as ξ_d crosses it (a jump of m ω ċ_d, 150 N at 1 m/s, made runs
from inputs a micrometre apart differ by a centimetre within 2 s).

The polygon tests run on every control tick, on plain floats (model/sole.py's ``*_points`` functions: a few
corners, where numpy's per-call overhead was most of the cost).
"""

from __future__ import annotations

import numpy as np

from stylesync.model.sole import Point, convex_hull_points, outside_distance_points

# Over this distance of ξ_d beyond the polygon [m], the bounded target's velocity goes from ċ_d to zero
BAND_M = 0.05


def bounded_com_target(com_d_world: np.ndarray, com_vel_d_world: np.ndarray, omega_1ps: float,
                       soles_xy: list[list[Point]], margin_m: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """The COM target (position (3,) [m], velocity (3,) [m/s]) with its capture point ξ_d = c_d + ċ_d / ω
    (``omega_1ps`` [1/s]) within the support polygon of the soles ``soles_xy`` (each its corners' world horizontal
    positions, model/sole.sole_points_xy, shrunk as wanted): unchanged where it is within (or without soles);
    otherwise with its capture point on the polygon's point nearest to ξ_d and its velocity cut over BAND_M
    (horizontally; the height and vertical velocity are kept). With ``margin_m`` > 0 the capture point may lie up to
    that far outside the polygon [m]: the bound is the polygon grown by it (a gait's capture point runs ahead of
    its front foot, :func:`gait_capture_margin_m`)."""
    if not soles_xy:
        return com_d_world, com_vel_d_world
    polygon = convex_hull_points([p for sole in soles_xy for p in sole])
    vx, vy = float(com_vel_d_world[0]), float(com_vel_d_world[1])
    xi_d = (float(com_d_world[0]) + vx / omega_1ps, float(com_d_world[1]) + vy / omega_1ps)
    distance, (nx, ny) = outside_distance_points(xi_d, polygon)
    if distance <= margin_m:
        return com_d_world, com_vel_d_world
    if margin_m > 0.0:  # the nearest point of the grown polygon, on the line from the polygon's nearest to ξ_d
        nx += margin_m * (xi_d[0] - nx) / distance
        ny += margin_m * (xi_d[1] - ny) / distance
        distance -= margin_m
    keep = max(0.0, 1.0 - distance / BAND_M)
    vel = np.array([vx * keep, vy * keep, float(com_vel_d_world[2])])
    com = np.array([nx - vel[0] / omega_1ps, ny - vel[1] / omega_1ps, float(com_d_world[2])])
    return com, vel


def gait_capture_margin_m(reach_m: float, omega_1ps: float, step_s: float) -> float:
    """How far outside the soles a double stance's capture point may run and a step of ``step_s`` [s] still catch
    it within ``reach_m`` of where it is [m]: ξ(T) = p + (ξ - p) e^(ω T) (Eq. 21's pendulum, the centre of pressure p
    at the soles' edge), so the distance d now reaches d e^(ω T) by the landing: d = reach e^(-ω T)."""
    return reach_m * float(np.exp(-omega_1ps * step_s))


def landing_catch_region(stance_xy: list[Point], landing_offset_xy: tuple[float, float],
                         shrink: float) -> list[Point]:
    """The capture points [m] that a landing catches, for a capture point bounded in single stance (corners of a
    convex region): with the centre of pressure held at a point p of the stance sole (corners ``stance_xy``),
    ξ(T) = p + (ξ - p) exp(ω T) after the swing's remaining time T, so the capture points now whose ξ(T) is within
    the landing's sole (the stance sole moved by ``landing_offset_xy``, the landing ankle from the stance ankle) are
    (1 - k) p + k q, q within the landing's sole, k = ``shrink`` = exp(-ω T): the region spanned by every pair of
    the two soles' corners."""
    dx, dy = landing_offset_xy
    landing = [(x + dx, y + dy) for x, y in stance_xy]
    return [((1.0 - shrink) * px + shrink * qx, (1.0 - shrink) * py + shrink * qy)
            for px, py in stance_xy for qx, qy in landing]
