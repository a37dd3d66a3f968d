"""The recipes of docs/viewing.md, run: where MuJoCo puts each body of OUT/scene.xml, and where
PyBullet puts each OUT/<name>.urdf loaded with the pose from OUT/scene.json exactly as the doc
says (basePosition = pose.translation, baseOrientation = pose.quaternion_xyzw), plus the pose
written as a comment in each URDF. JSON on stdout.

usage: check_view.py OUT_DIR

Per object: "mujoco" (xpos, xquat as MuJoCo's w, x, y, z), "pybullet" (the link frame's position and
orientation as PyBullet's x, y, z, w; and the orientation getBasePositionAndOrientation gives,
which is the inertia's principal axes), "urdf_comment" (xyz, quaternion_xyzw as written) and "scene_json" (the
pose entry), each a plain list of numbers, so the caller compares them itself.
"""
import json
import os
import re
import sys

import mujoco
import pybullet as p


def main():
    out = sys.argv[1]
    scene = json.load(open(os.path.join(out, "scene.json")))

    # MuJoCo: the scene as the viewer opens it (`python -m mujoco.viewer --mjcf OUT/scene.xml`).
    model = mujoco.MjModel.from_xml_path(os.path.join(out, "scene.xml"))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)

    # PyBullet, as docs/viewing.md does it.
    cid = p.connect(p.DIRECT)
    result = {}
    for o in scene["objects"]:
        name = o["name"]
        pose = o["pose"]
        bid = p.loadURDF(
            os.path.join(out, name + ".urdf"),
            basePosition=pose["translation"],
            baseOrientation=pose["quaternion_xyzw"],
            useFixedBase=bool(o.get("fixed", False)),
            flags=p.URDF_USE_INERTIA_FROM_FILE,
        )
        # PyBullet reports a base's pose at its inertial frame, whose axes are the principal
        # axes of the inertia tensor it diagonalised; the URDF link frame is that pose times
        # the inverse of the base's local inertial frame.
        com_pos, com_orn = p.getBasePositionAndOrientation(bid)
        local = p.getDynamicsInfo(bid, -1)
        inv_pos, inv_orn = p.invertTransform(local[3], local[4])
        pos, orn = p.multiplyTransforms(com_pos, com_orn, inv_pos, inv_orn)
        body = model.body(name).id
        text = open(os.path.join(out, name + ".urdf")).read()
        m = re.search(r'xyz="([^"]*)" quaternion_xyzw="([^"]*)" rpy="([^"]*)"', text)
        result[name] = {
            "mujoco": {
                "xpos": [float(x) for x in data.xpos[body]],
                "xquat_wxyz": [float(x) for x in data.xquat[body]],
            },
            "pybullet": {
                "position": list(pos),
                "orientation_xyzw": list(orn),
                "inertial_orientation_xyzw": list(com_orn),
            },
            "urdf_comment": None
            if m is None
            else {
                "xyz": [float(x) for x in m.group(1).split()],
                "quaternion_xyzw": [float(x) for x in m.group(2).split()],
                "rpy": [float(x) for x in m.group(3).split()],
            },
            "scene_json": pose,
        }
    p.disconnect(cid)
    json.dump(result, sys.stdout, indent=1)


if __name__ == "__main__":
    main()
