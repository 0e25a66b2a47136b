"""Following the operator over the ground by step placement.

Eq. 10 retargets the operator's COM onto the character's own feet, and the swing lands relative to the character's
capture point as his landed relative to his: every quantity is relative to the character's body, so a character
that falls behind its operator stays behind. This module keeps the one global quantity that relates the two: the
operator's path scaled onto the character's, from where both started (as the imitation metrics scale it,
``metrics/imitation.scale_operator_to_character``).

With the divergent component of motion (the capture point) of the linear inverted pendulum, ξ̇ = ω (ξ - p), and the
operator's, scaled, ξ̇_ref = ω (ξ_ref - p_ref), the error δ = ξ - ξ_ref obeys δ̇ = ω (δ - (p - p_ref)). A landing
placed relative to the character's capture point as his was relative to his (p - ξ = p_ref - ξ_ref at the landing)
keeps δ over the stance that follows. Moved by k δ, the foot stays there for the step's time T while δ evolves:
δ(T) = δ (1 - k (e^(ωT) - 1)). The step removes the share s = k (e^(ωT) - 1) of the error; s = 1 removes it in one
step (deadbeat), s > 2 makes it grow with alternating sign. The gain is set as that share (Englsberger et al.'s DCM
tracking, in its footstep form), k = s / (e^(ωT) - 1), T the operator's usual step (his swing and double stance).
The correction is bounded: a character far behind catches up over several steps, not one.

The same scaled path also gives the targets a pull (:meth:`PathReference.target_pull_xy`), kept in full while he goes
no faster than the character's gait carries it at his cadence (:func:`pull_share_at_speed`), steps
(:func:`pull_share_after_steps`) and goes along his way (pose_optimization.py, ``_path_pull_along``). The
pendulum's relation above holds for a body left to its pendulum; the whole-body controller's COM task tracks the COM
target instead, and the target of Eq. 10 is anchored on the character's own stance foot: within a stance it moves at
his speed, and at a change of stance it falls back by as much as the character's step was shorter than his. The
character's speed over the ground is then its target's, and no landing undoes a lag that the target carries. Moving
the targets a share of the way to his COM on the character's path (bounded) puts the restoring term where the speed
is set.
"""

from __future__ import annotations

import math

import numpy as np


