//! The command line: every subcommand's arguments (clap derive) and how they become the
//! library's options (`BuildArgs::options`, `CheckArgs::options`, `LimitsArgs::limits`, ...).
//!
//! Entry point: [`Cli`].

use crate::body::Engine;
use crate::io::Limits;
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "interact3d",
    version,
    about = "Turn composed 3D scenes into simulation-ready assets and prove they are physically sound"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand)]
pub enum Command {
    /// Export a scene (Interact3D sample folder or scene.json) to MJCF + URDF assets.
    Export(ExportArgs),
    /// Check scenes, export folders, and URDF/MJCF assets written by anyone (files, folders,
    /// globs, in parallel): inertia, geometry, contact and settle checks with file:line findings.
    Validate(ValidateArgs),
    /// Convert a whole dataset: every sample folder and scene.json under ROOT, in parallel,
    /// resumable, shardable; writes OUT/summary.json, summary.csv and index.html.
    Batch(BatchArgs),
    /// Register each object_*.glb onto its guidance_object_*.glb (Interact3D's composition, on
    /// a CPU, no learned weights); writes OUT/metadata.json, OUT/scene.json and the GLBs.
    Compose(ComposeArgs),
    /// Draw a scene or export folder (CPU, deterministic PNGs): six views, the same views of the
    /// collision hulls, cross-sections through each contact, and views.json.
    Render(RenderArgs),
}

#[derive(Args)]
pub struct RenderArgs {
    /// A scene (sample folder, scene.json, mesh file) or an export output folder.
    pub path: PathBuf,
    /// Output folder (replaced atomically).
    #[arg(short, long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub render: RenderOpts,
    #[command(flatten)]
    pub build: BuildArgs,
    #[command(flatten)]
    pub limits: LimitsArgs,
    /// Replace OUT even if it is not an earlier render.
    #[arg(long)]
    pub force: bool,
}

/// Picture sizes (for `render`, and for `--render` of export, validate and batch).
#[derive(Args, Clone)]
pub struct RenderOpts {
    /// Width and height of each view, pixels.
    #[arg(long, default_value_t = 512)]
    pub image_size: u32,
    /// Width and height of each cross-section, pixels.
    #[arg(long, default_value_t = 512)]
    pub section_size: u32,
}

impl RenderOpts {
    pub(crate) fn options(&self) -> crate::render::RenderOptions {
        crate::render::RenderOptions {
            size: self.image_size,
            section_size: self.section_size,
            ..Default::default()
        }
    }
}

#[derive(Args)]
pub struct ComposeArgs {
    /// Sample folder with object_*.glb and guidance_object_*.glb (and metadata.json).
    pub sample: PathBuf,
    /// Output folder (written atomically; `export OUT` takes it).
    #[arg(short, long)]
    pub out: PathBuf,
    /// Anchor object (default: the one whose guidance part has the larger silhouette).
    #[arg(long, value_name = "NAME")]
    pub anchor: Option<String>,
    /// Seed of all sampling (same seed, same result).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Stages to run (the ablation rows); the default is the whole pipeline.
    #[arg(long, value_enum, default_value_t = crate::compose::Method::FullColour)]
    pub method: crate::compose::Method,
    /// Replace OUT even if it is not an earlier interact3d output.
    #[arg(long)]
    pub force: bool,
    /// While the composition penetrates (pair penetration > 1 % of the smaller object), run
    /// this shell command with a JSON attempt on stdin; its stdout JSON names replacement
    /// meshes; recompose (see docs/render.md).
    #[arg(long, value_name = "CMD")]
    pub agent: Option<String>,
    /// Most calls of the --agent command.
    #[arg(long, default_value_t = 5, requires = "agent")]
    pub max_iterations: usize,
}

