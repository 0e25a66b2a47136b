"""Recovery steps on the capture point: the character steps when its feet can no longer stop its body.

The balance state is the divergent component of motion (capture point) of the linear inverted pendulum of
Eq. 21, ``ξ = c + ċ / ω`` with ``ω = sqrt(g / h)`` (h the COM height above the ground): with the centre of
pressure at ``p``, ``ξ̇ = ω (ξ - p)``. A centre of pressure can only lie in the support polygon of the soles on
the ground, so once ξ is outside that polygon the body cannot be stopped where it stands: it must step.

The operator's steps are followed as they come (pose_optimization.py). When the operator stands (his stance
FSM in double stance, and his own capture point within the polygon of his soles, :func:`operator_stands`: in the
double stance of a walk it is ahead of them) the character may still carry momentum he does not have: the
operator of a recorded file holds his last pose at its end, mid-stride; a live operator stops faster than the
smaller body can; a push moves the character, not him. Then, when the character's ξ is further than
``MotionConfig.recovery_step_margin_m`` outside the support polygon of its soles on the ground, it steps on its
own:

* the stance foot is the one whose step leaves the predicted capture point least outside the new support (the
  stance sole and the swing sole at its landing, below), the one whose sole is nearer ξ on a tie: when ξ drifts out
  beside the front foot of a staggered stance, the rear foot cannot land beyond it, and the front foot steps out;
* the landing is planned each tick where ξ will be when the foot lands: with the centre of pressure held at the
  stance sole's point nearest ξ, ``ξ(t + τ) = p + (ξ(t) - p) e^(ω τ)``, τ the swing time left; the sole is placed
  with its trailing edge there (trailing along ξ's direction of divergence from p), so that every centre of
  pressure on the new sole drives ξ back; ξ is the body's with the swing leg carried by the pelvis
  (``MotionConfig.recovery_landing_without_swing``): the leg's own swing, which the ground stops at the landing,
  would otherwise move the landing with the foot;
* within the leg's reach (``MotionConfig.recovery_step_reach_share`` of its length from the stance ankle) and
  across the stance foot only as a crossover step, landing at least ``MotionConfig.recovery_cross_clear_m`` ahead of
  or behind the stance ankle, and otherwise moved to the nearer of ``MIN_FOOT_SEPARATION_M`` outwards of it and
  that clearance ahead or behind (``MotionConfig.recovery_cross_nearest``), in the stance sole's own yaw frame
  (``MotionConfig.recovery_cross_stance_frame``; otherwise the heading frame): a capture point that
  leaves the stance sole on the side away from the swing foot is caught by one step, as the operator's own crossing
  steps catch it;
* the foot rises ``recovery_step_height_m`` at mid-swing, follows a smooth step from its lift-off point to the
  landing, is back at the ground at ``recovery_touchdown_share`` of ``recovery_swing_s`` (it trails its target: so
  it touches down near the swing's end, when its landing is planned for) and is then lowered below the ground until
  it touches (the stance FSM ends the step on its contact); the whole-body controller tracks that target with a
  task of its own (``ReferencePose.recovery_ankle_world``), at the profile's velocity for the landing as it is
  planned this tick (``ReferencePose.recovery_ankle_vel_world``; ``WholeBodyConfig.recovery_foot_target_rate``), not
  the landing's own motion from tick to tick.

The step's timing is the nominal swing time (``recovery_swing_s``) as long as its capture landing stays within the
leg's reach; otherwise it is shortened, each tick, to when that landing would leave the reach
(:meth:`RecoveryStepper.time_to_reach_limit_s`), but to no less than ``recovery_swing_min_s``: landing later, the step
would land short of the capture point, and the next one would start with it outside its support. Its position and its
timing both adapt to the capture point. A swing of the operator's that he holds up too long while the character cannot
stand on one foot, or that would land at his pace only once the capture point is out of a step's reach, is taken over
by such a step in the air (:meth:`RecoveryStepper.take_over`, pose_optimization.py): the foot is lowered from where it
is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from stylesync import rotations as rot
from stylesync.config import MotionConfig
from stylesync.model.character import (
    ANKLE_HEIGHT_M,
    FOOT_CENTER_AHEAD_OF_ANKLE_M,
    FOOT_LENGTH_M,
    FOOT_WIDTH_M,
    HIP_HALF_WIDTH_M,
    LINK_NAMES,
    OTHER_SIDE,
)
from stylesync.model.sole import (
    convex_hull_points,
    convex_hull_xy,
    outside_distance_m,
    outside_distance_points,
    sole_corner_points,
    sole_corners_world,
    sole_outside_m,
    sole_points_xy,
    sole_points_xy_yaw,
    sole_within_m,
)
from stylesync.model.state import CharacterState
from stylesync.processing.interpolation import smooth_step, smooth_step_slope

MIN_FOOT_SEPARATION_M = 1.2 * HIP_HALF_WIDTH_M  # the swing ankle lands at least this far outwards of the stance one
LANDING_PRESS_M = 0.02  # after the nominal swing time the foot is aimed this far below the ground [m]
# The foot reaches the landing point horizontally at this share of the nominal swing time (the remaining share
# lowers it there).
HORIZONTAL_SHARE = 0.8
ON_GROUND_GAP_M = 0.01  # a sole whose lowest corner is this close to the ground counts in the support polygon [m]
_SOLE_POINTS = sole_corner_points()  # the character's sole relative to its ankle [m]
_ANKLE = {s: LINK_NAMES.index(f"{s}_ankle") for s in ("left", "right")}
_OUT = {"left": 1.0, "right": -1.0}
_UP = np.array([0.0, 0.0, 1.0])  # world up (Z)


@dataclass(frozen=True)
class WalkOn:
    """A recovery step that walks on (MotionConfig.recovery_walk_on_m): it lands with the capture point
    ``distance_m`` ahead of its ankle, as a gait's foot lands behind its capture point, instead of on its sole's
    trailing edge. Along ``way_world`` ((3,) unit, horizontal: the operator's way over the ground,
    MotionConfig.recovery_walk_on_his_way), only as far as the capture point diverges that way: across it the
    step catches the body on its ankle. None: along the capture point's own divergence from the stance sole."""

    distance_m: float
    way_world: np.ndarray | None = None

    def ahead_world(self, u: np.ndarray) -> np.ndarray:
        """(3,) the capture point's offset ahead of the landing ankle for its divergence ``u`` (3,) (unit) [m]."""
        if self.way_world is None:
            return self.distance_m * u
        return self.distance_m * max(float(u @ self.way_world), 0.0) * self.way_world


