#!/usr/bin/env python3
"""Independent check of the reference hulls' hulls -> mesh figure (trimesh + scipy, none of
our Rust code).

For every `<name>.<engine>.hulls.obj` in --ref (written by bench_reference.py) beside its input
`<name>.obj`, samples the hulls' surfaces by area, drops the samples within --seam (relative to
the mesh's bounding-box diagonal) of another hull (seams, inside the union, as
`metrics::surface_distances` does with 1e-6), and prints one JSON line:

  hulls             hulls read (flat ones, which qhull rejects, are skipped, as the bench does)
  bbox_dev          largest offset between the hulls' and the mesh's bounding boxes
  h2m_p95, h2m_max  union boundary -> mesh surface (the bench's "h->m")
  interior_share    share of those samples inside the mesh and > 1 % of the diagonal from its
                    surface: faces of hulls that do not meet, i.e. slots through the solid
  slot_gap_p10/p50  for those samples, how far they lie outside the nearest other hull
  h2m_p95_outside   the same p95 over the samples outside the mesh only (collision surface
                    standing proud of the object: protrusions, filled concavities)
  seam_sweep        h2m p95 with seams widened to 1e-4, 1e-3 and 1e-2 of the diagonal

Usage: check_reference_hulls.py --ref DIR [--engines coacd32,vhacd] [--samples 4000] [NAME...]
Needs numpy, scipy, trimesh and rtree (tests/python/requirements-check.txt).
"""

import argparse
import json
import os
import sys

import numpy as np
import trimesh
from scipy.spatial import ConvexHull


def read_obj(path):
    """Vertices, triangles (fan-split) and the vertex index where each `o` group starts."""
    vs, fs, starts = [], [], []
    with open(path) as f:
        for line in f:
            p = line.split()
            if not p:
                continue
            if p[0] == "o":
                starts.append(len(vs))
            elif p[0] == "v":
                vs.append([float(x) for x in p[1:4]])
            elif p[0] == "f":
                idx = [int(x.split("/")[0]) - 1 for x in p[1:]]
                for k in range(1, len(idx) - 1):
                    fs.append([idx[0], idx[k], idx[k + 1]])
    return np.array(vs), np.array(fs, dtype=np.int64), starts


class Hull:
    def __init__(self, pts):
        c = ConvexHull(pts)
        self.eq = c.equations  # n . x + d <= 0 inside, n outward
        self.mesh = trimesh.Trimesh(pts, c.simplices, process=False)
        self.area = c.area

    def outside(self, p):
        """Largest face-plane distance: > 0 outside (a lower bound of the distance)."""
        return (p @ self.eq[:, :3].T + self.eq[:, 3]).max(axis=1)


def check(ref, name, eng, n, seam):
    v, f, _ = read_obj(os.path.join(ref, name + ".obj"))
    mesh = trimesh.Trimesh(v, f, process=False)
    diag = float(np.linalg.norm(mesh.bounds[1] - mesh.bounds[0]))
    hv, _, starts = read_obj(os.path.join(ref, f"{name}.{eng}.hulls.obj"))
    bounds = list(zip(starts, starts[1:] + [len(hv)]))
    hulls = []
    for a, b in bounds:
        try:
            hulls.append(Hull(hv[a:b]))
        except Exception:  # flat: qhull has no 3-D hull of it
            print(f"{name} {eng}: flat hull (vertices {a}..{b}) skipped", file=sys.stderr)
    total = sum(h.area for h in hulls)
    pts, gaps = [], []
    for i, h in enumerate(hulls):
        p, _ = trimesh.sample.sample_surface(h.mesh, max(1, int(n * h.area / total)), seed=i)
        gap = np.full(len(p), np.inf)
        for j, g in enumerate(hulls):
            if j != i:
                gap = np.minimum(gap, g.outside(p))
        pts.append(p)
        gaps.append(gap / diag)
    p, gap = np.concatenate(pts), np.concatenate(gaps)
    _, d, _ = trimesh.proximity.closest_point(mesh, p)
    d = d / diag
    inside = mesh.contains(p)
    keep = gap > seam
    dk, ik, gk = d[keep], inside[keep], gap[keep]
    deep = ik & (dk > 0.01)
    hb = np.array([hv.min(axis=0), hv.max(axis=0)])
    return {
        "name": name,
        "engine": eng,
        "hulls": len(hulls),
        "bbox_dev": float(np.abs(hb - mesh.bounds).max() / diag),
        "h2m_p95": float(np.percentile(dk, 95)),
        "h2m_max": float(dk.max()),
        "interior_share": float(deep.mean()),
        "slot_gap_p10": float(np.percentile(gk[deep], 10)) if deep.any() else 0.0,
        "slot_gap_p50": float(np.median(gk[deep])) if deep.any() else 0.0,
        "h2m_p95_outside": float(np.percentile(dk[~ik], 95)) if (~ik).any() else 0.0,
        "seam_sweep": {
            str(t): float(np.percentile(d[gap > t], 95)) for t in (1e-4, 1e-3, 1e-2)
        },
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ref", required=True)
    ap.add_argument("--engines", default="coacd32,vhacd")
    ap.add_argument("--samples", type=int, default=4000)
    ap.add_argument("--seam", type=float, default=1e-6)
    ap.add_argument("names", nargs="*")
    a = ap.parse_args()
    names = a.names or sorted(
        x[: -len(".coacd32.hulls.obj")] for x in os.listdir(a.ref) if x.endswith(".coacd32.hulls.obj")
    )
    for name in names:
        for eng in a.engines.split(","):
            if os.path.exists(os.path.join(a.ref, f"{name}.{eng}.hulls.obj")):
                print(json.dumps(check(a.ref, name, eng, a.samples, a.seam)), flush=True)


if __name__ == "__main__":
    main()