#[derive(Args, Clone)]
pub struct CheckArgs {
    /// Sample points for R_volume.
    #[arg(long, default_value_t = 1_000_000)]
    pub points: usize,
    /// Largest penetration between collision hulls of different objects at the composed pose (m).
    #[arg(long, default_value_t = 1e-4)]
    pub max_penetration: f64,
    /// Largest penetration between the visual meshes of different objects (m).
    #[arg(long, default_value_t = 1e-4)]
    pub max_visual_penetration: f64,
    /// Largest drift while settling, as a fraction of the object's bounding-box diagonal.
    #[arg(long, default_value_t = 0.1)]
    pub max_drift: f64,
    /// Largest rotation while settling (degrees).
    #[arg(long, default_value_t = 30.0)]
    pub max_settle_rotation: f64,
    /// Largest motion during the rest check (m).
    #[arg(long, default_value_t = 1e-3)]
    pub max_rest_motion: f64,
    /// Largest rotation during the rest check (degrees).
    #[arg(long, default_value_t = 1.0)]
    pub max_rest_rotation: f64,
    /// Largest contact penetration during the rest check (m).
    #[arg(long, default_value_t = 1e-3)]
    pub max_rest_penetration: f64,
    /// Skip the metrics on the visual meshes (collision hulls are always checked).
    #[arg(long)]
    pub no_visual_metrics: bool,
    /// What an undetermined scene does to the exit code (its verdict flips under a 0.5°
    /// nudge of the composed pose): `warn` and keep the unnudged verdict, or `fail` it (a strict
    /// gate; see docs/validation.md for what each costs).
    #[arg(long, value_enum, default_value = "warn")]
    pub undetermined: crate::validate::Undetermined,
    /// Run the nudge check: where one settle's numbers say the verdict may be fragile, settle
    /// again from the composed pose turned 0.5° four ways and call a split verdict
    /// `undetermined` (off by default: it costs 4 settles a firing body; `--undetermined fail`
    /// turns it on).
    #[arg(long)]
    pub nudge_check: bool,
}

impl CheckArgs {
    pub(crate) fn options(&self) -> crate::validate::ValidateOptions {
        let mut o = crate::validate::ValidateOptions::default();
        o.metrics.points = self.points;
        o.max_collision_penetration = self.max_penetration;
        o.settle.max_relative_drift = self.max_drift;
        o.settle.max_settle_rotation_deg = self.max_settle_rotation;
        o.settle.max_rest_motion = self.max_rest_motion;
        o.settle.max_rest_rotation_deg = self.max_rest_rotation;
        o.settle.max_rest_penetration = self.max_rest_penetration;
        o.visual_metrics = !self.no_visual_metrics;
        o.max_visual_penetration = self.max_visual_penetration;
        o.undetermined = self.undetermined;
        o.nudge.enabled =
            self.nudge_check || self.undetermined == crate::validate::Undetermined::Fail;
        o
    }
}

/// Size limits on what is read: a file over one is refused with an error naming the limit.
#[derive(Args, Clone)]
pub struct LimitsArgs {
    /// Largest input file read (mesh, texture, manifest), bytes.
    #[arg(long, value_name = "BYTES", default_value_t = Limits::default().max_file_bytes)]
    pub max_file_bytes: u64,
    /// Most triangles in one mesh file.
    #[arg(long, value_name = "N", default_value_t = Limits::default().max_triangles)]
    pub max_triangles: usize,
    /// Most pixels (width x height) in one texture image.
    #[arg(long, value_name = "N", default_value_t = Limits::default().max_texture_pixels)]
    pub max_texture_pixels: u64,
}

impl LimitsArgs {
    pub(crate) fn limits(&self) -> Limits {
        Limits {
            max_file_bytes: self.max_file_bytes,
            max_triangles: self.max_triangles,
            max_texture_pixels: self.max_texture_pixels,
        }
    }
}