def capture_point(com_world: np.ndarray, com_vel_world: np.ndarray, gravity_mps2: float) -> tuple[np.ndarray, float]:
    """ξ = c + ċ / ω (horizontal, (2,)) [m] and ω = sqrt(g / h) [1/s] of the linear inverted pendulum (Eq. 21),
    h the COM height above the ground."""
    omega = float(np.sqrt(gravity_mps2 / max(float(com_world[2]), 0.1)))
    return np.asarray(com_world, dtype=float)[:2] + np.asarray(com_vel_world, dtype=float)[:2] / omega, omega


def _grown_from(x: float, y: float, polygon: list[tuple[float, float]], omega: float,
                remaining_s: float) -> tuple[float, float]:
    """A capture point (x, y) ``remaining_s`` later, the centre of pressure held at the polygon's point nearest to it:
    ``ξ(t + τ) = p + (ξ(t) - p) e^(ω τ)`` (Eq. 21's pendulum) [m]."""
    _, (px, py) = outside_distance_points((x, y), polygon)
    grow = math.exp(omega * remaining_s)
    return px + (x - px) * grow, py + (y - py) * grow


def capture_point_after(com_world: np.ndarray, com_vel_world: np.ndarray, gravity_mps2: float,
                        stance_ankle_world: np.ndarray, stance_foot_quat_wxyz: np.ndarray,
                        remaining_s: float) -> tuple[float, float]:
    """The capture point (horizontal) ``remaining_s`` from now, with the centre of pressure held at the stance
    sole's point nearest to it: ``ξ(t + τ) = p + (ξ(t) - p) e^(ω τ)`` (Eq. 21's pendulum) [m]. On plain floats (model/
    sole.py's ``*_points``): it runs on every tick of an operator's swing."""
    xi, omega = capture_point(com_world, com_vel_world, gravity_mps2)
    polygon = convex_hull_points(sole_points_xy(stance_ankle_world, stance_foot_quat_wxyz, _SOLE_POINTS))
    return _grown_from(float(xi[0]), float(xi[1]), polygon, omega, remaining_s)


