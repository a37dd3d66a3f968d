//! A CI slice of the cross-engine rest agreement generator (`examples/agreement.rs`, issue #33):
//! a few seeded scenes from six shared objects (a dice, a golf ball, an orange, a screwdriver, a
//! plate, the PyBullet tray), settled in Rapier, exported, replayed in MuJoCo (`scene.xml`) and
//! in PhysX (`scene.usda`, ovphysx on the CPU). Every scene must get the same verdict from each
//! engine as from ours, and every body we call at rest must stay within 1 mm and 1° for 2 s in
//! MuJoCo from the exported pose. PhysX's rest is not asserted yet: with the default export (no
//! polygon limit) PhysX re-cooks hulls over 64 polygons smaller, and the screwdriver of seed 4
//! then rolls 2.0 mm / 7.1° (issue #31's hull legality; docs/agreement.md).
//!
//! A second case covers the heavy-on-light rule (`SettleOptions::load_ratio`): a 4.1 kg
//! toothbrush box on 47 g scissors (seed 23 of a two-object catalog; the shape of seed 6 of the
//! full generator). The rule must mark the scissors, our verdict with it must be MuJoCo's and
//! PhysX's, and with the rule off Rapier squeezes the scissors out: a failure the engines do
//! not share. Not every such stack agrees: of this catalog's six loaded scenes we pass in
//! 0..40, MuJoCo fails seed 30 and moves the box of seeds 5 and 32 past 1 mm (docs/agreement.md).
//!
//! A third case runs PhysX's own verdict from the nudged composed poses (`Judge::nudged`, what
//! `agreement --physx --nudge` counts) on that stack: every nudged start passes, as in ours.

mod common;

use interact3d::agreement::{judge, run_scene, run_scene_with, Catalog, Generated, Ours};
use interact3d::physics::SettleOptions;
use std::path::{Path, PathBuf};

const OBJECTS: [&str; 6] = [
    "ycb/062_dice",
    "ycb/058_golf_ball",
    "ycb/017_orange",
    "ycb/043_phillips_screwdriver",
    "ycb/029_plate",
    "pybullet_data/tray",
];

/// Seeds 0..6 over the six objects, settled and exported into `tmp`.
fn scenes(tmp: &Path) -> Vec<(Generated, Ours, PathBuf)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/datasets/objects");
    let catalog = Catalog::load(&dir, Some(&OBJECTS), Some(tmp.join("cache"))).unwrap();
    (0..6u64)
        .map(|seed| {
            let g = catalog.compose(seed);
            let out = tmp.join(format!("scene_{seed}"));
            let ours = run_scene(&g, &out).unwrap();
            (g, ours, out)
        })
        .collect()
}

fn agree(engine: &str, script: &str, scenes: &[(Generated, Ours, PathBuf)], rest: bool) {
    let python = common::python();
    let script = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/python")
        .join(script);
    let judged = judge(engine, &python, &script, scenes).unwrap();
    let passed = judged.iter().filter(|j| j.ours.passed).count();
    assert!(
        passed >= 3,
        "too few passing scenes to judge rest: {passed}"
    );
    for j in &judged {
        eprintln!(
            "{engine} seed {} {:?} {:?}: ours {} theirs {} drifts {:?}",
            j.seed, j.kind, j.objects, j.ours.passed, j.mujoco.passed, j.rest_drifts
        );
        assert!(j.mujoco.finite);
        assert!(j.verdict_agrees, "seed {}: verdicts differ: {j:?}", j.seed);
        if !rest {
            continue;
        }
        assert_ne!(
            j.rest_agrees,
            Some(false),
            "seed {}: {:?}",
            j.seed,
            j.rest_drifts
        );
    }
}

#[test]
fn generated_scenes_agree_with_mujoco_and_physx() {
    let tmp = tempfile::tempdir().unwrap();
    let scenes = scenes(tmp.path());
    agree("MuJoCo", "agreement_mujoco.py", &scenes, true);
    agree("PhysX", "agreement_physx.py", &scenes, false);
}

/// The heavy-on-light catalog: scissors (47 g) and a toothbrush box (4.1 kg), both items.
const LOADED: [&str; 2] = [
    "ycb/037_scissors",
    "gso/Philips_Sonicare_Tooth_Brush_2_count",
];
/// The seed of [`LOADED`]'s catalog that puts the box on the scissors.
const LOADED_SEED: u64 = 23;

