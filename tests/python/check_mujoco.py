"""Load an interact3d export in MuJoCo and report what MuJoCo sees, as JSON on stdout.

usage: check_mujoco.py OUT_DIR [--seconds S] [--key NAME]

Reports: body and geom counts per body, the contact dimensionality of the collision geoms (condim),
masses and inertias as MuJoCo compiled them, the deepest initial contact between different bodies,
per-body motion after S seconds (position change in m, rotation angle in degrees) and final body
positions, whether the state stayed finite, and which free bodies moved more than 1 mm / 1 degree. Also loads every <object>.xml alone and all of them through <include>.
"""
import json
import math
import os
import sys
import tempfile

import mujoco
import numpy as np


def quat_angle_deg(q0, q1):
    d = abs(float(np.dot(q0, q1)) / (np.linalg.norm(q0) * np.linalg.norm(q1)))
    return math.degrees(2.0 * math.acos(min(1.0, d)))


def main():
    out = sys.argv[1]
    seconds = 1.0
    key = None
    args = sys.argv[2:]
    while args:
        a = args.pop(0)
        if a == "--seconds":
            seconds = float(args.pop(0))
        elif a == "--key":
            key = args.pop(0)
    model = mujoco.MjModel.from_xml_path(os.path.join(out, "scene.xml"))
    data = mujoco.MjData(model)
    if key is not None:
        mujoco.mj_resetDataKeyframe(model, data, model.key(key).id)
    mujoco.mj_forward(model, data)

    bodies = {}
    for b in range(1, model.nbody):
        name = model.body(b).name
        geoms = [g for g in range(model.ngeom) if model.geom_bodyid[g] == b]
        bodies[name] = {
            "mass": float(model.body_mass[b]),
            "inertia_principal": [float(x) for x in model.body_inertia[b]],
            "visual_geoms": sum(1 for g in geoms if model.geom_group[g] == 2),
            "collision_geoms": sum(1 for g in geoms if model.geom_group[g] == 3),
            "collision_condim": sorted({int(model.geom_condim[g]) for g in geoms if model.geom_group[g] == 3}),
            "free": bool(model.body_jntnum[b] > 0),
        }

    deepest = 0.0
    deepest_pair = None
    for i in range(data.ncon):
        c = data.contact[i]
        b1 = model.geom_bodyid[c.geom1]
        b2 = model.geom_bodyid[c.geom2]
        if b1 != b2 and b1 != 0 and b2 != 0 and -c.dist > deepest:
            deepest = float(-c.dist)
            deepest_pair = [model.body(b1).name, model.body(b2).name]

    start = {}
    for b in range(1, model.nbody):
        start[model.body(b).name] = (data.xpos[b].copy(), data.xquat[b].copy())
    finite = True
    while data.time < seconds:
        mujoco.mj_step(model, data)
        if not np.all(np.isfinite(data.qpos)):
            finite = False
            break
    motion = {}
    final_pos = {}
    for b in range(1, model.nbody):
        final_pos[model.body(b).name] = [float(x) for x in data.xpos[b]]
        name = model.body(b).name
        p0, q0 = start[name]
        motion[name] = {
            "moved_m": float(np.linalg.norm(data.xpos[b] - p0)),
            "turned_deg": quat_angle_deg(q0, data.xquat[b]),
        }

    # Each object file alone, and all of them included into one model.
    objects_ok = {}
    includes = []
    for name in bodies:
        path = os.path.join(out, name + ".xml")
        m = mujoco.MjModel.from_xml_path(path)
        objects_ok[name] = {
            "nbody": int(m.nbody),
            "mass": float(m.body_mass[1]),
            "collision_condim": sorted({int(m.geom_condim[g]) for g in range(m.ngeom) if m.geom_group[g] == 3}),
        }
        includes.append('<include file="%s.xml"/>' % name)
    with tempfile.NamedTemporaryFile("w", suffix=".xml", dir=out, delete=False) as f:
        f.write('<mujoco model="includes">%s</mujoco>' % "".join(includes))
        wrapper = f.name
    try:
        inc = mujoco.MjModel.from_xml_path(wrapper)
        include_nbody = int(inc.nbody)
    finally:
        os.unlink(wrapper)

    json.dump(
        {
            "nbody": int(model.nbody),
            "ngeom": int(model.ngeom),
            "nkey": int(model.nkey),
            "bodies": bodies,
            "initial_penetration": deepest,
            "initial_penetration_pair": deepest_pair,
            "finite": finite,
            "motion": motion,
            "final_pos": final_pos,
            "objects": objects_ok,
            "include_nbody": include_nbody,
        },
        sys.stdout,
        indent=1,
        sort_keys=True,
    )


if __name__ == "__main__":
    main()