def out_of_reach_after_wait(com_world: np.ndarray, com_vel_world: np.ndarray, gravity_mps2: float,
                            ankles_world: dict[str, np.ndarray], feet_quat_wxyz: dict[str, np.ndarray],
                            on_ground: list[str], wait_s: float, swing_s: float, reach_m: float) -> bool:
    """Whether a step begun ``wait_s`` from now lands too late, whichever foot it leaves standing: with the centre of
    pressure held in the support polygon of the soles ``on_ground`` for ``wait_s``, then in the stance sole for the
    swing's ``swing_s`` (each time at its point nearest to the capture point, Eq. 21's pendulum), the capture point
    would end further than ``reach_m`` from every stance ankle. On plain floats."""
    xi, omega = capture_point(com_world, com_vel_world, gravity_mps2)
    soles = {s: convex_hull_points(sole_points_xy(ankles_world[s], feet_quat_wxyz[s], _SOLE_POINTS)) for s in on_ground}
    support = convex_hull_points([p for s in on_ground for p in soles[s]])
    x, y = _grown_from(float(xi[0]), float(xi[1]), support, omega, wait_s)
    for s in on_ground:
        lx, ly = _grown_from(x, y, soles[s], omega, swing_s)
        if math.hypot(lx - float(ankles_world[s][0]), ly - float(ankles_world[s][1])) <= reach_m:
            return False
    return True


def soles_on_ground(state: CharacterState) -> list[str]:
    """The feet whose soles press the ground (``CharacterState.feet_pressing``) or whose lowest sole corner is within
    ON_GROUND_GAP_M of it: the soles of the support polygon."""
    pressing = state.feet_pressing()
    return [s for s in ("left", "right") if pressing[s]
            or sole_within_m(state.link_origin_world[_ANKLE[s]], state.link_quat_wxyz[_ANKLE[s]], ON_GROUND_GAP_M)]


def support_outside_m(xi_world: np.ndarray, ankles_world: dict[str, np.ndarray],
                      feet_quat_wxyz: dict[str, np.ndarray], on_ground: list[str]) -> float:
    """Signed distance of a capture point (horizontal) from the support polygon of the soles ``on_ground`` (each at
    its ankle, turned by its foot's orientation): > 0 outside [m]. On plain floats (model/sole.py's ``*_points``):
    it runs on every double-stance tick."""
    return support_outside_along(xi_world, ankles_world, feet_quat_wxyz, on_ground, (1.0, 0.0))[0]


def support_outside_along(xi_world: np.ndarray, ankles_world: dict[str, np.ndarray],
                          feet_quat_wxyz: dict[str, np.ndarray], on_ground: list[str],
                          direction_world: tuple[float, float] | np.ndarray) -> tuple[float, float]:
    """:func:`support_outside_m`, and the cosine between the outward direction (from the polygon's nearest point to
    the capture point) and a horizontal direction (``direction_world``, (2,), unit) [m, -]; the cosine is 0 inside."""
    corners = [p for s in on_ground for p in sole_points_xy(ankles_world[s], feet_quat_wxyz[s], _SOLE_POINTS)]
    x, y = float(xi_world[0]), float(xi_world[1])
    distance, (nx, ny) = outside_distance_points((x, y), convex_hull_points(corners))
    if distance <= 0.0:
        return distance, 0.0
    return distance, ((x - nx) * float(direction_world[0]) + (y - ny) * float(direction_world[1])) / distance


def beyond_sole_towards_m(xi_world: np.ndarray, stance_ankle_world: np.ndarray, stance_foot_quat_wxyz: np.ndarray,
                          other_ankle_world: np.ndarray) -> float:
    """How far a capture point (horizontal) lies outside the stance sole on the side of the other foot [m]: its
    distance from the sole where the direction from the sole's nearest point to it points towards the other ankle,
    0 otherwise. Standing on that sole alone, the body then falls back onto the other foot. On plain floats."""
    polygon = convex_hull_points(sole_points_xy(stance_ankle_world, stance_foot_quat_wxyz, _SOLE_POINTS))
    x, y = float(xi_world[0]), float(xi_world[1])
    distance, (nx, ny) = outside_distance_points((x, y), polygon)
    towards = ((x - nx) * (float(other_ankle_world[0]) - float(stance_ankle_world[0]))
               + (y - ny) * (float(other_ankle_world[1]) - float(stance_ankle_world[1])))
    return distance if distance > 0.0 and towards > 0.0 else 0.0


def operator_stands(xi_h_world: np.ndarray, ankles_h_world: dict[str, np.ndarray], foot_yaw_h_rad: dict[str, float],
                    scale: float) -> bool:
    """Whether the operator's capture point (horizontal) is within the support polygon of his soles, each the
    character's sole scaled by 1 / ``scale`` (h_C / h_H, Eq. 9) at his ankle, turned by his foot's yaw."""
    in_foot = [(x / scale, y / scale, z / scale) for x, y, z in _SOLE_POINTS]
    corners = [p for s in ankles_h_world for p in sole_points_xy_yaw(ankles_h_world[s], foot_yaw_h_rad[s], in_foot)]
    xi = (float(xi_h_world[0]), float(xi_h_world[1]))
    return outside_distance_points(xi, convex_hull_points(corners))[0] <= 0.0


