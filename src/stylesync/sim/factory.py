"""The default engine, built from the configuration (kept apart from the interface it implements)."""

from __future__ import annotations

from stylesync.config import WorldConfig
from stylesync.sim.backend import PhysicsBackend


def make_backend(
    world: WorldConfig, physics_hz: float, gui: bool = False, fixed_root: bool = False
) -> PhysicsBackend:
    """The default engine. ``fixed_root`` loads the pelvis welded to the world, only for gain tuning and tests
    "with the root fixed" (Sec. 7.2); a teleoperated character always has a free root."""
    from stylesync.sim.pybullet_backend import PyBulletBackend

    return PyBulletBackend(world, physics_hz, gui=gui, fixed_root=fixed_root)
