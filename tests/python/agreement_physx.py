"""PhysX's side of the rest-agreement generator (src/agreement): replay exported scenes' USD.

usage: agreement_physx.py LIST.json

Same input and output as agreement_mujoco.py (one JSON line per scene on stdout), with PhysX
(ovphysx, CPU) simulating OUT/scene.usda instead of MuJoCo simulating OUT/scene.xml:
- from the composed pose (customData "interact3d" composedTranslation/composedOrientation of each
  object prim, written into a copy of scene.usda beside it): simulate "settle_s" (default 6 s, our
  settle cap) to settle, then 1 s
  (rest). A free body passes when its centre of mass moved at most 10 % of its bounding-box
  diagonal over the settle part and at most 1 mm / 1 degree over the rest part; the scene passes
  when all do; the turn over the settle part is reported (settle_deg, settle_q0, settle_q1 as
  w, x, y, z) for the caller's large-turn rule;
- from scene.usda as exported (the settled pose): the worst displacement and turn of each body
  over 2 s;
- when the entry says "nudge": true, also "nudged": PhysX's verdict by the same rule from the
  composed pose nudged as our validator nudges it (each free body in turn: 0.5 deg about +-x,
  +-y through its centre of mass, then 0.5 mm along +-x, +-y; 8 starts a body), so a caller
  can tell a verdict PhysX itself would flip under a nudge from one it holds.
Poses are PhysX's rigid-body poses, read every step of the rest parts (every 24th of the settle part) (the export puts the body frame at the
centre of mass). Time step 1/240 s, PhysX's defaults otherwise (what scene.usda says).
Engine chatter goes to stderr.
"""
import gc
import json
import os
import sys
import time

import numpy as np

DT = 1.0 / 240.0
# The settle part: as long as our settle test may take (SettleOptions::settle_max_time); the
# caller passes it per scene as "settle_s".
SETTLE_S = 6.0
REST_S = 1.0
FROM_SETTLED_S = 2.0
# Over the settle part only the end pose counts (and that every pose stays finite, which a
# non-finite pose never recovers from): read every 24 steps (10 Hz). Reading every step cost
# 3x the whole judge (4 ms a read, 0.15 ms a step, ovphysx CPU, 2-body scene) and gives the
# same verdicts.
SETTLE_READ_EVERY = 24
# An entry with "nudge": true also gets PhysX's verdict from nudged composed poses, as
# src/validate/nudge.rs nudges ours (NUDGE_M, NUDGE_DEG there).
NUDGE_M = 5e-4
NUDGE_DEG = 0.5


# The PhysX driver's helpers (this folder is the script's own, first on sys.path).
from check_usd import quat_angle_deg as angle_deg
from check_usd import read_rigid_bodies, start_physx, stdout_to_stderr


def wxyz(q):
    """PhysX orientations are (x, y, z, w)."""
    return [float(q[3]), float(q[0]), float(q[1]), float(q[2])]


def composed_copy(scene_dir):
    """scene.usda with every object prim moved to its composed pose, written beside it (so the
    object references resolve); returns (path, {prim path: object name})."""
    from pxr import Gf, Usd

    stage = Usd.Stage.Open(os.path.join(scene_dir, "scene.usda"))
    names = {}
    for prim in stage.GetPseudoRoot().GetChild("World").GetChildren():
        custom = prim.GetCustomDataByKey("interact3d")
        if not custom:
            continue
        names[str(prim.GetPath())] = custom["name"]
        t = custom.get("composedTranslation")
        q = custom.get("composedOrientation")
        if t is not None and q is not None:
            prim.GetAttribute("xformOp:translate").Set(Gf.Vec3d(*t))
            prim.GetAttribute("xformOp:orient").Set(Gf.Quatd(q.GetReal(), q.GetImaginary()))
    path = os.path.join(scene_dir, "scene_composed.usda")
    stage.GetRootLayer().Export(path)
    return path, names


class Run:
    """One PhysX world on one USD file."""

    def __init__(self, path):
        import ovstage
        from ovphysx import PhysX

        self.physx = PhysX()
        self.stage = ovstage.Stage("interact3d-agreement")
        ovstage.population.open_usd(
            self.stage, path, ordinal=1, domains=ovstage.PopulationDomain.ALL
        )
        self.stage.advance_write_floor(ordinal=1).wait()
        self.physx.wait_task(self.physx.attach_ovstage(self.stage, read_ordinal=1))

    def poses(self):
        rows = read_rigid_bodies(self.physx, ["position", "orientation"])
        return {p: (r["position"], r["orientation"]) for p, r in rows.items() if len(r) == 2}

    def run(self, seconds, start, every=1):
        """Step `seconds`; worst displacement and turn of each body from `start`, read every
        `every` steps and after the last (a read costs about 25 steps of a small scene, so the
        settle part, whose worst is not used, reads only to see that the poses stay finite)."""
        worst = {p: [0.0, 0.0] for p in start}
        finite = True
        n = int(round(seconds / DT))
        for k in range(n):
            self.physx.step_sync(DT)
            if (k + 1) % every != 0 and k + 1 != n:
                continue
            now = self.poses()
            for p, (x0, q0) in start.items():
                x, q = now.get(p, (x0, q0))
                if not (np.all(np.isfinite(x)) and np.all(np.isfinite(q))):
                    finite = False
                    continue
                worst[p][0] = max(worst[p][0], float(np.linalg.norm(x - x0)))
                worst[p][1] = max(worst[p][1], angle_deg(q0, q))
        return worst, finite

    def close(self):
        gc.collect()
        self.physx.wait_all()
        self.physx.wait_task(self.physx.detach_ovstage())
        self.stage.destroy()
        self.physx.destroy()


