"""PyBullet's own view of a URDF asset, as JSON on stdout (the judge of tests/assets.rs).

usage: check_asset_pybullet.py FILE.urdf [--lift Z] [--seconds S] [--window W] [--fixed]
                               [--no-file-inertia | --inertia IXX IYY IZZ]

Loads the URDF on a ground plane at z = 0, with its base frame lifted by Z (the lift
interact3d's validate gives it: lowest collision point on the plane), with the inertia the file
writes (URDF_USE_INERTIA_FROM_FILE) unless --no-file-inertia (PyBullet's default then computes
it from the collision shapes' bounding boxes), or with the given principal moments
(changeDynamics localInertiaDiagonal, in the inertial frame's axes). Reports whether PyBullet loads it (and its error
if not), the deepest contact with the plane and between links of different bodies after one
collision detection, and the base's centre-of-mass motion (m) and rotation (degrees) over the
whole S seconds (default 4) and over the last W of them (default 1): "does it still move once
it had time to settle".
"""
import json
import math
import os
import sys

import pybullet as p


def arg(name, default):
    return type(default)(sys.argv[sys.argv.index(name) + 1]) if name in sys.argv else default


def moved(a, b):
    (p0, q0), (p1, q1) = a, b
    d = abs(sum(x * y for x, y in zip(q0, q1)))
    return {"moved": math.dist(p0, p1), "turned_deg": math.degrees(2 * math.acos(min(1.0, d)))}


def main():
    # Bullet's C++ side prints to stdout; keep stdout for the JSON.
    out = os.fdopen(os.dup(1), "w")
    os.dup2(2, 1)
    path = sys.argv[1]
    lift = arg("--lift", 0.0)
    seconds = arg("--seconds", 4.0)
    window = arg("--window", 1.0)
    own = "--no-file-inertia" in sys.argv or "--inertia" in sys.argv
    flags = 0 if own else p.URDF_USE_INERTIA_FROM_FILE
    cid = p.connect(p.DIRECT)
    p.setGravity(0, 0, -9.81)
    dt = 1.0 / 240.0
    p.setTimeStep(dt)
    plane = p.createMultiBody(0, p.createCollisionShape(p.GEOM_PLANE))
    try:
        body = p.loadURDF(path, basePosition=[0, 0, lift], flags=flags,
                          useFixedBase="--fixed" in sys.argv)
    except Exception as e:  # PyBullet refuses the file: say why
        print(json.dumps({"loads": False, "error": str(e)}), file=out)
        return
    if "--inertia" in sys.argv:
        k = sys.argv.index("--inertia")
        p.changeDynamics(body, -1, localInertiaDiagonal=[float(x) for x in sys.argv[k + 1:k + 4]])
    p.performCollisionDetection()
    floor_pen = 0.0
    for c in p.getContactPoints(bodyA=body, bodyB=plane):
        floor_pen = max(floor_pen, -c[8])
    info = p.getDynamicsInfo(body, -1)
    start = p.getBasePositionAndOrientation(body)
    steps = int(round(seconds / dt))
    last = steps - int(round(window / dt))
    before = start
    for k in range(steps):
        if k == last:
            before = p.getBasePositionAndOrientation(body)
        p.stepSimulation()
    end = p.getBasePositionAndOrientation(body)
    p.disconnect(cid)
    print(json.dumps({
        "loads": True,
        "mass": info[0],
        "inertia_diagonal": list(info[2]),
        "floor_penetration": floor_pen,
        "motion": moved(start, end),
        "window_motion": moved(before, end),
        "finite": all(math.isfinite(v) for v in list(end[0]) + list(end[1])),
    }), file=out)


if __name__ == "__main__":
    main()