#[test]
fn heavy_item_on_light_one_agrees_only_with_the_load_rule() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/datasets/objects");
    let catalog = Catalog::load(&dir, Some(&LOADED), Some(tmp.path().join("cache"))).unwrap();
    let g = catalog.compose(LOADED_SEED);
    assert_eq!(
        g.objects,
        [
            "ycb/037_scissors",
            "gso/Philips_Sonicare_Tooth_Brush_2_count"
        ]
    );
    let mass: Vec<f64> = g.assembly.bodies.iter().map(|b| b.inertial.mass).collect();
    assert!(mass[1] >= 10.0 * mass[0], "not a 10x load: {mass:?}");
    let light = g.assembly.bodies[0].name.clone();

    let on_dir = tmp.path().join("rule_on");
    let on = run_scene(&g, &on_dir).unwrap();
    let off_dir = tmp.path().join("rule_off");
    let off_opts = SettleOptions {
        load_ratio: 0.0,
        ..Default::default()
    };
    let off = run_scene_with(&g, &off_dir, &off_opts).unwrap();
    eprintln!(
        "loaded {:?}; rule on: passed {} ({:.2} s); rule off: passed {} ({:.2} s) {:?}",
        on.heavily_loaded, on.passed, on.seconds, off.passed, off.seconds, off.reasons
    );
    // (a) the rule names the light body, and only it.
    assert_eq!(on.heavily_loaded, [light]);
    // (c) without it Rapier squeezes the scissors out and the box falls off.
    assert!(off.heavily_loaded.is_empty());
    assert!(!off.passed, "the rule off passed: {off:?}");
    assert!(
        off.reasons
            .iter()
            .any(|r| r.contains("left what it rested in or on")),
        "{:?}",
        off.reasons
    );

    // The engines' verdict is the settle rule replayed from the composed pose, which both
    // exports share (the settled pose only starts their rest run): one judged scene serves both.
    let python = common::python();
    let scripts = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python");
    let scenes = [(g, on, on_dir)];
    for (engine, script, rest) in [
        ("MuJoCo", "agreement_mujoco.py", true),
        ("PhysX", "agreement_physx.py", false),
    ] {
        let j = &judge(engine, &python, &scripts.join(script), &scenes).unwrap()[0];
        eprintln!(
            "{engine}: ours {} theirs {} drifts {:?} bodies {:?}",
            j.ours.passed, j.mujoco.passed, j.rest_drifts, j.mujoco.bodies
        );
        assert!(j.mujoco.finite);
        // (b) with the rule our verdict (a pass) is the engine's ...
        assert!(j.ours.passed);
        assert!(j.verdict_agrees, "{engine}: {j:?}");
        // ... and MuJoCo holds every body of our rest pose within 1 mm / 1° for 2 s.
        if rest {
            assert_eq!(j.rest_agrees, Some(true), "{:?}", j.rest_drifts);
            for b in j.mujoco.bodies.values() {
                assert!(
                    b.from_settled_m <= 1e-3 && b.from_settled_deg <= 1.0,
                    "{b:?}"
                );
            }
        }
        // (c) without the rule our verdict (a fail) is not the engine's.
        assert_ne!(off.passed, j.mujoco.passed, "{engine}");
    }
}

/// PhysX's own verdict from nudged composed poses (`Judge::nudged`, the `--nudge` count of the
/// generator): the loaded stack above (a 4.1 kg box lying flat on 47 g scissors) nudged by
/// 0.5° or 0.5 mm stays a pass in PhysX from every start, as in ours: one start a nudge of
/// ours (`validate::nudge::nudged_poses`, 8 a free body), and the unnudged answer is the
/// plain judge's to the bit.
#[test]
fn physx_keeps_a_flat_load_from_every_nudged_start() {
    use interact3d::agreement::judge::Judge;
    let tmp = tempfile::tempdir().unwrap();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/datasets/objects");
    let catalog = Catalog::load(&dir, Some(&LOADED), Some(tmp.path().join("cache"))).unwrap();
    let g = catalog.compose(LOADED_SEED);
    let out = tmp.path().join("scene");
    let ours = run_scene(&g, &out).unwrap();
    assert!(ours.passed, "{:?}", ours.reasons);
    let settle = SettleOptions::default();
    let our_nudged = interact3d::agreement::nudge::verdicts(&g, &settle).unwrap();
    let python = common::python();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/agreement_physx.py");
    let scenes = [(g, ours, out)];
    let judge = Judge {
        settle_s: settle.settle_max_time,
        ..Judge::new("PhysX", &python, &script)
    };
    let plain = &judge.run(&scenes).unwrap()[0];
    let nudged = &judge.nudged(&scenes).unwrap()[0];
    let v = nudged.mujoco.nudged.clone().expect("nudged verdicts");
    eprintln!("ours nudged {our_nudged:?}; PhysX nudged {v:?}");
    assert!(plain.mujoco.nudged.is_none());
    assert_eq!(v.len(), 16);
    assert_eq!(v.len(), our_nudged.len());
    assert!(
        v.iter().all(|&p| p),
        "PhysX dropped the load from a nudged start: {v:?}"
    );
    assert!(our_nudged.iter().all(|&p| p), "{our_nudged:?}");
    assert_eq!(plain.mujoco.passed, nudged.mujoco.passed);
    for (name, b) in &plain.mujoco.bodies {
        let n = &nudged.mujoco.bodies[name];
        assert_eq!(
            (b.settle_m, b.rest_m, b.from_settled_m),
            (n.settle_m, n.rest_m, n.from_settled_m)
        );
    }
}
