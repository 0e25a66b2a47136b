"""Skeleton matching by structure, when the joint names say nothing (``j0 .. jN``, another language's words).

The five chains from the pelvis (two legs, spine to head, two arms) are found by topology and the rest pose's
geometry (file units and axes; only directions and ratios are used):

1. The pelvis is the first joint from the root with three or more children. Its child subtree holding the most
   joints is the spine (it carries the arms and the head); the two others reaching farthest are the legs.
2. Along the spine, each joint's child whose subtree points most along the spine (pelvis to that joint) continues
   it; the other children are limbs. The two limbs that reach farthest are the arms, and the deepest joint they
   hang from is the chest. The spine continues past the chest to its end, or to a joint that branches again (eyes, jaw):
   two or more joints there give the neck (the first) and the head (the last); one gives the head, and the chest
   is the neck.
3. In a leg (the path from its first joint to its farthest end), the two adjacent segments of greatest summed
   length are the thigh and shank (hip, knee, ankle); the joint after the ankle is the toe. In an arm, the wrist
   is the joint where the hand branches into fingers (or the first joint placed on it: a hand segment of no
   length), and the elbow and the shoulder are the two joints before it (a clavicle before the shoulder, however
   long, is left out); an arm without fingers is read as a leg is: its two adjacent segments of greatest summed
   length are the upper arm and forearm, and the wrist may be the forearm's end site (an arm without a hand).
4. Left and right: ``up`` runs from the pelvis to the head, ``forward`` along the feet (ankle to toe), and the
   chain whose first joint lies further along ``up × forward`` is the left one.
"""

from __future__ import annotations

import numpy as np

from stylesync.errors import SourceError


class _Tree:
    def __init__(self, parent_index: list[int], rest: np.ndarray):
        self.parent = parent_index
        self.rest = rest
        self.children: list[list[int]] = [[] for _ in parent_index]
        for j, p in enumerate(parent_index):
            if p >= 0:
                self.children[p].append(j)

    def subtree(self, j: int) -> list[int]:
        out, stack = [], [j]
        while stack:
            k = stack.pop()
            out.append(k)
            stack.extend(self.children[k])
        return out

    def farthest(self, j: int, origin: np.ndarray) -> int:
        """The joint of ``j``'s subtree farthest from ``origin``."""
        sub = self.subtree(j)
        return sub[int(np.argmax(np.linalg.norm(self.rest[sub] - origin, axis=1)))]

    def path(self, top: int, bottom: int) -> list[int]:
        out = [bottom]
        while out[-1] != top:
            out.append(self.parent[out[-1]])
        return out[::-1]


_COINCIDENT = 1e-6  # a segment shorter than this fraction of the limb's longest joins its two joints


def _path_segments(tree: _Tree, first: int, origin: np.ndarray) -> tuple[list[int], np.ndarray]:
    path = tree.path(first, tree.farthest(first, origin))
    if len(path) < 3:
        raise SourceError("too few joints in a limb")
    return path, np.linalg.norm(np.diff(tree.rest[path], axis=0), axis=1)


def _longest_pair(seg: np.ndarray) -> int:
    """The index of the first of the two adjacent segments of greatest summed length (a thigh and shank, an upper arm
    and forearm)."""
    return int(np.argmax(seg[:-1] + seg[1:]))


def _leg(tree: _Tree, first: int, origin: np.ndarray) -> list[int]:
    """(hip, knee, ankle[, toe]): the two adjacent segments of greatest summed length on the path to the foot."""
    path, seg = _path_segments(tree, first, origin)
    i = _longest_pair(seg)
    return path[i:i + 4]


def _arm(tree: _Tree, first: int, origin: np.ndarray, end_sites: frozenset[int]) -> list[int]:
    """(shoulder, elbow, wrist) of the arm that starts at ``first``."""
    path, seg = _path_segments(tree, first, origin)
    real = [k for k in range(len(path)) if path[k] not in end_sites]
    branching = [k for k in real[1:] if len([c for c in tree.children[path[k]] if c not in end_sites]) >= 2]
    if not branching:  # no fingers: read as a leg; the wrist may be the forearm's end site (no hand)
        i = _longest_pair(seg)
        return path[i:i + 3]
    w = branching[0]
    while w > 0 and seg[w - 1] < _COINCIDENT * seg.max():  # a joint placed on the wrist (a hand with no length)
        w -= 1
    if w < 2:
        raise SourceError("too few joints in an arm")
    return path[w - 2:w + 1]


