"""MuJoCo's side of the rest-agreement generator (src/agreement): replay exported scenes.

usage: agreement_mujoco.py LIST.json

LIST.json: [{"dir": EXPORT_DIR, "diagonals": {body: m}, "settled": bool, "settle_s": s}, ...]. For
each scene,
prints one JSON line on stdout:
- from the "composed" keyframe: simulate the entry's "settle_s" seconds (default 6 s, our settle
  cap) to settle, then 1 s (rest). A free body passes when
  its centre of mass moved at most 10 % of its bounding-box diagonal over the settle part and at
  most 1 mm / 1 degree over the rest part (the settle test's rule); the scene passes when all do;
  the turn over the settle part is reported too (settle_deg, and the start and end orientations
  settle_q0/settle_q1 as w, x, y, z): the caller applies the settle test's large-turn rule, which
  needs the hulls;
- from the "settled" keyframe (the exported pose; "composed" if there is none): the worst
  displacement and turn of each body over 2 s.
Body positions are MuJoCo's xpos: the body frame, which the export puts at the centre of mass.
"""
import json
import math
import os
import sys
import time

import mujoco
import numpy as np

# The settle part: as long as our settle test may take (SettleOptions::settle_max_time); the
# caller passes it per scene as "settle_s".
SETTLE_S = 6.0
REST_S = 1.0
FROM_SETTLED_S = 2.0


def angle_deg(q0, q1):
    d = abs(float(np.dot(q0, q1)))
    return math.degrees(2.0 * math.acos(min(1.0, d)))


def free_bodies(model):
    return [b for b in range(1, model.nbody) if model.body_jntnum[b] > 0]


def reset(model, data, key):
    mujoco.mj_resetData(model, data)
    if model.nkey > 0:
        names = [model.key(k).name for k in range(model.nkey)]
        k = key if key in names else "composed"
        if k in names:
            mujoco.mj_resetDataKeyframe(model, data, model.key(k).id)
    mujoco.mj_forward(model, data)


def run(model, data, seconds, bodies, start):
    """Simulate `seconds`; worst displacement and turn of each body from `start`."""
    worst = {b: [0.0, 0.0] for b in bodies}
    end = data.time + seconds
    finite = True
    while data.time < end - 1e-9:
        mujoco.mj_step(model, data)
        if not np.all(np.isfinite(data.qpos)):
            finite = False
            break
        for b in bodies:
            p0, q0 = start[b]
            worst[b][0] = max(worst[b][0], float(np.linalg.norm(data.xpos[b] - p0)))
            worst[b][1] = max(worst[b][1], angle_deg(q0, data.xquat[b]))
    return worst, finite


def snapshot(data, bodies):
    return {b: (data.xpos[b].copy(), data.xquat[b].copy()) for b in bodies}


def judge(entry):
    t0 = time.time()
    model = mujoco.MjModel.from_xml_path(os.path.join(entry["dir"], "scene.xml"))
    data = mujoco.MjData(model)
    bodies = free_bodies(model)
    names = {b: model.body(b).name for b in bodies}
    diag = entry["diagonals"]

    reset(model, data, "composed")
    composed = snapshot(data, bodies)
    _, finite1 = run(model, data, entry.get("settle_s", SETTLE_S), bodies, composed)
    settle = {b: float(np.linalg.norm(data.xpos[b] - composed[b][0])) for b in bodies}
    turned = {b: data.xquat[b].copy() for b in bodies}
    rest, finite2 = run(model, data, REST_S, bodies, snapshot(data, bodies))
    passed = finite1 and finite2
    out = {}
    for b in bodies:
        ok = settle[b] <= 0.10 * diag.get(names[b], float("inf")) and rest[b][0] <= 1e-3 and rest[b][1] <= 1.0
        passed = passed and ok
        out[names[b]] = {
            "settle_m": settle[b],
            "settle_deg": angle_deg(composed[b][1], turned[b]),
            "settle_q0": [float(x) for x in composed[b][1]],
            "settle_q1": [float(x) for x in turned[b]],
            "rest_m": rest[b][0],
            "rest_deg": rest[b][1],
        }

    reset(model, data, "settled")
    worst, finite3 = run(model, data, FROM_SETTLED_S, bodies, snapshot(data, bodies))
    for b in bodies:
        out[names[b]]["from_settled_m"] = worst[b][0]
        out[names[b]]["from_settled_deg"] = worst[b][1]
    return {
        "dir": entry["dir"],
        "passed": bool(passed),
        "finite": bool(finite1 and finite2 and finite3),
        "bodies": out,
        "seconds": time.time() - t0,
    }


def main():
    with open(sys.argv[1]) as f:
        entries = json.load(f)
    for e in entries:
        print(json.dumps(judge(e), sort_keys=True), flush=True)


if __name__ == "__main__":
    main()