#[derive(Args)]
pub struct ValidateArgs {
    /// Scenes (sample folder, scene.json), export folders, URDF/MJCF files, folders holding them,
    /// or globs ('assets/**/*.urdf').
    #[arg(required = true, value_name = "PATH")]
    pub paths: Vec<String>,
    /// SARIF 2.1.0 of the asset findings to this file (GitHub code scanning).
    #[arg(long, value_name = "FILE")]
    pub sarif: Option<PathBuf>,
    /// Print GitHub Actions annotations (::error file=...,line=...) on stdout.
    #[arg(long)]
    pub github: bool,
    /// Known findings (from --write-baseline) that do not fail the run.
    #[arg(long, value_name = "FILE")]
    pub baseline: Option<PathBuf>,
    /// Write every finding's fingerprint to this file.
    #[arg(long, value_name = "FILE")]
    pub write_baseline: Option<PathBuf>,
    /// Lowest severity that fails the run (exit code 1).
    #[arg(long, value_enum, value_name = "LEVEL")]
    pub fail_on: Option<crate::validate::finding::Severity>,
    /// Where `package://NAME/...` mesh paths of a URDF point (no ROS tools are run).
    #[arg(long = "package", value_name = "NAME=DIR", value_parser = parse_package)]
    pub packages: Vec<(String, PathBuf)>,
    /// Skip the settle and rest tests of URDF/MJCF assets (static checks only).
    #[arg(long)]
    pub no_physics: bool,
    /// Only the assets whose file, included files or meshes changed since this git revision
    /// (committed, uncommitted or untracked), e.g. origin/main.
    #[arg(long, value_name = "GIT_REF")]
    pub changed_since: Option<String>,
    /// Check an MJCF object model file (one body, no joint, no floor) welded, as MuJoCo loads
    /// it alone, instead of as a free object on a ground plane.
    #[arg(long)]
    pub keep_welded: bool,
    #[command(flatten)]
    pub build: BuildArgs,
    #[command(flatten)]
    pub limits: LimitsArgs,
    #[command(flatten)]
    pub check: CheckArgs,
    /// Print the whole validation report as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Write JUnit XML (one test case per check) to this file.
    #[arg(long, value_name = "FILE")]
    pub junit: Option<PathBuf>,
    /// Also draw the scene into this folder (views, hull views, cross-sections, and
    /// index.html with the metrics and findings).
    #[arg(long, value_name = "DIR")]
    pub render: Option<PathBuf>,
    #[command(flatten)]
    pub render_opts: RenderOpts,
}

#[derive(Args)]
pub struct BuildArgs {
    /// Longest extent of one object in metres, NAME=METRES; scales the whole scene uniformly.
    /// NAME is the object's name or alias (a sample's `object_b` as well as its label `lemon`).
    #[arg(long = "size", value_name = "NAME=METRES", value_parser = parse_size)]
    pub sizes: Vec<(String, f64)>,
    /// Density of one object in kg/m³, NAME=KG_M3 (default 1000); repeatable.
    #[arg(long = "density", value_name = "NAME=KG_M3", value_parser = parse_density)]
    pub densities: Vec<(String, f64)>,
    /// Mass of one object in kg, NAME=KG (over any density); repeatable.
    #[arg(long = "mass", value_name = "NAME=KG", value_parser = parse_mass)]
    pub masses: Vec<(String, f64)>,
    /// Up axis of a lone OBJ/STL mesh (default z) or of a manifest (over its `up_axis`). glTF
    /// and sample folders are Y-up by the glTF specification.
    #[arg(long, value_enum, value_name = "AXIS")]
    pub up: Option<UpArg>,
    /// Convex decomposition engine.
    #[arg(long, value_enum, default_value_t = Engine::SceneAware)]
    pub engine: Engine,
    /// Most convex hulls per object.
    #[arg(long, default_value_t = crate::decompose::DEFAULT_MAX_HULLS)]
    pub max_hulls: usize,
    /// Most vertices per hull (PhysX/Isaac accept 64).
    #[arg(long, default_value_t = 64)]
    pub max_hull_vertices: usize,
    /// Most polygons per hull (coplanar triangles merged); 0: no limit. PhysX (Isaac) re-cooks
    /// a hull of more than 64 into another shape, silently: give 64 when exporting for Isaac
    /// (the engine then builds hulls of at most 34 vertices; it costs some fidelity on small
    /// round objects, see docs/usd.md).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub max_hull_polygons: usize,
    /// Build for one simulator. `isaac`: every hull within PhysX's 64 polygons, so Isaac Sim /
    /// Isaac Lab (PhysX) collide the hulls as written (what `--max-hull-polygons 64` does; an
    /// explicit --max-hull-polygons wins). See docs/usd.md for its cost.
    #[arg(long, value_enum, value_name = "SIM")]
    pub target: Option<TargetArg>,
    /// V-HACD voxel resolution.
    #[arg(long, default_value_t = 64)]
    pub vhacd_resolution: u32,
    /// Cache decompositions here (keyed by a hash of the meshes and options).
    #[arg(long, value_name = "DIR")]
    pub decompose_cache: Option<PathBuf>,
    /// Run each object's decomposition strategies to the end instead of dropping one far
    /// behind at a checkpoint (slower; checks the race's margins, docs/speed.md).
    #[arg(long)]
    pub no_race: bool,
}