def dynamic_only(poses, names):
    return {p: v for p, v in poses.items() if p in names}


def composed_verdict(path, names, diag, settle_s):
    """The verdict rule from the pose of the file at `path`: (passed, finite, composed poses,
    poses after the settle part, settle drift, rest part's worst) of every free body."""
    r = Run(path)
    composed = dynamic_only(r.poses(), names)
    _, finite1 = r.run(settle_s, composed, every=SETTLE_READ_EVERY)
    after = r.poses()
    settle = {p: float(np.linalg.norm(after[p][0] - composed[p][0])) for p in composed}
    rest, finite2 = r.run(REST_S, {p: after[p] for p in composed})
    r.close()
    passed = finite1 and finite2
    for p in composed:
        ok = settle[p] <= 0.10 * diag.get(names[p], float("inf")) and rest[p][0] <= 1e-3 and rest[p][1] <= 1.0
        passed = passed and ok
    return passed, finite1 and finite2, composed, after, settle, rest


def nudged_verdicts(scene_dir, composed_path, names, diag, settle_s):
    """PhysX's own verdict from the composed pose nudged as ours is (src/validate/nudge.rs
    `nudged_poses`): each free body in turn turned by NUDGE_DEG about world +x, -x, +y, -y
    through its centre of mass (the prim's origin: the export puts the body frame there), then
    shifted by NUDGE_M along +x, -x, +y, -y; 8 starts a free body, in that order."""
    from pxr import Gf, Sdf

    out = []
    path = os.path.join(scene_dir, "scene_nudged.usda")
    axes = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0)]
    for prim_path in names:
        for kind in range(2):
            for ax in axes:
                # A fresh copy of the composed layer each time, edited as a layer (no stage:
                # its object references resolve only beside scene.usda).
                layer = Sdf.Layer.CreateAnonymous(".usda")
                layer.TransferContent(Sdf.Layer.FindOrOpen(composed_path))
                if kind == 0:
                    spec = layer.GetAttributeAtPath(prim_path + ".xformOp:orient")
                    turn = Gf.Rotation(Gf.Vec3d(*ax), NUDGE_DEG).GetQuat()
                    spec.default = type(spec.default)(turn * Gf.Quatd(spec.default))
                else:
                    spec = layer.GetAttributeAtPath(prim_path + ".xformOp:translate")
                    t = spec.default
                    spec.default = type(t)(t[0] + NUDGE_M * ax[0], t[1] + NUDGE_M * ax[1], t[2])
                # Written beside scene.usda so the object references resolve.
                layer.Export(path)
                try:
                    out.append(bool(composed_verdict(path, names, diag, settle_s)[0]))
                finally:
                    os.remove(path)
    return out


def judge(entry):
    t0 = time.time()
    d = entry["dir"]
    diag = entry["diagonals"]
    settle_s = entry.get("settle_s", SETTLE_S)
    composed_path, names = composed_copy(d)
    out = {}
    nudged = None
    try:
        passed, finite12, composed, after, settle, rest = composed_verdict(
            composed_path, names, diag, settle_s
        )
        if entry.get("nudge"):
            nudged = nudged_verdicts(d, composed_path, names, diag, settle_s)
    finally:
        os.remove(composed_path)
    for p in composed:
        n = names[p]
        q0, q1 = wxyz(composed[p][1]), wxyz(after[p][1])
        out[n] = {
            "settle_m": settle[p],
            "settle_deg": angle_deg(q0, q1),
            "settle_q0": q0,
            "settle_q1": q1,
            "rest_m": rest[p][0],
            "rest_deg": rest[p][1],
        }

    r = Run(os.path.join(d, "scene.usda"))
    start = dynamic_only(r.poses(), names)
    worst, finite3 = r.run(FROM_SETTLED_S, start)
    r.close()
    for p in start:
        out[names[p]]["from_settled_m"] = worst[p][0]
        out[names[p]]["from_settled_deg"] = worst[p][1]
    res = {
        "dir": d,
        "passed": bool(passed),
        "finite": bool(finite12 and finite3),
        "bodies": out,
        "seconds": time.time() - t0,
    }
    if nudged is not None:
        res["nudged"] = nudged
    return res


def main():
    with open(sys.argv[1]) as f:
        entries = json.load(f)
    with stdout_to_stderr():
        import physx_usd_schemas

        physx_usd_schemas.register_all()
        start_physx()
    for e in entries:
        with stdout_to_stderr():
            res = judge(e)
        print(json.dumps(res, sort_keys=True), flush=True)


if __name__ == "__main__":
    main()
