"""A human-scale operator skeleton that plays joint-angle motion (the built-in operator's body).

Segment lengths follow the anthropometric proportions of Winter, *Biomechanics and Motor Control of Human
Movement* (4th ed., 2009, Table 4.1 / Fig. 4.1, after Drillis & Contini) for a given stature; segment masses
follow the human column of the paper's Table 2 (75.8 kg in total), scaled to the given total mass. The topology is
the character's (pelvis, torso, head, thighs, shanks, feet, upper arms, forearms, hands), but sizes and mass
distribution differ from the character's, as they would for a real operator.

Joint rotations are given in canonical axes (z up, x forward, identity = rest pose; see sources/frame.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stylesync import rotations as rot
from stylesync.sources.frame import JOINT_INDEX, N_JOINTS, OperatorFrame

# Winter (2009) Table 4.1 heights above the floor as fractions of stature H.
_ANKLE_H = 0.039
_KNEE_H = 0.285
_HIP_H = 0.530
_SHOULDER_H = 0.818
_CHIN_NECK_H = 0.870
_UPPER_ARM = 0.186
_FOREARM = 0.146
_HAND = 0.108
_FOOT_LENGTH = 0.152
_SHOULDER_HALF_WIDTH = 0.259 / 2
_HIP_JOINT_HALF_WIDTH = 0.052  # hip joint centres ~0.1 H apart (Winter Fig. 4.1 reads 0.191 H at the trochanters)

# Table 2, human column [kg]: one value per segment (limbs per side).
TABLE2_HUMAN_MASS_KG: dict[str, float] = {
    "pelvis": 19.8, "torso": 10.3, "head": 5.7, "upper_arm": 2.0, "forearm": 1.2,
    "thigh": 11.5, "shank": 3.3, "foot": 2.0,
}
TABLE2_HUMAN_TOTAL_KG = 75.8

# Segment COM as a fraction of the segment from its proximal joint (Winter 2009, Table 4.1).
_COM_FRACTION = {"thigh": 0.433, "shank": 0.433, "upper_arm": 0.436, "forearm": 0.682}  # forearm+hand: 0.682


@dataclass(frozen=True)
class HumanSegment:
    name: str  # e.g. "thigh_left"
    joint: str  # canonical joint at its proximal end (its orientation is the segment's)
    parent_joint: str | None
    offset_in_parent: np.ndarray  # proximal joint position in the parent segment's frame (canonical axes) [m]
    com_in_segment: np.ndarray  # segment COM in its own frame [m]
    mass_kg: float


class HumanModel:
    """A human skeleton of stature ``height_m`` [m] and total mass ``mass_kg`` [kg]."""

    def __init__(self, height_m: float = 1.75, mass_kg: float = TABLE2_HUMAN_TOTAL_KG):
        H = height_m
        self.height_m = H
        self.mass_kg = mass_kg
        s = mass_kg / TABLE2_HUMAN_TOTAL_KG
        m = {k: v * s for k, v in TABLE2_HUMAN_MASS_KG.items()}
        thigh = (_HIP_H - _KNEE_H) * H
        shank = (_KNEE_H - _ANKLE_H) * H
        self.thigh_m, self.shank_m = thigh, shank
        self.ankle_height_m = _ANKLE_H * H
        self.hip_height_m = _HIP_H * H
        chest_up = 0.5 * (_SHOULDER_H - _HIP_H) * H  # spine-chest joint half way from hips to shoulders
        shoulder_up = (_SHOULDER_H - _HIP_H) * H - chest_up
        neck_up = (_CHIN_NECK_H - _HIP_H) * H - chest_up
        hw, sw = _HIP_JOINT_HALF_WIDTH * H, _SHOULDER_HALF_WIDTH * H
        ua, fa = _UPPER_ARM * H, _FOREARM * H
        foot_len = _FOOT_LENGTH * H
        v = np.array
        segs = [
            HumanSegment("pelvis", "PELVIS", None, v([0, 0, 0.0]), v([0, 0, 0.05 * H]), m["pelvis"]),
            HumanSegment("torso", "SPINE_CHEST", "PELVIS", v([0, 0, chest_up]), v([0, 0, 0.5 * shoulder_up]),
                         m["torso"]),
            HumanSegment("head", "NECK", "SPINE_CHEST", v([0, 0, neck_up]), v([0, 0, 0.06 * H]), m["head"]),
        ]
        for side, sign in (("left", 1.0), ("right", -1.0)):
            S = side.upper()
            segs += [
                HumanSegment(f"thigh_{side}", f"HIP_{S}", "PELVIS", v([0, sign * hw, 0]),
                             v([0, 0, -_COM_FRACTION["thigh"] * thigh]), m["thigh"]),
                HumanSegment(f"shank_{side}", f"KNEE_{S}", f"HIP_{S}", v([0, 0, -thigh]),
                             v([0, 0, -_COM_FRACTION["shank"] * shank]), m["shank"]),
                HumanSegment(f"foot_{side}", f"ANKLE_{S}", f"KNEE_{S}", v([0, 0, -shank]),
                             v([0.25 * foot_len, 0, -0.5 * self.ankle_height_m]), m["foot"]),
                HumanSegment(f"upper_arm_{side}", f"SHOULDER_{S}", "SPINE_CHEST", v([0, sign * sw, shoulder_up]),
                             v([0, 0, -_COM_FRACTION["upper_arm"] * ua]), m["upper_arm"]),
                HumanSegment(f"forearm_{side}", f"ELBOW_{S}", f"SHOULDER_{S}", v([0, 0, -ua]),
                             v([0, 0, -_COM_FRACTION["forearm"] * fa]), m["forearm"]),
            ]
        self.segments: tuple[HumanSegment, ...] = tuple(segs)
        self.forearm_m, self.hand_m, self.foot_length_m = fa, _HAND * H, foot_len
        self.head_top_above_neck_m = (1.0 - _CHIN_NECK_H) * H

    @property
    def total_mass_kg(self) -> float:
        return float(sum(s.mass_kg for s in self.segments))

    def frame_from_pose(
        self, timestamp_s: float, root_pos_world: np.ndarray, local_quats: dict[str, np.ndarray]
    ) -> OperatorFrame:
        """Forward kinematics: canonical local rotations per joint (relative to the parent segment) to a frame.

        ``root_pos_world`` is the PELVIS joint position; ``local_quats['PELVIS']`` its world orientation.
        """
        pos = np.zeros((N_JOINTS, 3))
        quat = np.tile(rot.IDENTITY_WXYZ, (N_JOINTS, 1))
        conf = np.zeros(N_JOINTS)
        com = np.zeros(3)
        R_of: dict[str, np.ndarray] = {}
        for seg in self.segments:
            q_local = local_quats.get(seg.joint, rot.IDENTITY_WXYZ)
            if seg.parent_joint is None:
                q_world = rot.normalize(q_local)
                p = np.asarray(root_pos_world, dtype=float)
            else:
                qp = quat[JOINT_INDEX[seg.parent_joint]]
                q_world = rot.normalize(rot.multiply(qp, q_local))
                p = pos[JOINT_INDEX[seg.parent_joint]] + R_of[seg.parent_joint] @ seg.offset_in_parent
            R = rot.matrix_from_quat(q_world)
            R_of[seg.joint] = R
            i = JOINT_INDEX[seg.joint]
            pos[i], quat[i], conf[i] = p, q_world, 1.0
            com += seg.mass_kg * (p + R @ seg.com_in_segment)
        com /= self.total_mass_kg
        # End points the sensor also reports.
        for side in ("LEFT", "RIGHT"):
            Re, pe = R_of[f"ELBOW_{side}"], pos[JOINT_INDEX[f"ELBOW_{side}"]]
            wrist = pe + Re @ np.array([0, 0, -self.forearm_m])
            hand = wrist + Re @ np.array([0, 0, -0.5 * self.hand_m])
            for name, p in ((f"WRIST_{side}", wrist), (f"HAND_{side}", hand), (f"HANDTIP_{side}", hand),
                            (f"THUMB_{side}", hand)):
                pos[JOINT_INDEX[name]], quat[JOINT_INDEX[name]], conf[JOINT_INDEX[name]] = p, quat[
                    JOINT_INDEX[f"ELBOW_{side}"]], 1.0
            Ra, pa = R_of[f"ANKLE_{side}"], pos[JOINT_INDEX[f"ANKLE_{side}"]]
            i = JOINT_INDEX[f"FOOT_{side}"]
            pos[i] = pa + Ra @ np.array([0.75 * self.foot_length_m, 0, -self.ankle_height_m])
            quat[i], conf[i] = quat[JOINT_INDEX[f"ANKLE_{side}"]], 1.0
            iclav = JOINT_INDEX[f"CLAVICLE_{side}"]
            pos[iclav] = 0.5 * (pos[JOINT_INDEX["SPINE_CHEST"]] + pos[JOINT_INDEX[f"SHOULDER_{side}"]])
            quat[iclav], conf[iclav] = quat[JOINT_INDEX["SPINE_CHEST"]], 1.0
        Rh, ph = R_of["NECK"], pos[JOINT_INDEX["NECK"]]
        for name, off in (("HEAD", [0, 0, 0.5 * self.head_top_above_neck_m]),
                          ("NOSE", [0.09, 0, 0.5 * self.head_top_above_neck_m]),
                          ("EYE_LEFT", [0.08, 0.03, 0.6 * self.head_top_above_neck_m]),
                          ("EYE_RIGHT", [0.08, -0.03, 0.6 * self.head_top_above_neck_m]),
                          ("EAR_LEFT", [0.0, 0.07, 0.55 * self.head_top_above_neck_m]),
                          ("EAR_RIGHT", [0.0, -0.07, 0.55 * self.head_top_above_neck_m])):
            i = JOINT_INDEX[name]
            pos[i], quat[i], conf[i] = ph + Rh @ np.array(off), quat[JOINT_INDEX["NECK"]], 1.0
        i = JOINT_INDEX["SPINE_NAVEL"]
        pos[i] = 0.5 * (pos[JOINT_INDEX["PELVIS"]] + pos[JOINT_INDEX["SPINE_CHEST"]])
        quat[i], conf[i] = quat[JOINT_INDEX["PELVIS"]], 1.0
        return OperatorFrame(timestamp_s, pos, quat, conf, com_world=com)
