"""MuJoCo's own view of an MJCF asset, as JSON on stdout (the judge of tests/assets.rs).

usage: check_asset_mujoco.py MODEL.xml [--seconds S] [--window W] [--free-lone-body LIFT]

Reports whether MuJoCo loads the model (and its error if not), the deepest contact between two
different bodies and between a body and the world's plane after mj_forward (keyframe 0 when the
model has one), and every free body's centre-of-mass motion (m) and rotation (degrees) over S
seconds (default 2), and over the last W of them (`window_motion`, default 1): "does it still
move once it had time to settle". --free-lone-body gives the world's first body a free joint,
lifts it by LIFT and adds a ground plane at z = 0 (an object model file checked as a free
object, as interact3d validate does).
"""
import json
import math
import sys

import mujoco
import numpy as np


def main():
    path = sys.argv[1]
    seconds = float(sys.argv[sys.argv.index("--seconds") + 1]) if "--seconds" in sys.argv else 2.0
    window = float(sys.argv[sys.argv.index("--window") + 1]) if "--window" in sys.argv else 1.0
    try:
        if "--free-lone-body" in sys.argv:
            lift = float(sys.argv[sys.argv.index("--free-lone-body") + 1])
            spec = mujoco.MjSpec.from_file(path)
            body = spec.worldbody.first_body()
            body.add_freejoint()
            body.pos = [body.pos[0], body.pos[1], body.pos[2] + lift]
            spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[2, 2, 0.1])
            model = spec.compile()
        else:
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
    # Every named geom's world centre, and a mesh geom's world bounding box of its vertices.
    geoms = {}
    for g in range(model.ngeom):
        name = model.geom(g).name
        if not name:
            continue
        info = {"pos": data.geom_xpos[g].tolist()}
        if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH:
            m = model.geom_dataid[g]
            v = model.mesh_vert[model.mesh_vertadr[m]:model.mesh_vertadr[m] + model.mesh_vertnum[m]]
            w = v @ data.geom_xmat[g].reshape(3, 3).T + data.geom_xpos[g]
            info["aabb"] = [w.min(axis=0).tolist(), w.max(axis=0).tolist()]
        geoms[name] = info
    free = [b for b in range(model.nbody) if model.body_jntnum[b] > 0
            and model.jnt_type[model.body_jntadr[b]] == mujoco.mjtJoint.mjJNT_FREE]
    start = {b: (data.xipos[b].copy(), data.xquat[b].copy()) for b in free}
    steps = int(round(seconds / model.opt.timestep))
    last = steps - int(round(window / model.opt.timestep))
    before = start
    for k in range(steps):
        if k == last:
            before = {b: (data.xipos[b].copy(), data.xquat[b].copy()) for b in free}
        mujoco.mj_step(model, data)

    def moved(b, frm):
        p0, q0 = frm[b]
        d = abs(float(np.dot(q0, data.xquat[b])))
        return {
            "moved": float(np.linalg.norm(data.xipos[b] - p0)),
            "turned_deg": math.degrees(2.0 * math.acos(min(1.0, d))),
        }

    motion = {model.body(b).name: moved(b, start) for b in free}
    window_motion = {model.body(b).name: moved(b, before) for b in free}
    print(json.dumps({
        "loads": True,
        "body_penetration": body_pen,
        "floor_penetration": floor_pen,
        "motion": motion,
        "window_motion": window_motion,
        "geoms": geoms,
        "finite": bool(np.all(np.isfinite(data.qpos))),
    }))


if __name__ == "__main__":
    main()
