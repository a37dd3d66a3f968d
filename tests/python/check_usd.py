"""Load an interact3d export's USD files with usd-core, UsdPhysics' parser, PhysX and Newton, and
report what each sees, as JSON on stdout (engine chatter goes to stderr).

usage: check_usd.py OUT_DIR [--seconds S] [--dt DT] [--no-physx] [--newton]

- "files": every *.usda opened by usd-core; "errors": what the registered UsdValidation
  validators (among them usdPhysicsValidators' RigidBodyChecker and ColliderChecker) reported.
- "usdphysics": what UsdPhysicsLoadStageFromPrimRange finds in scene.usda: per body, its shapes
  and their approximations, whether it is dynamic, its mass and the full inertia tensor rebuilt
  from diagonalInertia and principalAxes (I = R diag(d) R^T), its world pose; plus the scene.
- "physx_authored": every prim of the composed scene.usda with a Physx* API schema applied (usd-core
  with the PhysX schemas registered): its applied schemas and its physx* attribute values, and
  for materials their physics:staticFriction / dynamicFriction (the settings the export says our
  settle assumed; tests/usd.rs compares them with SettleOptions).
- "physx": scene.usda simulated S seconds (default 2) on the CPU by PhysX (ovphysx): per dynamic
  body, the displacement (m) and rotation (degrees) of its frame, and the mass PhysX took; and
  "cooked": the convex hulls PhysX collides with, read back from its debug geometry and compared
  with the authored hull points: every authored hull vertex must be a cooked vertex and the
  other way round (distances in m).
- "newton" (with --newton): Newton's ModelBuilder.add_usd on scene.usda and on each object file:
  bodies and shapes it built, and the diameters of the hulls it collides (scale applied) beside
  the authored ones (usd-core, world frame).
"""
import contextlib
import glob
import json
import math
import os
import sys

import numpy as np


def log(*a):
    print(*a, file=sys.stderr)


@contextlib.contextmanager
def stdout_to_stderr():
    """Engines print to stdout; keep ours for the JSON (file-descriptor level)."""
    sys.stdout.flush()
    saved = os.dup(1)
    os.dup2(2, 1)
    try:
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


def quat_matrix(w, x, y, z):
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def quat_angle_deg(q0, q1):
    d = abs(float(np.dot(q0, q1)) / (np.linalg.norm(q0) * np.linalg.norm(q1)))
    return math.degrees(2.0 * math.acos(min(1.0, d)))


def validate_files(out):
    from pxr import Usd, UsdValidation

    reg = UsdValidation.ValidationRegistry()
    validators = reg.GetOrLoadAllValidators()
    ctx = UsdValidation.ValidationContext(validators)
    files = {}
    for path in sorted(glob.glob(os.path.join(out, "*.usda"))):
        name = os.path.basename(path)
        stage = Usd.Stage.Open(path)
        if stage is None:
            files[name] = {"opened": False, "errors": ["usd-core could not open it"]}
            continue
        errors = []
        for e in ctx.Validate(stage):
            if e.HasNoError():
                continue
            errors.append(f"{e.GetIdentifier()}: {e.GetMessage()}")
        files[name] = {
            "opened": True,
            "errors": errors,
            "default_prim": stage.GetDefaultPrim().GetName() if stage.GetDefaultPrim() else None,
            "meters_per_unit": stage.GetMetadata("metersPerUnit"),
            "kilograms_per_unit": stage.GetMetadata("kilogramsPerUnit"),
            "up_axis": stage.GetMetadata("upAxis"),
            "validators": len(validators),
        }
    return files