#[derive(Args)]
pub struct ExportArgs {
    /// Scene: an Interact3D sample folder, a folder with scene.json, or a manifest file.
    pub scene: PathBuf,
    /// Output folder (replaced atomically).
    #[arg(short, long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub build: BuildArgs,
    #[command(flatten)]
    pub limits: LimitsArgs,
    /// Folder of templates overriding the built-in ones (scene.xml.j2, object.xml.j2,
    /// object.urdf.j2).
    #[arg(long)]
    pub templates: Option<PathBuf>,
    /// Replace OUT even if it is not an earlier interact3d export.
    #[arg(long)]
    pub force: bool,
    /// Do not validate (no metrics, no settle; bodies start at the composed pose).
    #[arg(long)]
    pub no_validate: bool,
    /// Start bodies at the composed pose even when validation passes (default: settled pose).
    #[arg(long)]
    pub keep_composed_pose: bool,
    /// Remove slight interpenetration of the given poses first, moving each object as little
    /// as possible (the collision-aware refinement of `compose`); listed in report.json warnings.
    #[arg(long)]
    pub fix_penetration: bool,
    #[command(flatten)]
    pub check: CheckArgs,
    /// Write JUnit XML of the validation to this file.
    #[arg(long, value_name = "FILE")]
    pub junit: Option<PathBuf>,
    /// Also draw the scene into OUT/render/ (views, hull views, cross-sections, index.html).
    #[arg(long)]
    pub render: bool,
    #[command(flatten)]
    pub render_opts: RenderOpts,
}

#[derive(Args)]
pub struct BatchArgs {
    /// Dataset root (e.g. outputs/). With --merge-reports: shard summaries or folders holding
    /// them (default: OUT).
    #[arg(value_name = "ROOT")]
    pub inputs: Vec<PathBuf>,
    /// Output folder: one folder per scene, mirroring ROOT, plus the summaries.
    #[arg(short, long)]
    pub out: PathBuf,
    /// Only scenes whose path relative to ROOT matches one of these globs (e.g. 'food/**').
    #[arg(long, value_name = "GLOB")]
    pub include: Vec<String>,
    /// Skip scenes whose relative path matches one of these globs.
    #[arg(long, value_name = "GLOB")]
    pub exclude: Vec<String>,
    /// Scenes converted at once (default: all cores).
    #[arg(short, long, value_name = "N")]
    pub jobs: Option<usize>,
    /// Process only shard I of N (1-based; by a hash of each scene's relative path), or `auto`:
    /// I and N from a Slurm array, a Kubernetes Indexed Job or an AWS Batch array job.
    #[arg(long, value_name = "I/N|auto")]
    pub shard: Option<crate::batch::ShardArg>,
    /// Shard count for --shard auto where the scheduler does not give it (Kubernetes, AWS
    /// Batch); also read from INTERACT3D_SHARDS.
    #[arg(long, value_name = "N", requires = "shard")]
    pub shards: Option<usize>,
    /// Continue an earlier run in OUT (required to exist); finished scenes are reused.
    #[arg(long)]
    pub resume: bool,
    /// Convert every scene even if its output is current; accept an OUT that is not a batch.
    #[arg(long)]
    pub force: bool,
    /// Combine shard summaries (summary.shard-I-of-N.json) into OUT/summary.json, .csv, index.html.
    #[arg(long, conflicts_with_all = ["shard", "shards", "resume", "force", "include", "exclude", "list"])]
    pub merge_reports: bool,
    /// Print the selected scenes (relative paths) on stdout and stop.
    #[arg(long)]
    pub list: bool,
    /// Progress on stderr: a bar on a terminal, else one line per scene.
    #[arg(long, value_enum, default_value_t = ProgressArg::Auto)]
    pub progress: ProgressArg,
    #[command(flatten)]
    pub build: BuildArgs,
    #[command(flatten)]
    pub limits: LimitsArgs,
    /// Folder of templates overriding the built-in ones.
    #[arg(long)]
    pub templates: Option<PathBuf>,
    /// Start bodies at the composed pose even when validation passes.
    #[arg(long)]
    pub keep_composed_pose: bool,
    #[command(flatten)]
    pub check: CheckArgs,
    /// Draw every scene into OUT/<scene>/render/; index.html then shows a thumbnail per scene
    /// linking to the scene's page.
    #[arg(long)]
    pub render: bool,
    #[command(flatten)]
    pub render_opts: RenderOpts,
}

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum TargetArg {
    /// Isaac Sim / Isaac Lab (PhysX): hulls within 64 polygons.
    Isaac,
}

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum UpArg {
    Y,
    Z,
}

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum ProgressArg {
    Auto,
    Bar,
    Lines,
    Quiet,
}

