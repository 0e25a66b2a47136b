"""Whole-body control tasks: one class per task, each an error and a Jacobian over the joint accelerations."""

from stylesync.control.tasks.base import Task, TaskRows
from stylesync.control.tasks.frame import FrameOrientationTask, FramePositionTask
from stylesync.control.tasks.momentum import CentroidalMomentumTask
from stylesync.control.tasks.posture import JointPostureTask

__all__ = ["Task", "TaskRows", "FrameOrientationTask", "FramePositionTask", "CentroidalMomentumTask",
           "JointPostureTask"]
