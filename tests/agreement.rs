//! A CI slice of the cross-engine rest agreement generator (`examples/agreement.rs`, issue #33):
//! a few seeded scenes from six shared objects (a dice, a golf ball, an orange, a screwdriver, a
//! plate, the PyBullet tray), settled in Rapier, exported, replayed in MuJoCo (`scene.xml`) and
//! in PhysX (`scene.usda`, ovphysx on the CPU). Every scene must get the same verdict from each
//! engine as from ours, and every body we call at rest must stay within 1 mm and 1° for 2 s in
//! MuJoCo from the exported pose. PhysX's rest is not asserted yet: with the default export (no
//! polygon limit) PhysX re-cooks hulls over 64 polygons smaller, and the screwdriver of seed 4
//! then rolls 2.0 mm / 7.1° (issue #31's hull legality; docs/agreement.md).

mod common;

use interact3d::agreement::{judge, run_scene, Catalog, Generated, Ours};
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