def usd_physics(out):
    from pxr import Gf, Usd, UsdGeom, UsdPhysics

    stage = Usd.Stage.Open(os.path.join(out, "scene.usda"))
    parsed = UsdPhysics.UsdPhysicsLoadStageFromPrimRange(stage, ["/"])
    bodies, shapes, scenes = {}, {}, 0
    for otype, (paths, descs) in parsed.items():
        for path, desc in zip(paths, descs):
            if otype == UsdPhysics.ObjectType.Scene:
                scenes += 1
            elif otype == UsdPhysics.ObjectType.RigidBody:
                bodies[str(path)] = desc
            elif "Shape" in str(type(desc).__name__):
                shapes[str(path)] = (otype, desc)
    out_bodies = {}
    for path, desc in sorted(bodies.items()):
        prim = stage.GetPrimAtPath(path)
        mass_api = UsdPhysics.MassAPI(prim)
        d = [float(x) for x in mass_api.GetDiagonalInertiaAttr().Get()]
        q = mass_api.GetPrincipalAxesAttr().Get()
        r = quat_matrix(q.GetReal(), *q.GetImaginary())
        full = r @ np.diag(d) @ r.T
        com = [float(x) for x in mass_api.GetCenterOfMassAttr().Get()]
        xf = UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(Usd.TimeCode.Default())
        t = xf.ExtractTranslation()
        rot = xf.ExtractRotationQuat()
        custom = prim.GetCustomDataByKey("interact3d") or {}
        own = []
        for spath, (otype, sdesc) in sorted(shapes.items()):
            if str(sdesc.rigidBody) == path:
                approx = str(getattr(sdesc, "approximation", "")) if otype == UsdPhysics.ObjectType.MeshShape else str(otype)
                own.append({"path": spath, "approximation": approx})
        out_bodies[custom.get("name", prim.GetName())] = {
            "path": path,
            "dynamic": bool(desc.rigidBodyEnabled) and not bool(desc.kinematicBody),
            "mass": float(mass_api.GetMassAttr().Get()),
            "com": com,
            "diagonal_inertia": d,
            "inertia": full.tolist(),
            "position": [t[0], t[1], t[2]],
            "orientation": [rot.GetReal(), *rot.GetImaginary()],
            "composed_translation": list(custom.get("composedTranslation", [])),
            "shapes": own,
        }
    statics = sorted(
        p for p, (o, d) in shapes.items() if str(d.rigidBody) in ("", "None") or not str(d.rigidBody)
    )
    return {"scenes": scenes, "bodies": out_bodies, "static_shapes": statics}


def physx_authored(out):
    from pxr import Usd

    stage = Usd.Stage.Open(os.path.join(out, "scene.usda"))
    rows = {}
    for prim in stage.Traverse():
        schemas = [str(s) for s in prim.GetAppliedSchemas()]
        if not any(s.startswith("Physx") for s in schemas):
            continue
        attrs = {}
        for a in prim.GetAttributes():
            n = a.GetName()
            authored = n.startswith("physx") or n in ("physics:staticFriction", "physics:dynamicFriction")
            if authored and a.HasAuthoredValue():
                v = a.Get()
                attrs[n] = v if isinstance(v, str) else float(v) if v is not None else None
        rows[str(prim.GetPath())] = {"schemas": schemas, "attrs": attrs}
    return rows


def authored_hulls(out):
    """Authored hull points in the world frame, from the composed scene (usd-core)."""
    from pxr import Usd, UsdGeom, UsdPhysics

    stage = Usd.Stage.Open(os.path.join(out, "scene.usda"))
    hulls = []
    for prim in stage.Traverse():
        if prim.IsA(UsdGeom.Mesh) and prim.HasAPI(UsdPhysics.MeshCollisionAPI):
            xf = UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(Usd.TimeCode.Default())
            m = np.array(xf).T  # row-vector convention -> column
            pts = np.array(UsdGeom.Mesh(prim).GetPointsAttr().Get(), dtype=float)
            world = (m[:3, :3] @ pts.T).T + m[:3, 3]
            hulls.append((str(prim.GetPath()), world))
    return hulls


def read_rigid_bodies(physx, attrs):
    """Every rigid body's attributes `attrs` from a running ovphysx `PhysX`: {prim path: {attr:
    numpy array}} (shared with agreement_physx.py)."""
    from ovphysx.types import ObjectScope, SimObjectType

    rows = {}
    with physx.read_sync(SimObjectType.RIGID_BODY, attrs, scope=ObjectScope.ALL) as result:
        paths = result.dictionary
        for g in result.groups:
            if g.is_delete or g.is_array or not g.tensors:
                continue
            names = paths.get_path_strings(g.prim_list)
            attr = paths.token_to_string(g.attribute)
            vals = g.tensors[0].numpy().copy()
            for i, p in enumerate(names):
                rows.setdefault(p, {})[attr] = np.array(vals[i], dtype=float)
    return rows


