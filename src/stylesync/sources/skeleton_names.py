"""Skeleton joint names as the conventions users bring write them, matched to the canonical skeleton.

A joint name is read as (side, segment word):

1. Namespaces and rig prefixes are dropped: ``mixamorig:``, ``Armature|``, ``Bip01 ``, ``CC_Base_``, ``J_Bip_``,
   ``DEF-``/``ORG-``/``MCH-``.
2. The side is a marker as prefix or suffix: ``Left``/``Right``, ``L``/``R`` as a word (``L_``, ``_L``, ``.L``,
   ``Bip01 L Thigh``), or a lower-case ``l``/``r`` before a capital (Poser/DAZ ``lThigh``, ``rShin``). A fully
   lower-case name takes ``left``/``right``/``l``/``r`` as prefix when the rest is a known segment word.
3. The rest is split into words (case changes, spaces, dots, dashes, underscores), lower-cased (numbers without
   their leading zeros: Blender's ``spine.001`` and Unreal's ``spine_01`` read ``spine1``) and joined; ``bend``
   (DAZ's main bones, ``lThighBend``) is dropped, and joints whose name holds ``twist`` or ``roll`` are helpers
   that are never matched (``lThighTwist``, ``upperarm_twist_01_l``).

Each canonical joint then takes the first joint, in the file's depth-first order, whose word is the best-ranked of
its synonyms (``SIDE_SYNONYMS``, ``CENTRE_SYNONYMS``). The ranking resolves names whose meaning differs between
conventions: MotionBuilder's ``LeftShoulder`` is the clavicle and ``LeftArm`` the upper arm, 3ds Max's
``LeftShoulder`` is the upper arm; "arm" is tried before "shoulder", so each file gets its own meaning. End sites
appear as words ending in ``end`` (``lFoot`` end site → ``footend``, ``foot.L``'s → left ``footend``), the toe of a
skeleton without toe joints, and the forearm's the wrist of an arm without a hand (a simple Blender metarig's, whose
head joint is ``face``).
A file joint stands for one canonical joint at most, taken in the order of ``SIDE_SYNONYMS``: where a skeleton has
an ``Ankle`` joint (SMPL's ``L_Ankle``, Xsens's ``LeftAnkle``), that is the ankle and its ``Foot`` child the toe;
where it has none (MotionBuilder's ``LeftFoot``), the foot joint is the ankle. OptiTrack Motive's upper arm and
forearm are ``LUArm`` and ``LFArm`` (its ``LShoulder`` is the clavicle).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

_PREFIX = re.compile(r"^(?:mixamorig\d*[_:]?|bip0*1[ _]?|cc_base_|j_bip_|def[-_.]|org[-_.]|mch[-_.])",
                     re.IGNORECASE)
_WORD = re.compile(r"[A-Z]+(?![a-z])|[A-Z]?[a-z]+|\d+")
_HELPER_WORDS = frozenset({"twist", "roll"})
_DROPPED_WORDS = frozenset({"bend"})
_LEFT, _RIGHT = frozenset({"l", "left"}), frozenset({"r", "right"})

# Canonical part -> segment words in the order tried (joined lower-case words, side removed).
SIDE_SYNONYMS: dict[str, tuple[str, ...]] = {
    "HIP": ("upleg", "thigh", "upperleg", "hip"),
    "KNEE": ("leg", "calf", "lowerleg", "shin", "knee", "lowleg"),
    "ANKLE": ("ankle", "foot"),
    "FOOT": ("toebase", "toe0", "toes", "toe", "ball", "foot", "footend", "ankleend"),
    "SHOULDER": ("arm", "upperarm", "shldr", "uparm", "uarm", "shoulder"),
    "ELBOW": ("forearm", "lowerarm", "elbow", "lowarm", "farm"),
    "WRIST": ("wrist", "hand", "forearmend", "lowerarmend"),
}
CENTRE_SYNONYMS: dict[str, tuple[str, ...]] = {
    "PELVIS": ("hips", "pelvis", "hip", "root"),
    "SPINE_CHEST": ("spine3", "spine2", "chest2", "upperchest", "chestupper", "spine1", "chest", "chestlower", "spine",
                    "abdomen2", "abdomenupper", "abdomen"),
    "NECK": ("neck", "lowerneck", "necklower", "neck1"),
    "HEAD": ("head", "face"),
}
_KNOWN_WORDS = frozenset(w for ws in (*SIDE_SYNONYMS.values(), *CENTRE_SYNONYMS.values()) for w in ws)


@dataclass(frozen=True)
class ParsedName:
    """A joint name read as side ("left", "right" or None) and segment word; ``helper`` for twist/roll bones."""

    side: str | None
    word: str
    helper: bool


def parse_name(name: str) -> ParsedName:
    s = re.split(r"[:|]", name)[-1].strip()
    s = _PREFIX.sub("", s)
    side: str | None = None
    m = re.match(r"^([lr])(?=[A-Z])", s)
    if m:
        side, s = ("left" if m.group(1) == "l" else "right"), s[1:]
    words = [str(int(w)) if w.isdigit() else w.lower() for w in _WORD.findall(s)]  # spine.001 -> spine 1
    if words and words[0] == "c" and len(words) > 1:  # VRM's centre marker, J_Bip_C_Hips
        words = words[1:]
    end_site = len(words) > 2 and words[-1] == "end"  # the loader's end-site suffix after a side: foot.L + End
    if end_site:
        words.pop()
    for pos in (0, -1):
        if side is None and len(words) > 1 and (words[pos] in _LEFT or words[pos] in _RIGHT):
            side = "left" if words[pos] in _LEFT else "right"
            words.pop(pos)
    if end_site:
        words.append("end")
    helper = any(w in _HELPER_WORDS for w in words)
    word = "".join(w for w in words if w not in _DROPPED_WORDS)
    if side is None and word not in _KNOWN_WORDS:
        for prefix, which in (("left", "left"), ("right", "right"), ("l", "left"), ("r", "right")):
            if word.startswith(prefix) and word[len(prefix):] in _KNOWN_WORDS:
                side, word = which, word[len(prefix):]
                break
    return ParsedName(side, word, helper)


def synonyms() -> dict[str, tuple[str | None, tuple[str, ...]]]:
    """Canonical joint -> (side, segment words tried in order)."""
    out: dict[str, tuple[str | None, tuple[str, ...]]] = {c: (None, ws) for c, ws in CENTRE_SYNONYMS.items()}
    for side in ("left", "right"):
        for part, ws in SIDE_SYNONYMS.items():
            out[f"{part}_{side.upper()}"] = (side, ws)
    return out


def match_by_name(names: list[str]) -> dict[str, tuple[str, str]]:
    """Canonical joint -> (joint name, how it was matched), for the canonical joints whose synonyms occur.

    ``names`` are in the file's depth-first order; the first joint with the best-ranked word wins.
    """
    by_key: dict[tuple[str | None, str], str] = {}
    for n in names:
        p = parse_name(n)
        if not p.helper:
            by_key.setdefault((p.side, p.word), n)
    out: dict[str, tuple[str, str]] = {}
    used: set[str] = set()
    for canon, (side, words) in synonyms().items():
        for w in words:
            name = by_key.get((side, w))
            if name is not None and name not in used:
                out[canon] = (name, f"name: {side + ' ' if side else ''}{w}")
                used.add(name)
                break
    return out
