"""MuJoCo's rolling friction on an incline (issue #33, tests/contact_statics.rs): a cylinder of
SIDES facets (r 2 cm, 10 cm long, 0.2 kg, its axis across the slope, a face down) on a fixed
plate tilted by each DEG, with the contact settings of the MJCF export (templates/scene.xml.j2:
timestep 0.002, implicitfast, elliptic cone, noslip_iterations 10, solref 0.004 1, solimp
0.95 0.99 0.001, condim 6, friction MU 0.005 MU_R, MU 0.6 unless given). Prints JSON: {"moved":
[m, ...]}, the distance the cylinder's centre moved from 1 s to 3 s at each DEG.

Usage: incline_mujoco.py [--mu MU] SIDES MU_R DEG [DEG ...]"""
import json
import math
import sys

import mujoco
import numpy as np


def scene(sides, mu_r, deg, mu=0.6):
    r, length, m = 0.02, 0.1, 0.2
    half = math.pi / sides
    pts = []
    for k in range(sides):
        a = 2 * math.pi * k / sides + half
        for y in (-length / 2, length / 2):
            pts.append(f"{r * math.sin(a):.12f} {y} {-r * math.cos(a):.12f}")
    ia, it = 0.5 * m * r * r, m * (3 * r * r + length * length) / 12
    th = math.radians(deg)
    up = np.array([math.sin(th), 0.0, math.cos(th)])
    pos = up * (r * math.cos(half) + 1e-5)
    q = f"{math.cos(th / 2)} 0 {math.sin(th / 2)} 0"
    return f"""<mujoco><compiler inertiafromgeom="false"/>
<option timestep="0.002" gravity="0 0 -9.81" integrator="implicitfast" cone="elliptic" noslip_iterations="10"/>
<default><default class="c"><geom condim="6" solref="0.004 1" solimp="0.95 0.99 0.001" friction="{mu} 0.005 {mu_r}"/></default></default>
<asset><mesh name="cyl" vertex="{' '.join(pts)}"/></asset>
<worldbody>
<geom type="box" size="2 0.2 0.01" pos="{-0.01 * up[0]} 0 {-0.01 * up[2]}" quat="{q}" class="c"/>
<body pos="{pos[0]} {pos[1]} {pos[2]}" quat="{q}"><freejoint/>
<inertial pos="0 0 0" mass="{m}" diaginertia="{it} {ia} {it}"/><geom type="mesh" mesh="cyl" class="c"/></body>
</worldbody></mujoco>"""


def moved(sides, mu_r, deg, mu=0.6):
    m = mujoco.MjModel.from_xml_string(scene(sides, mu_r, deg, mu))
    d = mujoco.MjData(m)

    def at(t):
        while d.time < t - 1e-9:
            mujoco.mj_step(m, d)
        return d.qpos[:3].copy()

    a = at(1.0)
    return float(np.linalg.norm(at(3.0) - a))


if __name__ == "__main__":
    args = sys.argv[1:]
    mu = 0.6
    if args[:1] == ["--mu"]:
        mu, args = float(args[1]), args[2:]
    sides, mu_r = int(args[0]), float(args[1])
    print(json.dumps({"moved": [moved(sides, mu_r, float(x), mu) for x in args[2:]]}))