def outside_step_m(xi_world: np.ndarray, stance_ankle_world: np.ndarray, stance_foot_quat_wxyz: np.ndarray,
                   landing_ankle_world: np.ndarray, heading_world: np.ndarray) -> float:
    """Signed distance of a capture point (horizontal) from the support polygon of the stance sole and a sole landed
    flat at ``landing_ankle_world`` along the heading (``heading_world``: (3, 3), x forward): > 0 outside [m]."""
    yaw = float(np.arctan2(heading_world[1, 0], heading_world[0, 0]))
    corners = np.vstack([sole_corners_world(stance_ankle_world, stance_foot_quat_wxyz)[:, :2],
                         sole_corners_world(landing_ankle_world, rot.quat_from_yaw(yaw))[:, :2]])
    return outside_distance_m(xi_world, convex_hull_xy(corners))[0]


def stands_on(xi_world: np.ndarray, stance_ankle_world: np.ndarray, stance_foot_quat_wxyz: np.ndarray,
              landing_ankle_world: np.ndarray, heading_world: np.ndarray) -> bool:
    """Whether a capture point is within the support of the stance sole and a landed sole (:func:`outside_step_m`)."""
    return outside_step_m(xi_world, stance_ankle_world, stance_foot_quat_wxyz, landing_ankle_world,
                          heading_world) <= 0.0


def not_across(landing_world: np.ndarray, stance_ankle_world: np.ndarray, frame_world: np.ndarray,
               side: str, cross_clear_m: float | None = None, nearest: bool = False) -> np.ndarray:
    """(3,) a swing ankle's landing moved, if needed, off the stance foot, in the frame ``frame_world`` ((3, 3),
    x forward, y left: the heading's or the stance sole's yaw). A landing across the stance ankle, or less than
    ``MIN_FOOT_SEPARATION_M`` outwards of it, is kept where it is if it lies at least ``cross_clear_m`` ahead of or
    behind the stance ankle (a crossover step, its foot clear of the stance foot; None: never across). Otherwise it
    is moved sideways to ``MIN_FOOT_SEPARATION_M`` outwards, or, with ``nearest``, to whichever of that and the
    crossover clearance ahead or behind (on the side it already is) is the nearer. A foot landing across the stance
    foot beside it would land on it."""
    base = np.array([stance_ankle_world[0], stance_ankle_world[1], 0.0])
    rel = frame_world.T @ (np.array([landing_world[0], landing_world[1], 0.0]) - base)
    out = _OUT[side]
    if cross_clear_m is None or abs(rel[0]) < cross_clear_m:
        sideways_m = MIN_FOOT_SEPARATION_M - out * rel[1]  # > 0: the landing is not far enough outwards
        if sideways_m > 0.0:
            if nearest and cross_clear_m is not None and cross_clear_m - abs(rel[0]) < sideways_m:
                rel[0] = cross_clear_m if rel[0] >= 0.0 else -cross_clear_m
            else:
                rel[1] = out * MIN_FOOT_SEPARATION_M
    landing = base + frame_world @ rel
    landing[2] = landing_world[2]
    return landing


@dataclass(frozen=True)
class _OverStance:
    """The linear inverted pendulum over a stance sole (world frame, horizontal) [m, 1/s]."""

    xi: np.ndarray  # (2,) the capture point
    omega: float  # sqrt(g / h)
    cop: np.ndarray  # (2,) the centre of pressure: the sole's point nearest xi
    away: np.ndarray  # (2,) xi - cop
    norm: float  # |xi - cop|
    u: np.ndarray  # (3,) xi's direction of divergence from cop (unit; zero when xi is on the sole)


@dataclass
class RecoveryStep:
    """A step the character takes on its own (world frame) [m, s]."""

    side: str  # the swinging foot
    start_s: float
    lift_off_world: np.ndarray  # (3,) swing ankle at lift-off (or where it was when the step took a swing over)
    landing_world: np.ndarray  # (3,) the planned landing of the swing ankle, re-planned each tick
    duration_s: float  # the swing's time: the nominal one, shortened while the capture point runs out of reach
    taken_over: bool = False  # the step took over a swing of the operator's (it only lands it)
    # its foot, in the air, is lowered from where it is: a taken-over swing's, unless the foot was still on the ground
    # (MotionConfig.recovery_takeover_low_foot_m), which steps up and down as a step of its own does
    lowered: bool = False
    fixed_landing: bool = False  # a step to a place chosen before it began (rest_step.py): not re-planned
    # (3,) the target's velocity along the swing profile, the landing held where it is this tick (a new array each
    # tick: the reference pose passes it on as it is) [m/s]
    target_vel_world: np.ndarray = field(default_factory=lambda: np.zeros(3))