def match_by_structure(names: list[str], parent_index: list[int], rest: np.ndarray,
                       end_sites: frozenset[int] = frozenset()) -> dict[str, tuple[str, str]]:
    """Canonical joint -> (joint name, how it was matched) for the required joints, from the tree and rest pose.

    ``rest``: (n, 3) rest-pose joint positions (any units and axes); ``end_sites``: indices of joints that are end
    sites (only used as a toe). Raises SourceError when the tree does not have the shape of a humanoid.
    """
    tree = _Tree(parent_index, np.asarray(rest, dtype=float))
    pelvis = next((j for j in range(len(names)) if len(tree.children[j]) >= 3), None)
    if pelvis is None:
        raise SourceError("no joint with three chains (legs and spine) below it")
    p0 = tree.rest[pelvis]
    subs = sorted(tree.children[pelvis], key=lambda c: len(tree.subtree(c)), reverse=True)
    spine_top = subs[0]
    legs = sorted(subs[1:], key=lambda c: float(np.linalg.norm(tree.rest[tree.farthest(c, p0)] - p0)))[-2:]
    if len(legs) < 2:
        raise SourceError("fewer than two legs below the pelvis")

    # The spine: follow the child that continues it; the other children are limbs.
    spine, limbs, j = [spine_top], [], spine_top
    while True:
        kids = [c for c in tree.children[j] if c not in end_sites]
        if not kids:
            break
        axis = tree.rest[j] - p0

        def along(c: int, j: int = j, axis: np.ndarray = axis) -> float:
            d = tree.rest[tree.farthest(c, tree.rest[j])] - tree.rest[j]
            return float(d @ axis / (np.linalg.norm(d) * np.linalg.norm(axis) + 1e-12))

        nxt = max(kids, key=along)
        limbs += [(c, j) for c in kids if c != nxt]
        spine.append(nxt)
        j = nxt
    arms = sorted(limbs, key=lambda cj: float(np.linalg.norm(tree.rest[tree.farthest(cj[0], tree.rest[cj[1]])]
                                                             - tree.rest[cj[1]])))[-2:]
    if len(arms) < 2:
        raise SourceError("fewer than two arms along the spine")
    chest = max(spine.index(hang) for _, hang in arms)
    after = spine[chest + 1:]
    if not after:
        raise SourceError("no head above the arms")
    # The head is where the chain past the chest ends or branches again (eyes, jaw).
    branch = [k for k, j in enumerate(after) if len([c for c in tree.children[j] if c not in end_sites]) >= 2]
    after = after[:branch[0] + 1] if branch else after
    if len(after) >= 2:
        chest_j, neck_j, head_j = spine[chest], after[0], after[-1]
    else:
        chest_j, neck_j, head_j = (spine[chest - 1] if chest > 0 else pelvis), spine[chest], after[0]

    up = tree.rest[head_j] - p0
    leg_joints = [_leg(tree, c, p0) for c in legs]
    if any(len(lj) < 4 for lj in leg_joints):
        raise SourceError("a leg has no joint past the ankle to tell forward from backward")
    forward = np.sum([tree.rest[lj[3]] - tree.rest[lj[2]] for lj in leg_joints], axis=0)
    forward = forward - (forward @ up) / (up @ up) * up
    left = np.cross(up, forward)
    if float(np.linalg.norm(left)) < 1e-9 * max(float(np.linalg.norm(up)), 1e-12):
        raise SourceError("the feet do not point anywhere to tell left from right")
    arm_joints = [_arm(tree, c, tree.rest[hang], end_sites) for c, hang in arms]

    out = {"PELVIS": (names[pelvis], "structure: pelvis"), "SPINE_CHEST": (names[chest_j], "structure: chest"),
           "NECK": (names[neck_j], "structure: neck"), "HEAD": (names[head_j], "structure: head")}
    for chains, parts in ((leg_joints, ("HIP", "KNEE", "ANKLE", "FOOT")), (arm_joints, ("SHOULDER", "ELBOW", "WRIST"))):
        a, b = chains
        if (tree.rest[a[0]] - tree.rest[b[0]]) @ left < 0:
            a, b = b, a
        for side, chain in (("LEFT", a), ("RIGHT", b)):
            for part, k in zip(parts, chain[:len(parts)], strict=True):
                out[f"{part}_{side}"] = (names[k], f"structure: {side.lower()} {part.lower()}")
    return out