pub(crate) fn parse_package(s: &str) -> Result<(String, PathBuf), String> {
    let (name, dir) = s.split_once('=').ok_or("expected NAME=DIR")?;
    if name.is_empty() || dir.is_empty() {
        return Err("expected NAME=DIR".into());
    }
    Ok((name.to_string(), PathBuf::from(dir)))
}

/// `NAME=VALUE` with a positive finite value in `unit`.
pub(crate) fn parse_named(s: &str, what: &str, unit: &str) -> Result<(String, f64), String> {
    let (name, v) = s
        .split_once('=')
        .ok_or_else(|| format!("expected NAME={}", unit.to_ascii_uppercase()))?;
    let v: f64 = v.parse().map_err(|_| format!("{v:?} is not a number"))?;
    if !(v.is_finite() && v > 0.0) {
        return Err(format!("{what} must be a positive number of {unit}"));
    }
    Ok((name.to_string(), v))
}

pub(crate) fn parse_size(s: &str) -> Result<(String, f64), String> {
    parse_named(s, "size", "metres")
}

pub(crate) fn parse_density(s: &str) -> Result<(String, f64), String> {
    parse_named(s, "density", "kg_m3")
}

pub(crate) fn parse_mass(s: &str) -> Result<(String, f64), String> {
    parse_named(s, "mass", "kg")
}

impl BuildArgs {
    pub(crate) fn options(&self) -> crate::body::BuildOptions {
        let mut o = crate::body::BuildOptions::default();
        o.prepare.sizes = self.sizes.iter().cloned().collect();
        o.prepare.densities = self.densities.iter().cloned().collect();
        o.prepare.masses = self.masses.iter().cloned().collect();
        o.prepare.up = self.up.map(|u| match u {
            UpArg::Y => crate::scene::UpAxis::Y,
            UpArg::Z => crate::scene::UpAxis::Z,
        });
        o.engine = self.engine;
        o.decompose.max_hulls = self.max_hulls;
        o.decompose.max_vertices = self.max_hull_vertices;
        o.decompose.max_polygons = match (self.max_hull_polygons, self.target) {
            (0, Some(TargetArg::Isaac)) => crate::decompose::PHYSX_MAX_POLYGONS,
            (0, None) => usize::MAX,
            (n, _) => n,
        };
        o.decompose.resolution = self.vhacd_resolution;
        o.decompose.cache_dir = self.decompose_cache.clone();
        o.decompose.race = !self.no_race;
        o
    }
}
