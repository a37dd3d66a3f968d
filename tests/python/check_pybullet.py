"""Load every URDF of an interact3d export in PyBullet (at its pose from scene.json, on a plane)
and report what PyBullet sees, as JSON on stdout.

usage: check_pybullet.py OUT_DIR [--seconds S] [--warmup W]
"""
import json
import math
import os
import sys

import pybullet as p


def main():
    out = sys.argv[1]
    seconds = 1.0
    warmup = 0.25
    if "--warmup" in sys.argv:
        warmup = float(sys.argv[sys.argv.index("--warmup") + 1])
    if "--seconds" in sys.argv:
        seconds = float(sys.argv[sys.argv.index("--seconds") + 1])
    scene = json.load(open(os.path.join(out, "scene.json")))
    cid = p.connect(p.DIRECT)
    p.setGravity(0, 0, -9.81)
    plane = p.createCollisionShape(p.GEOM_PLANE)
    p.createMultiBody(0, plane)
    dt = 1.0 / 240.0
    p.setTimeStep(dt)
    ids = {}
    for o in scene["objects"]:
        pose = o["pose"]
        w, x, y, z = pose["quaternion_wxyz"]
        bid = p.loadURDF(
            os.path.join(out, o["name"] + ".urdf"),
            basePosition=pose["translation"],
            baseOrientation=[x, y, z, w],
            useFixedBase=bool(o.get("fixed", False)),
            flags=p.URDF_USE_INERTIA_FROM_FILE,
        )
        ids[o["name"]] = bid
    # Bullet rests convex shapes a collision margin (about 1 mm here) apart, so bodies placed
    # in exact contact first rise by that much; motion is measured after this warm-up.
    for _ in range(int(round(warmup / dt))):
        p.stepSimulation()
    bodies = {}
    start = {}
    for name, bid in ids.items():
        info = p.getDynamicsInfo(bid, -1)
        shapes = p.getCollisionShapeData(bid, -1)
        bodies[name] = {
            "mass": info[0],
            "inertia_diagonal": list(info[2]),
            "collision_shapes": len(shapes),
        }
        start[name] = p.getBasePositionAndOrientation(bid)
    finite = True
    for _ in range(int(round(seconds / dt))):
        p.stepSimulation()
    motion = {}
    for name, bid in ids.items():
        pos, orn = p.getBasePositionAndOrientation(bid)
        p0, q0 = start[name]
        if not all(math.isfinite(v) for v in list(pos) + list(orn)):
            finite = False
        d = abs(sum(a * b for a, b in zip(orn, q0)))
        motion[name] = {
            "moved_m": math.dist(pos, p0),
            "turned_deg": math.degrees(2 * math.acos(min(1.0, d))),
        }
    p.disconnect(cid)
    json.dump({"bodies": bodies, "finite": finite, "motion": motion}, sys.stdout, indent=1, sort_keys=True)


if __name__ == "__main__":
    main()