class PathReference:
    """The operator's capture point scaled onto the character's path, and the landing correction it gives."""

    def __init__(self, share: float, max_m: float, target_share: float = 0.0, target_max_m: float = 0.0):
        self.share = share  # s, the share of the error a step removes [-]
        self.max_m = max_m  # the correction's largest horizontal length [m]
        self.target_share = target_share  # the share of the way the targets are moved to his path [-]
        self.target_max_m = target_max_m  # the targets' largest move [m]
        self._char_origin_xy: np.ndarray | None = None  # the character's pelvis over the ground at the start [m]
        self._op_origin_xy: np.ndarray | None = None  # the operator's [m]
        self.error_xy = np.zeros(2)  # δ = ξ_c - ξ_ref of the last update, world frame [m]
        self.omega_per_s = 1.0  # ω of the character's pendulum at the last update [1/s]

    @property
    def enabled(self) -> bool:
        """Whether the path is tracked: for the landing's correction or the targets' pull."""
        return self.share > 0.0 or self.target_share > 0.0

    def update(self, char_pelvis_world: np.ndarray, op_pelvis_world: np.ndarray, xi_c_world: np.ndarray,
               xi_h_world: np.ndarray, scale: float, omega_per_s: float) -> np.ndarray:
        """δ = ξ_c - ξ_ref (2,) [m], world frame: the character's capture point ``xi_c_world`` against the
        operator's ``xi_h_world`` scaled by ``scale`` about his first pelvis ground point, moved onto the
        character's first pelvis ground point; ``omega_per_s``: the character's ω [1/s]. The first call fixes both
        origins."""
        self.omega_per_s = omega_per_s
        if self._char_origin_xy is None or self._op_origin_xy is None:
            self._char_origin_xy = np.asarray(char_pelvis_world, dtype=float)[:2].copy()
            self._op_origin_xy = np.asarray(op_pelvis_world, dtype=float)[:2].copy()
        xi_ref = self._char_origin_xy + scale * (np.asarray(xi_h_world, dtype=float)[:2] - self._op_origin_xy)
        self.error_xy = np.asarray(xi_c_world, dtype=float)[:2] - xi_ref
        return self.error_xy

    def landing_shift_xy(self, step_s: float) -> np.ndarray:
        """k δ (2,) [m], world frame, k = share / (e^(ω T) - 1) for the last update's ω and ``step_s`` = T [s],
        bounded to ``max_m``: what the landing moves by."""
        return bounded_xy(deadbeat_gain(self.omega_per_s, step_s) * self.share * self.error_xy, self.max_m)

    def on_path_xy(self, op_point_world: np.ndarray, scale: float) -> np.ndarray | None:
        """(2,) [m], world frame: a point of the operator's scaled by ``scale`` about his first pelvis ground point and
        moved onto the character's; None before the first :meth:`update`."""
        if self._char_origin_xy is None or self._op_origin_xy is None:
            return None
        return self._char_origin_xy + scale * (np.asarray(op_point_world, dtype=float)[:2] - self._op_origin_xy)

    def target_pull_xy(self, com_target_world: np.ndarray, op_com_world: np.ndarray, scale: float) -> np.ndarray:
        """(2,) [m], world frame: what the targets move by, ``target_share`` of the way from the COM target
        ``com_target_world`` to the operator's COM ``op_com_world`` scaled by ``scale`` about his first pelvis
        ground point onto the character's, at most ``target_max_m``; zero before the first :meth:`update` or when
        off."""
        his = self.on_path_xy(op_com_world, scale)
        if self.target_share <= 0.0 or his is None:
            return np.zeros(2)
        return bounded_xy(self.target_share * (his - np.asarray(com_target_world, dtype=float)[:2]), self.target_max_m)


def pull_share_at_speed(speed_mps: float, fade_from_mps: float | None, fade_to_mps: float) -> float:
    """The share of the targets' pull kept when he goes ``speed_mps`` over the ground (scaled) [-]: 1 up to
    ``fade_from_mps``, 0 from ``fade_to_mps``, linear between; 1 at every speed when ``fade_from_mps`` is None. The
    character's gait at his cadence has a top speed (its steps' reach at his step time): a pull towards an operator
    faster than that drives its capture point beyond the reach of a step landed at his timing, and the steps it then
    takes of its own land early, out of step with his."""
    if fade_from_mps is None:
        return 1.0
    return min(max((fade_to_mps - speed_mps) / (fade_to_mps - fade_from_mps), 0.0), 1.0)


def pull_share_after_steps(since_single_stance_s: float, hold_s: float | None) -> float:
    """The share of the targets' pull kept ``since_single_stance_s`` after he last stood on one foot [-]: 1 for
    ``hold_s``, then falling linearly to 0 over another ``hold_s``; 1 always when ``hold_s`` is None. The character
    follows his path by its steps; an operator who takes none (he stands, he jumps with both feet, he sways without
    lifting a foot) gives it no step to follow with, and a pull then moves the body only by steps of its own."""
    if hold_s is None:
        return 1.0
    return min(max(2.0 - since_single_stance_s / hold_s, 0.0), 1.0)


def bounded_xy(shift_xy: np.ndarray, max_m: float) -> np.ndarray:
    """``shift_xy`` (2,) shortened to at most ``max_m`` long [m]."""
    n = float(np.linalg.norm(shift_xy))
    return shift_xy * (max_m / n) if n > max_m else shift_xy


def deadbeat_gain(omega_per_s: float, step_s: float) -> float:
    """k = 1 / (e^(ω T) - 1) [-]: the landing shift per metre of capture-point error that removes the error
    over one step of ``step_s`` = T [s] (ω = ``omega_per_s`` [1/s])."""
    return 1.0 / max(math.expm1(omega_per_s * step_s), 1e-6)
