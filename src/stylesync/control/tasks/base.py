"""What a whole-body task is: a name, a weight per row, and at each control tick the rows ``A q̈ = b`` it asks for.

A task's desired acceleration comes from its own feedback law (a PD on its error, with its gains); the rows are its
Jacobian ``A`` (k, nv) and ``b = ẍ* - J̇ q̇`` (the desired acceleration minus the drift). The formulation adds
``½ Σ_rows w (A q̈ - b)²`` to the QP's objective (weighted tasks, as TSID's and placo's soft tasks).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from stylesync.model.character_model import CharacterModel


@dataclass
class TaskRows:
    """One task's contribution at one tick: ``weight * (jacobian @ q̈ - target)²`` summed over rows. A task on
    single DOFs gives ``dofs`` instead of a Jacobian (rows q̈[dofs] = target): a diagonal in the QP's Hessian."""

    jacobian: np.ndarray | None  # (k, nv), or None with dofs
    target: np.ndarray  # (k,)
    weight: np.ndarray  # (k,) per-row weight (>= 0)
    dofs: np.ndarray | slice | None = None  # (k,) DOF indices (or a range of them) when jacobian is None


class Task(ABC):
    """A whole-body task. Subclasses hold their gains and targets (set by the controller before each tick)."""

    name: str = "task"
    active: bool = True
    frame: str = ""  # the frame a task on one frame acts on
    _frame_of: tuple[int, int] | None = None  # (id of the model, the frame's index in it), looked up once

    def _frame_id(self, model: CharacterModel) -> int:
        """The index of ``frame`` in ``model``."""
        if self._frame_of is None or self._frame_of[0] != id(model):
            self._frame_of = (id(model), model.frame_id(self.frame))
        return self._frame_of[1]

    @abstractmethod
    def rows(self, model: CharacterModel) -> TaskRows:
        """The task's rows at the model's current state (``CharacterModel.update`` has run)."""
