#!/usr/bin/env python3
"""Reference decompositions for examples/bench_decompose.rs: CoACD and V-HACD 4 (vhacdx).

Reads every `<name>.obj` in --in (triangles, metres, written by the bench), runs the engines
that are installed (`pip install coacd vhacdx`) and writes, per mesh and engine,
`<name>.<engine>.hulls.obj` into --out: one `o hull_<k>` group per hull, global 1-based
indices, and `<name>.<engine>.json` with the wall time (s) or the error; a run whose json
exists is not repeated (resumable). `results.json` in --out collects them all. The Rust
bench measures the hulls with the same metric code as its own engines.

Settings:
  coacd   defaults of coacd.run_coacd (threshold 0.05, no hull limit, no vertex limit:
          max_ch_vertex 256 applies only with decimate, which is off by default;
          seed 0) -- the configuration the issue measured.
  coacd32 coacd.run_coacd at the engine limits: max_convex_hull 32, decimate on with
          max_ch_vertex 64 (CoACD applies the vertex limit only with decimate),
          other parameters at their defaults (seed 0) -- the like-for-like comparison.
  vhacd   vhacdx.compute_vhacd with the engine limits: maxConvexHulls 32,
          maxNumVerticesPerCH 64, other parameters at their defaults (resolution 400000).
"""

import argparse
import json
import os
import sys
import time


def read_obj(path):
    vs, fs = [], []
    with open(path) as f:
        for line in f:
            p = line.split()
            if not p:
                continue
            if p[0] == "v":
                vs.append([float(x) for x in p[1:4]])
            elif p[0] == "f":
                idx = [int(x.split("/")[0]) - 1 for x in p[1:]]
                for k in range(1, len(idx) - 1):
                    fs.append([idx[0], idx[k], idx[k + 1]])
    return vs, fs


def write_hulls(path, hulls):
    off = 1
    with open(path, "w") as f:
        for k, (v, t) in enumerate(hulls):
            f.write(f"o hull_{k}\n")
            for p in v:
                f.write(f"v {float(p[0])!r} {float(p[1])!r} {float(p[2])!r}\n")
            for tri in t:
                f.write(f"f {int(tri[0]) + off} {int(tri[1]) + off} {int(tri[2]) + off}\n")
            off += len(v)


def run_coacd(vs, fs):
    import coacd
    import numpy as np

    coacd.set_log_level("error")
    mesh = coacd.Mesh(np.asarray(vs, dtype=np.float64), np.asarray(fs, dtype=np.int32))
    parts = coacd.run_coacd(mesh, seed=0)
    return [(np.asarray(v), np.asarray(t)) for v, t in parts]


def run_coacd32(vs, fs):
    import coacd
    import numpy as np

    coacd.set_log_level("error")
    mesh = coacd.Mesh(np.asarray(vs, dtype=np.float64), np.asarray(fs, dtype=np.int32))
    parts = coacd.run_coacd(mesh, max_convex_hull=32, decimate=True, max_ch_vertex=64, seed=0)
    return [(np.asarray(v), np.asarray(t)) for v, t in parts]


def run_vhacd(vs, fs):
    import numpy as np
    import vhacdx

    return vhacdx.compute_vhacd(
        np.asarray(vs, dtype=np.float64),
        np.asarray(fs, dtype=np.uint32),
        maxConvexHulls=32,
        maxNumVerticesPerCH=64,
    )


ENGINES = {"coacd": run_coacd, "coacd32": run_coacd32, "vhacd": run_vhacd}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--in", dest="inp", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--engines", default="coacd,coacd32,vhacd")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    results = {}
    previous = {}
    try:
        with open(os.path.join(a.out, "results.json")) as f:
            previous = json.load(f)
    except (OSError, ValueError):
        pass
    # Inputs only: with --in and --out the same folder (bench_decompose --ref-dir), the hulls
    # written there are .obj files too.
    names = sorted(
        n[:-4]
        for n in os.listdir(a.inp)
        if n.endswith(".obj") and not n.endswith(".hulls.obj")
    )
    for name in names:
        vs, fs = read_obj(os.path.join(a.inp, name + ".obj"))
        results[name] = {}
        for eng in a.engines.split(","):
            done = os.path.join(a.out, f"{name}.{eng}.json")
            if os.path.exists(done):  # resumable: a finished run is kept
                with open(done) as f:
                    results[name][eng] = json.load(f)
                continue
            if eng in previous.get(name, {}) and "seconds" in previous[name][eng]:
                results[name][eng] = previous[name][eng]
                continue
            try:
                t0 = time.perf_counter()
                hulls = ENGINES[eng](vs, fs)
                dt = time.perf_counter() - t0
                write_hulls(os.path.join(a.out, f"{name}.{eng}.hulls.obj"), hulls)
                results[name][eng] = {"seconds": dt, "hulls": len(hulls)}
            except Exception as e:  # missing package or engine failure: reported, not fatal
                results[name][eng] = {"error": f"{type(e).__name__}: {e}"}
            with open(done, "w") as f:
                json.dump(results[name][eng], f)
            print(f"{name} {eng}: {results[name][eng]}", file=sys.stderr, flush=True)
    with open(os.path.join(a.out, "results.json"), "w") as f:
        json.dump(results, f, indent=1, sort_keys=True)


if __name__ == "__main__":
    main()
