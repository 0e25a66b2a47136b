"""Link volumes from a body point cloud by the micro-cuboid method (Sec. 4.2, Eq. 2-5).

The cloud is seen along the body's sagittal axis (its forward direction): the coronal plane (lateral y, vertical
z) is cut into square cells of side about ``cell_m`` that tile the cloud's extent exactly; in each cell the
thickness of the body is the distance between its front-most and back-most points (Eq. 3, t_pc = |pc_f - pc_b|),
the micro cuboid's volume is the cell area times that thickness (Eq. 4) and the volumes add up (Eq. 5). The paper
uses the sensor's point grid as the cells; a regular grid does the same for clouds from any source (PLY scans,
synthetic bodies). The cloud must be dense enough that every cell holds points of both surfaces (about ten points
per cell face; 3 mm cells need about 1 point per mm^2). For a link's volume the cloud is first split by link: each
point goes to the nearest link axis (the segment between the link's two joints, Eq. 1). Link masses are then the
total mass shared by volume proportion (Eq. 2).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from stylesync.errors import SourceError


def load_point_cloud(path: str | Path) -> np.ndarray:
    """Points (n, 3) [m] from a ``.npy`` array or a PLY file (vertex x, y, z)."""
    p = Path(path)
    if not p.is_file():
        raise SourceError(f"point cloud not found: {p}")
    try:
        if p.suffix.lower() == ".npy":
            pts = np.load(p, allow_pickle=False)
        elif p.suffix.lower() == ".ply":
            from plyfile import PlyData

            v = PlyData.read(str(p))["vertex"]
            pts = np.stack([np.asarray(v["x"]), np.asarray(v["y"]), np.asarray(v["z"])], axis=1)
        else:
            raise SourceError(f"point cloud {p}: expected a .ply or .npy file")
    except SourceError:
        raise
    except Exception as exc:  # noqa: BLE001 - numpy/plyfile raise many kinds on a bad file
        raise SourceError(f"point cloud {p} could not be read: {type(exc).__name__}: {exc}".splitlines()[0]) from None
    pts = np.asarray(pts, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) < 4:
        raise SourceError(f"point cloud {p}: expected an (n, 3) array of points, got shape {pts.shape}")
    if not np.all(np.isfinite(pts)):
        raise SourceError(f"point cloud {p} contains NaN or infinite values")
    return pts


def micro_cuboid_volume(points_body: np.ndarray, cell_m: float = 0.003) -> float:
    """Eq. 3-5: volume [m^3] of a closed surface sampled by ``points_body`` (n, 3), body axes (x sagittal)."""
    if len(points_body) == 0:
        return 0.0
    yz = points_body[:, 1:]
    lo, extent = yz.min(axis=0), np.ptp(yz, axis=0)
    n_cells = np.maximum(np.ceil(extent / cell_m), 1).astype(np.int64)
    size = np.where(extent > 0, extent / n_cells, cell_m)  # cells tile the cloud's extent exactly
    cells = np.minimum(np.floor((yz - lo) / size).astype(np.int64), n_cells - 1)
    key = cells[:, 0] * n_cells[1] + cells[:, 1]
    order = np.argsort(key, kind="stable")
    key_sorted, x = key[order], points_body[order, 0]
    starts = np.flatnonzero(np.r_[True, key_sorted[1:] != key_sorted[:-1]])
    thickness = np.maximum.reduceat(x, starts) - np.minimum.reduceat(x, starts)  # Eq. 3, front minus back
    return float(np.sum(size[0] * size[1] * thickness))  # Eq. 4, summed as Eq. 5


def _distance_to_segments(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distances (n, k) from points (n, 3) to segments a[k] -> b[k]."""
    ab = b - a  # (k, 3)
    ap = points[:, None, :] - a[None]  # (n, k, 3)
    t = np.clip(np.sum(ap * ab[None], axis=2) / np.maximum(np.sum(ab * ab, axis=1), 1e-12)[None], 0.0, 1.0)
    closest = a[None] + t[..., None] * ab[None]
    return np.linalg.norm(points[:, None, :] - closest, axis=2)


def link_volumes(points_world: np.ndarray, links: dict[str, tuple[np.ndarray, np.ndarray]], heading_rad: float,
                 cell_m: float = 0.003) -> dict[str, float]:
    """Volume [m^3] per link: points split by nearest link axis, each part measured by Eq. 3-5 in the body axes
    (x forward along ``heading_rad``)."""
    c, s = np.cos(heading_rad), np.sin(heading_rad)
    R_body_world = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
    names = list(links)
    a = np.array([links[n][0] for n in names])
    b = np.array([links[n][1] for n in names])
    owner = np.empty(len(points_world), dtype=np.int64)
    for start in range(0, len(points_world), 20000):  # bounded memory for large clouds
        chunk = points_world[start:start + 20000]
        owner[start:start + len(chunk)] = np.argmin(_distance_to_segments(chunk, a, b), axis=1)
    body = points_world @ R_body_world.T
    return {n: micro_cuboid_volume(body[owner == k], cell_m) for k, n in enumerate(names)}


def masses_by_volume(volumes: dict[str, float], total_mass_kg: float) -> dict[str, float]:
    """Eq. 2: m_i = m_total * vp_i, vp_i the link's share of the summed volume."""
    total = sum(volumes.values())
    if total <= 0:
        raise SourceError("point cloud gives zero body volume")
    return {n: total_mass_kg * v / total for n, v in volumes.items()}
