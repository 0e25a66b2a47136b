"""The layering of Fig. 2 holds: no import cycle between the package's parts, and the pipeline's middle stages
(processing, motion, control) and the character model never import the engine or ``sim/``."""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "stylesync"
ENGINE_FREE = ("processing", "motion", "control", "model")


def _part(path: Path) -> str:
    rel = path.relative_to(SRC)
    return rel.parts[0] if len(rel.parts) > 1 else rel.stem


def _imports(path: Path) -> set[str]:
    """Every module this file imports, at any depth (function-level imports included)."""
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            out.add(node.module)
            out.update(f"{node.module}.{a.name}" for a in node.names)
    return out


def _is_engine(module: str) -> bool:
    """The engine's code (pybullet_data holds only its data files: the character's URDF, clips)."""
    return module.split(".")[0] in ("pybullet", "pybullet_utils")


def _graph() -> dict[str, set[str]]:
    graph: dict[str, set[str]] = {}
    for path in SRC.rglob("*.py"):
        part = _part(path)
        for mod in _imports(path):
            bits = mod.split(".")
            if bits[0] != "stylesync" or len(bits) < 2:
                continue
            target = bits[1]
            if (SRC / target).is_dir() or (SRC / f"{target}.py").exists():
                if target != part:
                    graph.setdefault(part, set()).add(target)
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one part (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_no_import_cycle_between_parts():
    assert _cycles(_graph()) == []


def test_cycle_finder_finds_a_cycle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def test_pipeline_stages_and_model_do_not_import_the_engine():
    offenders = []
    for part in ENGINE_FREE:
        for path in (SRC / part).rglob("*.py"):
            for mod in _imports(path):
                if _is_engine(mod) or mod.startswith("stylesync.sim"):
                    offenders.append(f"{path.relative_to(SRC)} imports {mod}")
    assert offenders == []


def test_only_sim_imports_pybullet():
    offenders = [f"{p.relative_to(SRC)}" for p in SRC.rglob("*.py") if _part(p) != "sim"
                 and any(_is_engine(m) for m in _imports(p))]
    assert offenders == []
