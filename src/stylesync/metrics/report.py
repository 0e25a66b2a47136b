"""``report.html`` for a run, a bench or an experiment folder: its figures, its metrics as a table, the
configuration it recorded and the versions of what ran it. One self-contained file (figures inlined)."""

from __future__ import annotations

import base64
import html
import json
import platform
from importlib import metadata
from pathlib import Path

from stylesync.files import write_atomically

_PACKAGES = ("stylesync", "pybullet", "numpy", "scipy", "viser", "bvhio")


def _flatten(d: dict, prefix: str = "") -> list[tuple[str, str]]:
    rows = []
    for k, v in d.items():
        key = f"{prefix}{k}"
        if isinstance(v, dict):
            rows += _flatten(v, key + ".")
        elif isinstance(v, list) and len(v) > 8:
            rows.append((key, f"[{len(v)} items]"))
        else:
            rows.append((key, json.dumps(v) if not isinstance(v, str) else v))
    return rows


def _versions() -> dict[str, str]:
    out = {"python": platform.python_version(), "platform": platform.platform()}
    for p in _PACKAGES:
        try:
            out[p] = metadata.version(p)
        except metadata.PackageNotFoundError:
            out[p] = "absent"
    return out


def _header(folder: Path) -> dict | None:
    """The folder's session file header (None: no readable one)."""
    session = folder / "session.jsonl"
    if not session.is_file():
        return None
    with session.open(encoding="utf-8", errors="replace") as f:
        first = f.readline()
    try:
        header = json.loads(first)
    except json.JSONDecodeError:
        return None
    return header if isinstance(header, dict) else None


def _metrics_run_id(folder: Path) -> str | None:
    try:
        metrics = json.loads((folder / "metrics.json").read_text())
    except (OSError, ValueError):
        return None
    return metrics.get("run_id") if isinstance(metrics, dict) else None


def _config(folder: Path) -> dict | None:
    header = _header(folder)
    return header.get("config") if header is not None else None


def write_report(folder: str | Path) -> Path:
    folder = Path(folder)
    parts = [f"<h1>stylesync report: {html.escape(folder.name)}</h1>"]
    header = _header(folder)
    metrics_id = _metrics_run_id(folder)
    if header is not None and metrics_id is not None:
        if header.get("run_id") == metrics_id:
            parts.append(f"<p>run {html.escape(str(metrics_id))}: the session file and the metrics are of this run</p>")
        else:
            parts.append("<p><b>the metrics are not of the run in this folder's session file "
                         f"({html.escape(str(metrics_id))} against {html.escape(str(header.get('run_id')))})</b></p>")
    for name in ("metrics.json", "bench.json"):
        p = folder / name
        if p.is_file():
            try:
                data = json.loads(p.read_text(encoding="utf-8", errors="replace"))
            except ValueError as exc:  # a damaged file is reported, not a reason to write no report
                parts.append(f"<h2>{name}</h2><p><b>not readable as JSON</b> ({html.escape(str(exc))})</p>")
                continue
            if not isinstance(data, dict):
                parts.append(f"<h2>{name}</h2><p><b>not a JSON object</b></p>")
                continue
            rows = "".join(f"<tr><td>{html.escape(k)}</td><td>{html.escape(v)}</td></tr>"
                           for k, v in _flatten(data))
            parts.append(f"<h2>{name}</h2><table>{rows}</table>")
    for name in ("bench.md", "dev_suite.md"):
        md = folder / name
        if md.is_file():
            parts.append(f"<h2>{name}</h2><pre>{html.escape(md.read_text(encoding='utf-8', errors='replace'))}</pre>")
    for png in sorted(folder.glob("*.png")):
        b64 = base64.b64encode(png.read_bytes()).decode()
        parts.append(f"<h2>{html.escape(png.name)}</h2><img src='data:image/png;base64,{b64}'>")
    cfg = _config(folder)
    if cfg is not None:
        parts.append(f"<h2>configuration</h2><pre>{html.escape(json.dumps(cfg, indent=1))}</pre>")
    vrows = "".join(f"<tr><td>{k}</td><td>{html.escape(v)}</td></tr>" for k, v in _versions().items())
    parts.append(f"<h2>versions</h2><table>{vrows}</table>")
    style = ("body{font-family:sans-serif;max-width:1100px;margin:auto}table{border-collapse:collapse}"
             "td{border:1px solid #ccc;padding:2px 8px;font-size:13px}img{max-width:100%}")
    out = folder / "report.html"
    write_atomically(out, f"<!doctype html><meta charset='utf-8'><title>stylesync report</title><style>{style}</style>"
                     + "".join(parts))
    return out
