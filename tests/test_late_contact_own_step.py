"""A swing held for a late contact (Sec. 5.1) taken over by the balance as the character's own step
(MotionConfig.recovery_in_late_contact; docs/decisions.md, "A late contact that the balance takes over")."""

from __future__ import annotations

import dataclasses

from conftest import suite_run

from stylesync.config import ControlConfig, MotionConfig


def _spin(option: bool) -> tuple[bool, int]:
    """The built-in spin, sensor seed 12, for 4 s: whether it fell, and on how many control ticks a step of the
    character's own followed a tick on which a late contact held the reference."""
    taken_over = [0]

    def watch(session):
        held = [False]

        def on_tick(state, ref) -> None:
            taken_over[0] += int(held[0] and ref.recovery_ankle_world is not None)
            held[0] = session.motion.reading.held
        return on_tick

    def configure(cfg):
        return dataclasses.replace(cfg, duration_s=4.0)

    motion = dataclasses.replace(MotionConfig(), recovery_in_late_contact=option)
    result = suite_run("builtin:spin", 12, motion, ControlConfig(), watch=watch, configure=configure)
    return result.fell, taken_over[0]


def test_a_held_swing_the_capture_point_leaves_becomes_an_own_step():
    """Traced (seed 12): his spin's leap carries his COM backwards and to the left at 1.3 m/s; the character, on its
    left foot, holds its right swing for his landing 0.55 m to the left of its stance foot while its capture point
    leaves the stance sole by 0.19-0.33 m, lands it there at 3.11 s with the capture point 0.13 m behind both feet, and
    falls at 3.43 s in the own steps that follow. With the option the held swing becomes an own step that lands where
    the capture point goes, and the run stands."""
    fell, taken_over = _spin(False)
    assert fell and taken_over == 0
    fell, taken_over = _spin(True)
    assert not fell and taken_over > 0