def start_physx():
    """PhysX on the CPU (ovphysx's thread default), with the PhysX schemas (and Newton's, when
    ovphysx ships them) registered with ovstage; the PhysX drivers' shared start."""
    import ovphysx
    import ovstage
    from ovphysx import PhysX
    from ovphysx.samples.python_samples.schema_support import physx_schema_paths
    from ovphysx.types import GlobalConfigKey

    ovphysx.set_global_config(GlobalConfigKey.NUM_THREADS, 0)
    PhysX.set_cpu_mode(True)
    roots = [str(p) for p in physx_schema_paths()]
    try:
        roots.append(str(ovphysx.newton_schema_root()))
    except FileNotFoundError:
        pass
    ovstage.population.register_usd_schemas(roots)


def run_physx(out, seconds, dt):
    import ovstage
    from ovphysx import PhysX
    from ovphysx.types import SimObjectType

    start_physx()
    physx = PhysX()
    stage = ovstage.Stage("interact3d-check")
    ovstage.population.open_usd(
        stage, os.path.join(out, "scene.usda"), ordinal=1, domains=ovstage.PopulationDomain.ALL
    )
    stage.advance_write_floor(ordinal=1).wait()
    physx.wait_task(physx.attach_ovstage(stage, read_ordinal=1))

    def read_bodies(attrs):
        return {
            p: {a: v.tolist() for a, v in r.items()}
            for p, r in read_rigid_bodies(physx, attrs).items()
        }

    def debug_render(settings):
        # One attribute per debug-render write session.
        for name, value in settings.items():
            with physx.write_sync(SimObjectType.DEBUG_RENDER, [name]) as w:
                for g in w.groups:
                    for tensor in g.tensors:
                        buf = np.full(tuple(tensor.shape), value, dtype=tensor.numpy().dtype)
                        tensor.assign(buf)
                    w.commit_sync(g)

    debug_render({"enabled": 1, "scale": 1.0, "collisionShapes": 1.0})
    # The shipped pose, before any step (a tiny first step would turn a contact's last micrometre
    # into a depenetration kick: velocity = depth / dt).
    start = read_bodies(["position", "orientation", "mass"])
    physx.step_sync(dt)
    def read_lines():
        lines = []
        with physx.read_sync(SimObjectType.DEBUG_RENDER, ["linePosition"]) as result:
            for g in result.groups:
                if g.tensors:
                    lines.append(g.tensors[0].numpy().copy().reshape(-1, 3))
        return lines

    lines = read_lines()
    debug_render({"enabled": 0})
    steps = max(1, int(round(seconds / dt)))
    for _ in range(steps - 1):
        physx.step_sync(dt)
    end = read_bodies(["position", "orientation"])
    import gc

    gc.collect()
    physx.wait_all()
    physx.wait_task(physx.detach_ovstage())
    stage.destroy()
    physx.destroy()

    bodies = {}
    for p, s in start.items():
        e = end.get(p)
        if e is None:
            continue
        q0 = np.array(s["orientation"], dtype=float)
        q1 = np.array(e["orientation"], dtype=float)
        bodies[p] = {
            "moved_m": float(np.linalg.norm(np.array(e["position"]) - np.array(s["position"]))),
            "turned_deg": quat_angle_deg(q0, q1),
            "mass": float(np.ravel(s["mass"])[0]) if "mass" in s else None,
            "finite": bool(np.all(np.isfinite(e["position"])) and np.all(np.isfinite(e["orientation"]))),
        }
    cooked = np.unique(np.concatenate(lines), axis=0) if lines else np.zeros((0, 3))
    return {"bodies": bodies, "steps": steps, "dt": dt, "cooked_points": cooked}