class RecoveryStepper:
    """Decides when the character steps on its own, with which foot, and where the swing foot goes each tick."""

    def __init__(self, cfg: MotionConfig, leg_length_m: float, gravity_mps2: float):
        self.cfg = cfg
        self.g = gravity_mps2
        self.max_step_m = cfg.recovery_step_reach_share * leg_length_m
        self.step: RecoveryStep | None = None
        self.count = 0  # recovery steps taken
        self._last_end_s = -np.inf

    def trigger(self, time_s: float, com_world: np.ndarray, com_vel_world: np.ndarray,
                ankles_world: dict[str, np.ndarray], feet_quat_wxyz: dict[str, np.ndarray],
                on_ground: list[str], heading_world: np.ndarray | None = None,
                loads_n: dict[str, float] | None = None) -> RecoveryStep | None:
        """A new step when the capture point is outside the support polygon of the soles ``on_ground`` by more
        than the margin (and the last recovery step ended at least ``recovery_min_stance_s`` ago). The stance
        foot is the one on the ground whose sole is nearer the capture point; with ``heading_world`` ((3, 3),
        x forward) and both feet on the ground, the foot whose step leaves the predicted capture point least
        outside the new support (:meth:`capture_residual_m`), the nearer sole on a tie; with ``loads_n`` (each sole's
        normal force [N]) and ``recovery_stance_min_load_share``, not a sole that bears less than that share of
        both while the COM moves away from its ankle. With one sole on the ground
        and ``recovery_landing_foot_waits``, none while the foot in the air, landed where it is, would leave the
        capture point predicted a recovery swing ahead no further outside than its step would."""
        cfg = self.cfg
        if not cfg.recovery_steps or not on_ground or time_s - self._last_end_s < cfg.recovery_min_stance_s:
            return None
        xi, _ = capture_point(com_world, com_vel_world, self.g)
        if support_outside_m(xi, ankles_world, feet_quat_wxyz, on_ground) <= cfg.recovery_step_margin_m:
            return None
        dist = {s: sole_outside_m(xi, ankles_world[s], feet_quat_wxyz[s]) for s in on_ground}
        stance = min(dist, key=lambda s: dist[s])
        if len(on_ground) == 1 and cfg.recovery_landing_foot_waits and heading_world is not None:
            # The other foot is in the air (a step just landed that bounced; the controller presses it down). If
            # landed where it is it would leave the predicted capture point no further outside the support than its
            # step would, within reach of the sole on the ground, it is landing where the body goes: a step would
            # take it back from there.
            up = OTHER_SIDE[stance]
            landing, xi_land = self.capture_landing(cfg.recovery_swing_s, com_world, com_vel_world,
                                                    ankles_world[stance], feet_quat_wxyz[stance], heading_world, up)
            stepped = outside_step_m(xi_land, ankles_world[stance], feet_quat_wxyz[stance], landing, heading_world)
            as_it_is = outside_step_m(xi_land, ankles_world[stance], feet_quat_wxyz[stance], ankles_world[up],
                                      heading_world)
            if as_it_is <= stepped:
                return None
        if heading_world is not None and len(on_ground) == 2:
            residual = {s: self.capture_residual_m(com_world, com_vel_world, ankles_world[s], feet_quat_wxyz[s],
                                                   heading_world, OTHER_SIDE[s]) for s in on_ground}
            best = min(residual.values())
            if residual[stance] > best + 1e-3:
                stance = min(residual, key=lambda s: residual[s])
        share = cfg.recovery_stance_min_load_share
        if share is not None and loads_n is not None and len(on_ground) == 2:
            # A stance foot that bears less than the share of the body, and that the body is not moving onto, would
            # leave it on neither sole once the other lifts: the loaded foot stands, and the other steps.
            total = loads_n["left"] + loads_n["right"]
            towards = float(np.dot(np.asarray(com_vel_world)[:2],
                                   np.asarray(ankles_world[stance])[:2] - np.asarray(com_world)[:2]))
            if total > 0.0 and loads_n[stance] < share * total and towards <= 0.0:
                stance = OTHER_SIDE[stance]
        side = OTHER_SIDE[stance]
        self.step = RecoveryStep(side, time_s, np.array(ankles_world[side], dtype=float),
                                 np.array(ankles_world[side], dtype=float), cfg.recovery_swing_s)
        self.count += 1
        return self.step

    def capture_residual_m(self, com_world: np.ndarray, com_vel_world: np.ndarray, stance_ankle_world: np.ndarray,
                           stance_foot_quat_wxyz: np.ndarray, heading_world: np.ndarray, side: str) -> float:
        """How far the capture point, at the end of a nominal recovery swing of ``side`` from now, would be outside
        the support of the stance sole and the swing sole at its capture landing (<= 0: the step captures it) [m]."""
        landing, xi_land = self.capture_landing(self.cfg.recovery_swing_s, com_world, com_vel_world,
                                                stance_ankle_world, stance_foot_quat_wxyz, heading_world, side)
        return float(outside_step_m(xi_land, stance_ankle_world, stance_foot_quat_wxyz, landing, heading_world))

    def take_over(self, side: str, time_s: float, swing_ankle_world: np.ndarray) -> RecoveryStep:
        """Turn the swing of ``side``, in the air since the operator lifted it, into a recovery step that lands it
        (step timing adaptation: the balance decides when the step ends). A foot still within
        ``recovery_takeover_low_foot_m`` of the ground (taken over at its lift-off) is stepped as a step from the
        ground, up by ``recovery_step_height_m`` and down, not lowered from where it is."""
        ankle = np.array(swing_ankle_world, dtype=float)
        low_m = self.cfg.recovery_takeover_low_foot_m
        in_air = low_m is None or float(ankle[2]) >= ANKLE_HEIGHT_M + low_m
        self.step = RecoveryStep(side, time_s, ankle, ankle.copy(), self.cfg.recovery_swing_s, taken_over=True,
                                 lowered=in_air)
        self.count += 1
        return self.step

    def begin_to(self, side: str, time_s: float, lift_off_world: np.ndarray, landing_world: np.ndarray,
                 duration_s: float) -> RecoveryStep:
        """A step of ``side`` from ``lift_off_world`` to ``landing_world`` ((3,) ankles, world frame [m]) over
        ``duration_s`` [s], its landing fixed (a step to where the operator stands, rest_step.py)."""
        self.step = RecoveryStep(side, time_s, np.array(lift_off_world, dtype=float),
                                 np.array(landing_world, dtype=float), duration_s, fixed_landing=True)
        return self.step

    def landing_due(self, time_s: float) -> bool:
        """Whether the step's foot is past its horizontal travel and should now be going down to the ground."""
        return self.step is not None and time_s - self.step.start_s >= HORIZONTAL_SHARE * self.step.duration_s

    def end(self, time_s: float) -> None:
        """The step is over (the stance FSM saw the foot land, or the operator took over)."""
        if self.step is not None:
            self.step = None
            self._last_end_s = time_s

    @staticmethod
    def _landing_ankle(xi_land_world: np.ndarray, u: np.ndarray, heading_world: np.ndarray,
                       walk_on: WalkOn | None) -> np.ndarray:
        """(3,) the swing ankle's landing for the capture point ``xi_land_world`` (2,) there, ``u`` (3,) its direction
        of divergence (unit, horizontal): behind it as ``walk_on`` says (:class:`WalkOn`), or (None) the sole's centre
        beyond it along ``u`` by the sole's half-extent along ``u`` (ξ then lands on the sole's trailing edge, and
        every centre of pressure on the sole drives it back) [m]."""
        if walk_on is not None:
            return np.array([xi_land_world[0], xi_land_world[1], 0.0]) - walk_on.ahead_world(u)
        u_heading = heading_world.T @ u
        half_extent = abs(u_heading[0]) * FOOT_LENGTH_M / 2 + abs(u_heading[1]) * FOOT_WIDTH_M / 2
        centre = np.array([xi_land_world[0], xi_land_world[1], 0.0]) + half_extent * u
        return centre - heading_world @ np.array([FOOT_CENTER_AHEAD_OF_ANKLE_M, 0.0, 0.0])

    def _over_stance(self, com_world: np.ndarray, com_vel_world: np.ndarray, stance_ankle_world: np.ndarray,
                     stance_foot_quat_wxyz: np.ndarray) -> _OverStance:
        """The pendulum over the stance sole (Eq. 21): the capture point ξ, ω, the centre of pressure p held at the
        sole's point nearest ξ, and ξ's direction of divergence from p."""
        xi, omega = capture_point(com_world, com_vel_world, self.g)
        _, cop = outside_distance_m(xi, convex_hull_xy(sole_corners_world(stance_ankle_world,
                                                                          stance_foot_quat_wxyz)[:, :2]))
        away = xi - cop
        norm = float(np.linalg.norm(away))
        u = np.array([*(away / norm), 0.0]) if norm > 1e-6 else np.zeros(3)
        return _OverStance(xi, omega, cop, away, norm, u)

    def capture_landing(self, remaining_s: float, com_world: np.ndarray, com_vel_world: np.ndarray,
                        stance_ankle_world: np.ndarray, stance_foot_quat_wxyz: np.ndarray, heading_world: np.ndarray,
                        side: str, walk_on: WalkOn | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Where the ``side`` ankle lands (3,) so that the capture point, ``remaining_s`` from now, is on the
        trailing edge of its sole (within reach, across the stance foot only as a crossover step), and that capture
        point (2,) [m]. With ``walk_on``, instead, the capture point ahead of the ankle (:class:`WalkOn`): a step that
        walks on, as a gait's lands behind its capture point.
        ``heading_world``: (3, 3) the heading frame's rotation (x forward, y left)."""
        over = self._over_stance(com_world, com_vel_world, stance_ankle_world, stance_foot_quat_wxyz)
        return self._landing_over(over, remaining_s, stance_ankle_world, stance_foot_quat_wxyz, heading_world, side,
                                  walk_on)

    def _landing_over(self, over: _OverStance, remaining_s: float, stance_ankle_world: np.ndarray,
                      stance_foot_quat_wxyz: np.ndarray, heading_world: np.ndarray, side: str,
                      walk_on: WalkOn | None) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`capture_landing` of the pendulum ``over`` the stance sole."""
        xi_land = over.cop + over.away * np.exp(over.omega * remaining_s)
        R = heading_world
        ankle = self._landing_ankle(xi_land, over.u, R, walk_on)
        # Within reach, and across the stance foot only as a crossover step (relative to the stance ankle, in the
        # stance sole's own yaw frame or the heading frame).
        base = np.array([stance_ankle_world[0], stance_ankle_world[1], 0.0])
        rel = R.T @ (ankle - base)
        rel[2] = 0.0
        length = float(np.linalg.norm(rel[:2]))
        if length > self.max_step_m:
            rel[:2] *= self.max_step_m / length
        R_clear = (rot.matrix_from_quat(rot.quat_from_yaw(rot.twist_angle(stance_foot_quat_wxyz, _UP)))
                   if self.cfg.recovery_cross_stance_frame else R)
        landing = not_across(base + R @ rel, stance_ankle_world, R_clear, side, self.cfg.recovery_cross_clear_m,
                             self.cfg.recovery_cross_nearest)
        landing[2] = ANKLE_HEIGHT_M
        return landing, xi_land

    def time_to_reach_limit_s(self, com_world: np.ndarray, com_vel_world: np.ndarray,
                              stance_ankle_world: np.ndarray, stance_foot_quat_wxyz: np.ndarray,
                              heading_world: np.ndarray, walk_on: WalkOn | None = None) -> float:
        """How long from now the capture landing (:meth:`capture_landing`, before its reach limit) stays within the
        step's reach of the stance ankle: the τ >= 0 at which ``|a + b e^(ω τ)| = max_step_m``, with ``a`` the
        landing's offset from the stance ankle when the capture point is on the centre of pressure and ``b = ξ - p``
        (Eq. 21's pendulum, the centre of pressure ``p`` held at the stance sole's point nearest ξ); 0 when it is
        already beyond reach, infinity when it never leaves it [s]. A step that lands later lands short of the
        capture point, and the next step then starts with the capture point outside its support."""
        over = self._over_stance(com_world, com_vel_world, stance_ankle_world, stance_foot_quat_wxyz)
        return self._reach_time_over(over, stance_ankle_world, heading_world, walk_on)

    def _reach_time_over(self, over: _OverStance, stance_ankle_world: np.ndarray, heading_world: np.ndarray,
                         walk_on: WalkOn | None) -> float:
        """:meth:`time_to_reach_limit_s` of the pendulum ``over`` the stance sole [s]."""
        b, norm = over.away, over.norm
        a = (self._landing_ankle(over.cop, over.u, heading_world, walk_on)[:2]
             - np.asarray(stance_ankle_world, dtype=float)[:2])
        # Within reach while |a + b s|² - L² = s² |b|² + 2 s a·b + |a|² - L² <= 0, s = e^(ω τ) >= 1 (now: s = 1):
        # between the roots.
        bb, ab, c = norm * norm, float(a @ b), float(a @ a) - self.max_step_m ** 2
        if norm <= 1e-6:
            return math.inf if c <= 0.0 else 0.0  # ξ on the centre of pressure: the landing stays where it is
        disc = ab * ab - bb * c
        if disc < 0.0:
            return 0.0  # the landing's line never comes within reach
        s_low, s_high = (-ab - math.sqrt(disc)) / bb, (-ab + math.sqrt(disc)) / bb
        if not s_low <= 1.0 <= s_high:
            return 0.0  # beyond reach now
        return math.log(s_high) / over.omega

    def swing_target(self, time_s: float, com_world: np.ndarray, com_vel_world: np.ndarray,
                     stance_ankle_world: np.ndarray, stance_foot_quat_wxyz: np.ndarray,
                     heading_world: np.ndarray, walk_on: WalkOn | None = None,
                     swing_ankle_world: np.ndarray | None = None) -> np.ndarray:
        """(3,) this tick's target of the swing ankle [m]; the landing re-planned on the capture point (``walk_on``:
        :meth:`capture_landing`).
        ``heading_world``: (3, 3) the heading frame's rotation (x forward, y left); ``swing_ankle_world``: (3,) where
        the swing ankle is (a taken-over swing's descent, ``recovery_takeover_clearance_share``)."""
        step, cfg = self.step, self.cfg
        assert step is not None
        elapsed = time_s - step.start_s
        if step.fixed_landing:
            landing = step.landing_world
        else:
            over = self._over_stance(com_world, com_vel_world, stance_ankle_world, stance_foot_quat_wxyz)
            if cfg.recovery_swing_min_s is not None and elapsed < step.duration_s:
                # Step timing: the step lands no later than when its capture landing leaves the leg's reach (and
                # no sooner than the shortest swing); the duration only shortens.
                reach_s = self._reach_time_over(over, stance_ankle_world, heading_world, walk_on)
                step.duration_s = min(step.duration_s, max(elapsed + reach_s, cfg.recovery_swing_min_s))
            landing, _ = self._landing_over(over, max(step.duration_s - elapsed, 0.0), stance_ankle_world,
                                            stance_foot_quat_wxyz, heading_world, step.side, walk_on)
            step.landing_world = landing
        phase = elapsed / step.duration_s
        along = phase / HORIZONTAL_SHARE
        moved = smooth_step(min(along, 1.0))
        # d(moved)/dt of the smooth step 3x² - 2x³, x = t / (HORIZONTAL_SHARE T) [1/s]
        moved_rate = smooth_step_slope(along) / (HORIZONTAL_SHARE * step.duration_s)
        target = step.lift_off_world + moved * (landing - step.lift_off_world)
        vel = moved_rate * (landing - step.lift_off_world)
        if phase < 1.0 and step.lowered:
            # Already in the air: lowered from where it is to the ground by the time it is over the landing ...
            target[2] = step.lift_off_world[2] + moved * (ANKLE_HEIGHT_M - step.lift_off_world[2])
            vel[2] = moved_rate * (ANKLE_HEIGHT_M - step.lift_off_world[2])
            share = cfg.recovery_takeover_clearance_share
            if share is not None and swing_ankle_world is not None:
                # ... but no lower than a step's height until the foot itself has come the clearance share of its
                # way to the landing, and from there down to the ground by a smooth step over the rest of its way.
                way = (landing - step.lift_off_world)[:2]
                way_sq = float(way @ way)
                gone = (float((np.asarray(swing_ankle_world)[:2] - step.lift_off_world[:2]) @ way) / way_sq
                        if way_sq > 1e-8 else 1.0)
                down = min(max((gone - share) / (1.0 - share), 0.0), 1.0)
                floor = ANKLE_HEIGHT_M + (1.0 - smooth_step(down)) * cfg.recovery_step_height_m
                if floor > target[2]:
                    target[2] = floor
                    vel[2] = -smooth_step_slope(down) / (1.0 - share) * moved_rate * cfg.recovery_step_height_m
        elif phase < cfg.recovery_touchdown_share:
            # Up and down again by the touchdown share of the swing: the foot trails its target, and reaches the
            # ground near the swing's end, when the landing is planned for.
            touchdown = phase / cfg.recovery_touchdown_share
            target[2] = ANKLE_HEIGHT_M + cfg.recovery_step_height_m * np.sin(np.pi * touchdown)
            vel[2] = (cfg.recovery_step_height_m * np.pi * np.cos(np.pi * touchdown)
                      / (cfg.recovery_touchdown_share * step.duration_s))
        else:
            target[2] = ANKLE_HEIGHT_M - LANDING_PRESS_M
            vel[2] = 0.0
        step.target_vel_world = vel
        return target
