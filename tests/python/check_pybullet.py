"""Load every URDF of an interact3d export in PyBullet (at its pose from scene.json, on a plane)
and report what PyBullet sees, as JSON on stdout.

usage: check_pybullet.py OUT_DIR [--seconds S] [--warmup W] [--max-warmup W]
"""
import json
import math
import os
import sys

import pybullet as p


def moved(a, b):
    (p0, q0), (p1, q1) = a, b
    d = abs(sum(x * y for x, y in zip(q0, q1)))
    return {"moved_m": math.dist(p0, p1), "turned_deg": math.degrees(2 * math.acos(min(1.0, d)))}


def main():
    out = sys.argv[1]
    seconds = 1.0
    warmup = 0.25
    max_warmup = 1.0
    if "--warmup" in sys.argv:
        warmup = float(sys.argv[sys.argv.index("--warmup") + 1])
    if "--max-warmup" in sys.argv:
        max_warmup = float(sys.argv[sys.argv.index("--max-warmup") + 1])
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
    # Bullet rests convex shapes a collision margin apart (1-3 mm at this scale, more with
    # many hulls in contact), so bodies placed in exact contact first rise by that much and drop
    # back; motion is measured once PyBullet has come to its own rest: every body slower than
    # 2 mm/s and 0.05 rad/s for 0.1 s (after at least `warmup`, at most `max_warmup` seconds).
    initial = {name: p.getBasePositionAndOrientation(bid) for name, bid in ids.items()}
    still_steps = 0
    steps = 0
    while steps * dt < max_warmup:
        p.stepSimulation()
        steps += 1
        still = all(
            math.hypot(*v) < 2e-3 and math.hypot(*w) < 0.05
            for v, w in (p.getBaseVelocity(bid) for bid in ids.values())
        )
        still_steps = still_steps + 1 if still else 0
        if steps * dt >= warmup and still_steps * dt >= 0.1:
            break
    warmup_used = steps * dt
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
    warmup_motion = {}
    for name, bid in ids.items():
        pos, orn = p.getBasePositionAndOrientation(bid)
        if not all(math.isfinite(v) for v in list(pos) + list(orn)):
            finite = False
        motion[name] = moved(start[name], (pos, orn))
        # What happened during the warm-up: a margin lift is a few mm without turning; a
        # topple or a slide is more.
        warmup_motion[name] = moved(initial[name], start[name])
    p.disconnect(cid)
    json.dump({"bodies": bodies, "finite": finite, "motion": motion, "warmup_motion": warmup_motion, "warmup_s": warmup_used}, sys.stdout, indent=1, sort_keys=True)


if __name__ == "__main__":
    main()