def compare_cooked(hulls, cooked):
    """Authored hull vertices against the cooked debug-geometry vertices (both world frame)."""
    if len(hulls) == 0:
        return {"hulls": 0}
    authored = np.concatenate([h for _, h in hulls])
    lo = authored.min(axis=0) - 0.01
    hi = authored.max(axis=0) + 0.01
    near = cooked[np.all((cooked >= lo) & (cooked <= hi), axis=1)] if len(cooked) else cooked
    per_hull = []
    worst_authored = 0.0
    for path, pts in hulls:
        if len(near) == 0:
            d = np.full(len(pts), np.inf)
        else:
            d = np.min(np.linalg.norm(pts[:, None, :] - near[None, :, :], axis=2), axis=1)
        worst_authored = max(worst_authored, float(d.max()) if np.all(np.isfinite(d)) else 1e9)
        if len(near):
            dc = np.min(np.linalg.norm(near[:, None, :] - pts[None, :, :], axis=2), axis=1)
            mine = near[dc <= 1e-3]  # PhysX may shift a vertex by its plane tolerance
        else:
            mine = near
        try:
            from scipy.spatial import ConvexHull

            eq = ConvexHull(mine).equations
            dev = float(max(0.0, np.max(pts @ eq[:, :3].T + eq[:, 3])))
        except Exception:  # qhull refuses a flat or tiny cooked set: tests/usd.rs measures it
            dev = None
        per_hull.append(
            {
                "path": path,
                # How far the farthest authored vertex lies outside the cooked hull (plane
                # distance; tests/usd.rs measures it exactly).
                "deviation_m": dev,
                "vertices": int(len(pts)),
                "max_unmatched_m": float(d.max()) if np.all(np.isfinite(d)) else None,
                # World frame: the authored points, and the cooked vertices that are among them.
                "authored": pts.tolist(),
                "cooked": mine.tolist(),
            }
        )
    if len(near):
        dc = np.min(np.linalg.norm(near[:, None, :] - authored[None, :, :], axis=2), axis=1)
        worst_cooked = float(dc.max())
    else:
        worst_cooked = None
    return {
        "hulls": len(hulls),
        "cooked_vertices": int(len(near)),
        "authored_vertices": int(len(authored)),
        # Farthest authored hull vertex from any cooked vertex, and the other way round.
        "authored_to_cooked_max_m": worst_authored,
        "cooked_to_authored_max_m": worst_cooked,
        "changed_hulls": [h["path"] for h in per_hull if (h["deviation_m"] or 0.0) > 1e-4],
        "deviation_max_m": max((h["deviation_m"] or 0.0) for h in per_hull),
        "per_hull": per_hull,
    }


def diameter(pts):
    """The largest distance between two points (frame-independent)."""
    d = pts[:, None, :] - pts[None, :, :]
    return float(np.sqrt(np.max(np.sum(d * d, axis=2))))


def run_newton(out):
    import newton

    res = {}
    for path in [os.path.join(out, "scene.usda")] + sorted(
        p for p in glob.glob(os.path.join(out, "*.usda")) if not p.endswith("scene.usda")
    ):
        b = newton.ModelBuilder()
        b.add_usd(path)
        collide = int(newton.ShapeFlags.COLLIDE_SHAPES)
        colliders = sum(1 for fl in b.shape_flags if int(fl) & collide)
        # The hulls' diameters as Newton will collide them (its mesh vertices times its shape
        # scale: hull points are written in decimetres with xformOp:scale 0.1), sorted, to
        # compare with the authored hulls' diameters in metres.
        sizes = []
        for i in range(b.shape_count):
            v = getattr(b.shape_source[i], "vertices", None)
            if v is None or not int(b.shape_flags[i]) & collide:
                continue
            pts = np.asarray(v, dtype=float) * np.array(b.shape_scale[i], dtype=float)
            sizes.append(diameter(pts))
        res[os.path.basename(path)] = {
            "bodies": int(b.body_count),
            "shapes": int(b.shape_count),
            "collision_shapes": colliders,
            "hull_diameters_m": sorted(sizes),
        }
    authored = sorted(diameter(pts) for _, pts in authored_hulls(out))
    res["authored_hull_diameters_m"] = authored
    return res


def main():
    out = sys.argv[1]
    args = sys.argv[2:]
    seconds, dt, physx, newton = 2.0, 1.0 / 240.0, True, False
    while args:
        a = args.pop(0)
        if a == "--seconds":
            seconds = float(args.pop(0))
        elif a == "--dt":
            dt = float(args.pop(0))
        elif a == "--no-physx":
            physx = False
        elif a == "--newton":
            newton = True
    with stdout_to_stderr():
        import physx_usd_schemas  # registers the PhysX schemas with usd-core

        physx_usd_schemas.register_all()
        result = {
            "files": validate_files(out),
            "usdphysics": usd_physics(out),
            "physx_authored": physx_authored(out),
        }
        if physx:
            r = run_physx(out, seconds, dt)
            cooked = r.pop("cooked_points")
            # Body rows keyed by our object names (the prim paths are /World/<prim>).
            names = {v["path"]: k for k, v in result["usdphysics"]["bodies"].items()}
            r["bodies"] = {names.get(p, p): v for p, v in r["bodies"].items()}
            r["cooked"] = compare_cooked(authored_hulls(out), cooked)
            result["physx"] = r
        if newton:
            result["newton"] = run_newton(out)
    json.dump(result, sys.stdout, indent=1, sort_keys=True, allow_nan=False)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
