"""MuJoCo's own view of an MJCF asset, as JSON on stdout (the judge of tests/assets.rs).

usage: check_asset_mujoco.py MODEL.xml [--seconds S]

Reports whether MuJoCo loads the model (and its error if not), the deepest contact between two
different bodies and between a body and the world's plane after mj_forward (keyframe 0 when the
model has one), and every free body's centre-of-mass motion (m) and rotation (degrees) over S
seconds (default 2).
"""
import json
import math
import sys

import mujoco
import numpy as np


def main():
    path = sys.argv[1]
    seconds = float(sys.argv[sys.argv.index("--seconds") + 1]) if "--seconds" in sys.argv else 2.0
    try:
        model = mujoco.MjModel.from_xml_path(path)
    except Exception as e:  # MuJoCo refuses the model: say why
        print(json.dumps({"loads": False, "error": str(e)}))
        return
    data = mujoco.MjData(model)
    if model.nkey > 0:
        mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    body_pen, floor_pen = 0.0, 0.0
    for c in data.contact[: data.ncon]:
        b1, b2 = model.geom_bodyid[c.geom1], model.geom_bodyid[c.geom2]
        plane = mujoco.mjtGeom.mjGEOM_PLANE
        if model.geom_type[c.geom1] == plane or model.geom_type[c.geom2] == plane:
            floor_pen = max(floor_pen, -c.dist)
        elif b1 != b2:
            body_pen = max(body_pen, -c.dist)
    free = [b for b in range(model.nbody) if model.body_jntnum[b] > 0
            and model.jnt_type[model.body_jntadr[b]] == mujoco.mjtJoint.mjJNT_FREE]
    start = {b: (data.xipos[b].copy(), data.xquat[b].copy()) for b in free}
    steps = int(round(seconds / model.opt.timestep))
    for _ in range(steps):
        mujoco.mj_step(model, data)
    motion = {}
    for b in free:
        p0, q0 = start[b]
        d = abs(float(np.dot(q0, data.xquat[b])))
        motion[model.body(b).name] = {
            "moved": float(np.linalg.norm(data.xipos[b] - p0)),
            "turned_deg": math.degrees(2.0 * math.acos(min(1.0, d))),
        }
    print(json.dumps({
        "loads": True,
        "body_penetration": body_pen,
        "floor_penetration": floor_pen,
        "motion": motion,
        "finite": bool(np.all(np.isfinite(data.qpos))),
    }))


if __name__ == "__main__":
    main()
