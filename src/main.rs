//! The `interact3d` command: argument parsing only; the work is in the library.
//!
//! Exit codes: 0 pass, 1 a scene failed validation (or an asset has findings at or above
//! `--fail-on`), 2 bad input or usage (or not one asset could be read).

use clap::{Args, Parser, Subcommand};
use interact3d::body::Engine;
use interact3d::io::Limits;
use interact3d::Error;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "interact3d",
    version,
    about = "Turn composed 3D scenes into simulation-ready assets and prove they are physically sound"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
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
struct RenderArgs {
    /// A scene (sample folder, scene.json, mesh file) or an export output folder.
    path: PathBuf,
    /// Output folder (replaced atomically).
    #[arg(short, long)]
    out: PathBuf,
    #[command(flatten)]
    render: RenderOpts,
    #[command(flatten)]
    build: BuildArgs,
    #[command(flatten)]
    limits: LimitsArgs,
    /// Replace OUT even if it is not an earlier render.
    #[arg(long)]
    force: bool,
}

/// Picture sizes (for `render`, and for `--render` of export, validate and batch).
#[derive(Args, Clone)]
struct RenderOpts {
    /// Width and height of each view, pixels.
    #[arg(long, default_value_t = 512)]
    image_size: u32,
    /// Width and height of each cross-section, pixels.
    #[arg(long, default_value_t = 512)]
    section_size: u32,
}

impl RenderOpts {
    fn options(&self) -> interact3d::render::RenderOptions {
        interact3d::render::RenderOptions {
            size: self.image_size,
            section_size: self.section_size,
            ..Default::default()
        }
    }
}

#[derive(Args)]
struct ComposeArgs {
    /// Sample folder with object_*.glb and guidance_object_*.glb (and metadata.json).
    sample: PathBuf,
    /// Output folder (written atomically; `export OUT` takes it).
    #[arg(short, long)]
    out: PathBuf,
    /// Anchor object (default: the one whose guidance part has the larger silhouette).
    #[arg(long, value_name = "NAME")]
    anchor: Option<String>,
    /// Seed of all sampling (same seed, same result).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Stages to run (the ablation rows); the default is the whole pipeline.
    #[arg(long, value_enum, default_value_t = interact3d::compose::Method::FullColour)]
    method: interact3d::compose::Method,
    /// Replace OUT even if it is not an earlier interact3d output.
    #[arg(long)]
    force: bool,
    /// While the composition penetrates (pair penetration > 1 % of the smaller object), run
    /// this shell command with a JSON attempt on stdin; its stdout JSON names replacement
    /// meshes; recompose (see docs/render.md).
    #[arg(long, value_name = "CMD")]
    agent: Option<String>,
    /// Most calls of the --agent command.
    #[arg(long, default_value_t = 5, requires = "agent")]
    max_iterations: usize,
}

#[derive(Args, Clone)]
struct CheckArgs {
    /// Sample points for R_volume.
    #[arg(long, default_value_t = 1_000_000)]
    points: usize,
    /// Largest penetration between collision hulls of different objects at the composed pose (m).
    #[arg(long, default_value_t = 1e-4)]
    max_penetration: f64,
    /// Largest penetration between the visual meshes of different objects (m).
    #[arg(long, default_value_t = 1e-4)]
    max_visual_penetration: f64,
    /// Largest drift while settling, as a fraction of the object's bounding-box diagonal.
    #[arg(long, default_value_t = 0.1)]
    max_drift: f64,
    /// Largest rotation while settling (degrees).
    #[arg(long, default_value_t = 30.0)]
    max_settle_rotation: f64,
    /// Largest motion during the rest check (m).
    #[arg(long, default_value_t = 1e-3)]
    max_rest_motion: f64,
    /// Largest rotation during the rest check (degrees).
    #[arg(long, default_value_t = 1.0)]
    max_rest_rotation: f64,
    /// Largest contact penetration during the rest check (m).
    #[arg(long, default_value_t = 1e-3)]
    max_rest_penetration: f64,
    /// Skip the metrics on the visual meshes (collision hulls are always checked).
    #[arg(long)]
    no_visual_metrics: bool,
}

impl CheckArgs {
    fn options(&self) -> interact3d::validate::ValidateOptions {
        let mut o = interact3d::validate::ValidateOptions::default();
        o.metrics.points = self.points;
        o.max_collision_penetration = self.max_penetration;
        o.settle.max_relative_drift = self.max_drift;
        o.settle.max_settle_rotation_deg = self.max_settle_rotation;
        o.settle.max_rest_motion = self.max_rest_motion;
        o.settle.max_rest_rotation_deg = self.max_rest_rotation;
        o.settle.max_rest_penetration = self.max_rest_penetration;
        o.visual_metrics = !self.no_visual_metrics;
        o.max_visual_penetration = self.max_visual_penetration;
        o
    }
}

/// Size limits on what is read: a file over one is refused with an error naming the limit.
#[derive(Args, Clone)]
struct LimitsArgs {
    /// Largest input file read (mesh, texture, manifest), bytes.
    #[arg(long, value_name = "BYTES", default_value_t = Limits::default().max_file_bytes)]
    max_file_bytes: u64,
    /// Most triangles in one mesh file.
    #[arg(long, value_name = "N", default_value_t = Limits::default().max_triangles)]
    max_triangles: usize,
    /// Most pixels (width x height) in one texture image.
    #[arg(long, value_name = "N", default_value_t = Limits::default().max_texture_pixels)]
    max_texture_pixels: u64,
}

impl LimitsArgs {
    fn limits(&self) -> Limits {
        Limits {
            max_file_bytes: self.max_file_bytes,
            max_triangles: self.max_triangles,
            max_texture_pixels: self.max_texture_pixels,
        }
    }
}

#[derive(Args)]
struct ValidateArgs {
    /// Scenes (sample folder, scene.json), export folders, URDF/MJCF files, folders holding them,
    /// or globs ('assets/**/*.urdf').
    #[arg(required = true, value_name = "PATH")]
    paths: Vec<String>,
    /// SARIF 2.1.0 of the asset findings to this file (GitHub code scanning).
    #[arg(long, value_name = "FILE")]
    sarif: Option<PathBuf>,
    /// Print GitHub Actions annotations (::error file=...,line=...) on stdout.
    #[arg(long)]
    github: bool,
    /// Known findings (from --write-baseline) that do not fail the run.
    #[arg(long, value_name = "FILE")]
    baseline: Option<PathBuf>,
    /// Write every finding's fingerprint to this file.
    #[arg(long, value_name = "FILE")]
    write_baseline: Option<PathBuf>,
    /// Lowest severity that fails the run (exit code 1).
    #[arg(long, value_enum, value_name = "LEVEL")]
    fail_on: Option<interact3d::validate::finding::Severity>,
    /// Where `package://NAME/...` mesh paths of a URDF point (no ROS tools are run).
    #[arg(long = "package", value_name = "NAME=DIR", value_parser = parse_package)]
    packages: Vec<(String, PathBuf)>,
    /// Skip the settle and rest tests of URDF/MJCF assets (static checks only).
    #[arg(long)]
    no_physics: bool,
    /// Only the assets whose file, included files or meshes changed since this git revision
    /// (committed, uncommitted or untracked), e.g. origin/main.
    #[arg(long, value_name = "GIT_REF")]
    changed_since: Option<String>,
    /// Check an MJCF object model file (one body, no joint, no floor) welded, as MuJoCo loads
    /// it alone, instead of as a free object on a ground plane.
    #[arg(long)]
    keep_welded: bool,
    #[command(flatten)]
    build: BuildArgs,
    #[command(flatten)]
    limits: LimitsArgs,
    #[command(flatten)]
    check: CheckArgs,
    /// Print the whole validation report as JSON on stdout.
    #[arg(long)]
    json: bool,
    /// Write JUnit XML (one test case per check) to this file.
    #[arg(long, value_name = "FILE")]
    junit: Option<PathBuf>,
    /// Also draw the scene into this folder (views, hull views, cross-sections, and
    /// index.html with the metrics and findings).
    #[arg(long, value_name = "DIR")]
    render: Option<PathBuf>,
    #[command(flatten)]
    render_opts: RenderOpts,
}

#[derive(Args)]
struct BuildArgs {
    /// Longest extent of one object in metres, NAME=METRES; scales the whole scene uniformly.
    /// NAME is the object's name or alias (a sample's `object_b` as well as its label `lemon`).
    #[arg(long = "size", value_name = "NAME=METRES", value_parser = parse_size)]
    sizes: Vec<(String, f64)>,
    /// Density of one object in kg/m³, NAME=KG_M3 (default 1000); repeatable.
    #[arg(long = "density", value_name = "NAME=KG_M3", value_parser = parse_density)]
    densities: Vec<(String, f64)>,
    /// Mass of one object in kg, NAME=KG (over any density); repeatable.
    #[arg(long = "mass", value_name = "NAME=KG", value_parser = parse_mass)]
    masses: Vec<(String, f64)>,
    /// Up axis of a lone OBJ/STL mesh (default z) or of a manifest (over its `up_axis`). glTF
    /// and sample folders are Y-up by the glTF specification.
    #[arg(long, value_enum, value_name = "AXIS")]
    up: Option<UpArg>,
    /// Convex decomposition engine.
    #[arg(long, value_enum, default_value_t = Engine::SceneAware)]
    engine: Engine,
    /// Most convex hulls per object.
    #[arg(long, default_value_t = interact3d::decompose::DEFAULT_MAX_HULLS)]
    max_hulls: usize,
    /// Most vertices per hull (PhysX/Isaac accept 64).
    #[arg(long, default_value_t = 64)]
    max_hull_vertices: usize,
    /// Most polygons per hull (coplanar triangles merged); 0: no limit. PhysX (Isaac) re-cooks
    /// a hull of more than 64 into another shape, silently: give 64 when exporting for Isaac
    /// (the engine then builds hulls of at most 34 vertices; it costs some fidelity on small
    /// round objects, see docs/usd.md).
    #[arg(long, value_name = "N", default_value_t = 0)]
    max_hull_polygons: usize,
    /// Build for one simulator. `isaac`: every hull within PhysX's 64 polygons, so Isaac Sim /
    /// Isaac Lab (PhysX) collide the hulls as written (what `--max-hull-polygons 64` does; an
    /// explicit --max-hull-polygons wins). See docs/usd.md for its cost.
    #[arg(long, value_enum, value_name = "SIM")]
    target: Option<TargetArg>,
    /// V-HACD voxel resolution.
    #[arg(long, default_value_t = 64)]
    vhacd_resolution: u32,
    /// Cache decompositions here (keyed by a hash of the meshes and options).
    #[arg(long, value_name = "DIR")]
    decompose_cache: Option<PathBuf>,
}

#[derive(Args)]
struct ExportArgs {
    /// Scene: an Interact3D sample folder, a folder with scene.json, or a manifest file.
    scene: PathBuf,
    /// Output folder (replaced atomically).
    #[arg(short, long)]
    out: PathBuf,
    #[command(flatten)]
    build: BuildArgs,
    #[command(flatten)]
    limits: LimitsArgs,
    /// Folder of templates overriding the built-in ones (scene.xml.j2, object.xml.j2,
    /// object.urdf.j2).
    #[arg(long)]
    templates: Option<PathBuf>,
    /// Replace OUT even if it is not an earlier interact3d export.
    #[arg(long)]
    force: bool,
    /// Do not validate (no metrics, no settle; bodies start at the composed pose).
    #[arg(long)]
    no_validate: bool,
    /// Start bodies at the composed pose even when validation passes (default: settled pose).
    #[arg(long)]
    keep_composed_pose: bool,
    /// Remove slight interpenetration of the given poses first, moving each object as little
    /// as possible (the collision-aware refinement of `compose`); listed in report.json warnings.
    #[arg(long)]
    fix_penetration: bool,
    #[command(flatten)]
    check: CheckArgs,
    /// Write JUnit XML of the validation to this file.
    #[arg(long, value_name = "FILE")]
    junit: Option<PathBuf>,
    /// Also draw the scene into OUT/render/ (views, hull views, cross-sections, index.html).
    #[arg(long)]
    render: bool,
    #[command(flatten)]
    render_opts: RenderOpts,
}

#[derive(Args)]
struct BatchArgs {
    /// Dataset root (e.g. outputs/). With --merge-reports: shard summaries or folders holding
    /// them (default: OUT).
    #[arg(value_name = "ROOT")]
    inputs: Vec<PathBuf>,
    /// Output folder: one folder per scene, mirroring ROOT, plus the summaries.
    #[arg(short, long)]
    out: PathBuf,
    /// Only scenes whose path relative to ROOT matches one of these globs (e.g. 'food/**').
    #[arg(long, value_name = "GLOB")]
    include: Vec<String>,
    /// Skip scenes whose relative path matches one of these globs.
    #[arg(long, value_name = "GLOB")]
    exclude: Vec<String>,
    /// Scenes converted at once (default: all cores).
    #[arg(short, long, value_name = "N")]
    jobs: Option<usize>,
    /// Process only shard I of N (1-based; by a hash of each scene's relative path), or `auto`:
    /// I and N from a Slurm array, a Kubernetes Indexed Job or an AWS Batch array job.
    #[arg(long, value_name = "I/N|auto")]
    shard: Option<interact3d::batch::ShardArg>,
    /// Shard count for --shard auto where the scheduler does not give it (Kubernetes, AWS
    /// Batch); also read from INTERACT3D_SHARDS.
    #[arg(long, value_name = "N", requires = "shard")]
    shards: Option<usize>,
    /// Continue an earlier run in OUT (required to exist); finished scenes are reused.
    #[arg(long)]
    resume: bool,
    /// Convert every scene even if its output is current; accept an OUT that is not a batch.
    #[arg(long)]
    force: bool,
    /// Combine shard summaries (summary.shard-I-of-N.json) into OUT/summary.json, .csv, index.html.
    #[arg(long, conflicts_with_all = ["shard", "shards", "resume", "force", "include", "exclude", "list"])]
    merge_reports: bool,
    /// Print the selected scenes (relative paths) on stdout and stop.
    #[arg(long)]
    list: bool,
    /// Progress on stderr: a bar on a terminal, else one line per scene.
    #[arg(long, value_enum, default_value_t = ProgressArg::Auto)]
    progress: ProgressArg,
    #[command(flatten)]
    build: BuildArgs,
    #[command(flatten)]
    limits: LimitsArgs,
    /// Folder of templates overriding the built-in ones.
    #[arg(long)]
    templates: Option<PathBuf>,
    /// Start bodies at the composed pose even when validation passes.
    #[arg(long)]
    keep_composed_pose: bool,
    #[command(flatten)]
    check: CheckArgs,
    /// Draw every scene into OUT/<scene>/render/; index.html then shows a thumbnail per scene
    /// linking to the scene's page.
    #[arg(long)]
    render: bool,
    #[command(flatten)]
    render_opts: RenderOpts,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum TargetArg {
    /// Isaac Sim / Isaac Lab (PhysX): hulls within 64 polygons.
    Isaac,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum UpArg {
    Y,
    Z,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum ProgressArg {
    Auto,
    Bar,
    Lines,
    Quiet,
}

fn parse_package(s: &str) -> Result<(String, PathBuf), String> {
    let (name, dir) = s.split_once('=').ok_or("expected NAME=DIR")?;
    if name.is_empty() || dir.is_empty() {
        return Err("expected NAME=DIR".into());
    }
    Ok((name.to_string(), PathBuf::from(dir)))
}

/// `NAME=VALUE` with a positive finite value in `unit`.
fn parse_named(s: &str, what: &str, unit: &str) -> Result<(String, f64), String> {
    let (name, v) = s
        .split_once('=')
        .ok_or_else(|| format!("expected NAME={}", unit.to_ascii_uppercase()))?;
    let v: f64 = v.parse().map_err(|_| format!("{v:?} is not a number"))?;
    if !(v.is_finite() && v > 0.0) {
        return Err(format!("{what} must be a positive number of {unit}"));
    }
    Ok((name.to_string(), v))
}

fn parse_size(s: &str) -> Result<(String, f64), String> {
    parse_named(s, "size", "metres")
}

fn parse_density(s: &str) -> Result<(String, f64), String> {
    parse_named(s, "density", "kg_m3")
}

fn parse_mass(s: &str) -> Result<(String, f64), String> {
    parse_named(s, "mass", "kg")
}

/// Every warning on stderr, one line each, under the table; then the summary line, which counts
/// them.
fn print_warnings_and_summary(warnings: &[String], summary: &str) {
    for w in warnings {
        eprintln!("warning: {w}");
    }
    let n = warnings.len();
    eprintln!("{summary}, {n} warning{}", if n == 1 { "" } else { "s" });
}

impl BuildArgs {
    fn options(&self) -> interact3d::body::BuildOptions {
        let mut o = interact3d::body::BuildOptions::default();
        o.prepare.sizes = self.sizes.iter().cloned().collect();
        o.prepare.densities = self.densities.iter().cloned().collect();
        o.prepare.masses = self.masses.iter().cloned().collect();
        o.prepare.up = self.up.map(|u| match u {
            UpArg::Y => interact3d::scene::UpAxis::Y,
            UpArg::Z => interact3d::scene::UpAxis::Z,
        });
        o.engine = self.engine;
        o.decompose.max_hulls = self.max_hulls;
        o.decompose.max_vertices = self.max_hull_vertices;
        o.decompose.max_polygons = match (self.max_hull_polygons, self.target) {
            (0, Some(TargetArg::Isaac)) => interact3d::decompose::PHYSX_MAX_POLYGONS,
            (0, None) => usize::MAX,
            (n, _) => n,
        };
        o.decompose.resolution = self.vhacd_resolution;
        o.decompose.cache_dir = self.decompose_cache.clone();
        o
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

fn run(cli: Cli) -> Result<ExitCode, Error> {
    match cli.command {
        Command::Export(a) => {
            let job = interact3d::pipeline::ExportJob {
                limits: a.limits.limits(),
                build: a.build.options(),
                export: interact3d::export::ExportOptions {
                    templates: a.templates,
                    force: a.force,
                },
                validate: (!a.no_validate).then(|| a.check.options()),
                keep_composed_pose: a.keep_composed_pose,
                fix_penetration: a.fix_penetration,
                render: a.render.then(|| a.render_opts.options()),
            };
            let t = std::time::Instant::now();
            let done = interact3d::pipeline::export_scene(&a.scene, &a.out, &job)?;
            let report = &done.report;
            for o in &report.objects {
                // Collision fit, % of the bbox diagonal: two-sided p95 (hulls→mesh,
                // mesh→hulls) and the mesh's outside depth at p99.
                let fit = o.collision_fit.map_or(String::new(), |f| {
                    format!(
                        "fit p95 {:>5.2} % ({:.2}/{:.2})  outside p99 {:>4.2} %  ",
                        f.p95 * 100.0,
                        f.hull_to_mesh_p95 * 100.0,
                        f.mesh_to_hull_p95 * 100.0,
                        f.outside_p99 * 100.0
                    )
                });
                eprintln!(
                    "{:<16} mass {:>9.4} kg  hulls {:>3}  max verts {:>3}  {fit}{}",
                    o.name,
                    o.mass,
                    o.hull_count,
                    o.hull_vertex_counts.iter().max().unwrap_or(&0),
                    if o.closed {
                        "closed"
                    } else {
                        "open: hull-union inertia"
                    }
                );
            }
            let mut summary = format!(
                "exported {} to {} in {:.2} s: ",
                report.scene,
                a.out.display(),
                t.elapsed().as_secs_f64()
            );
            let code = match &done.validation {
                Some(v) => {
                    eprint!("{}", interact3d::validate::table(v));
                    if let Some(f) = &a.junit {
                        interact3d::fsutil::write_atomically(
                            f,
                            interact3d::validate::junit(&report.scene, v).as_bytes(),
                        )?;
                    }
                    summary += if v.passed { "PASS" } else { "FAIL" };
                    if v.passed {
                        ExitCode::SUCCESS
                    } else {
                        ExitCode::from(1)
                    }
                }
                None => {
                    summary += "not validated";
                    ExitCode::SUCCESS
                }
            };
            print_warnings_and_summary(&report.warning_lines(done.validation.as_ref()), &summary);
            Ok(code)
        }
        Command::Batch(a) => batch(a),
        Command::Render(a) => {
            let t = std::time::Instant::now();
            let assembly =
                interact3d::pipeline::load_any(&a.path, &a.limits.limits(), &a.build.options())?;
            let t_draw = std::time::Instant::now();
            let r = interact3d::render::render_to_dir(
                &assembly,
                &a.out,
                &a.render.options(),
                None,
                a.force,
            )?;
            eprintln!(
                "rendered {} pictures of {} into {} in {:.2} s (loading {:.2} s)",
                r.pictures.len(),
                assembly.name,
                a.out.display(),
                t_draw.elapsed().as_secs_f64(),
                (t_draw - t).as_secs_f64()
            );
            Ok(ExitCode::SUCCESS)
        }
        Command::Compose(a) => {
            let t = std::time::Instant::now();
            let opts = interact3d::compose::ComposeOptions {
                method: a.method,
                seed: a.seed,
                anchor: a.anchor,
                ..Default::default()
            };
            if let Some(cmd) = &a.agent {
                let mut ao = interact3d::compose::agent::AgentOptions::new(cmd.clone());
                ao.max_iterations = a.max_iterations;
                let r = interact3d::compose::agent::compose_with_agent(
                    &a.sample,
                    &a.out,
                    &opts,
                    &Default::default(),
                    a.force,
                    &ao,
                )?;
                eprintln!(
                    "composed into {} with {} agent call(s) in {:.2} s: penetration ratio {:.2e} ({})",
                    a.out.display(),
                    r.iterations,
                    t.elapsed().as_secs_f64(),
                    r.ratio,
                    if r.success { "success" } else { "still above the threshold" }
                );
                return Ok(if r.success {
                    ExitCode::SUCCESS
                } else {
                    ExitCode::from(1)
                });
            }
            let (comp, check) = interact3d::compose::folder::compose_folder(
                &a.sample,
                &a.out,
                &opts,
                &Default::default(),
                a.force,
            )?;
            for o in &comp.objects {
                eprintln!(
                    "{:<16} scale {:>9.5}  score {:.3}  rms {:.3e}  {}",
                    o.name, o.transform.scale, o.score, o.icp_rms, o.method
                );
            }
            eprintln!(
                "composed {} objects (anchor {}) into {} in {:.2} s; max R_volume {:.2e}, max penetration {:.2e}",
                comp.objects.len(),
                comp.anchor,
                a.out.display(),
                t.elapsed().as_secs_f64(),
                check["max_r_volume"].as_f64().unwrap_or(f64::NAN),
                check["max_penetration_depth"].as_f64().unwrap_or(f64::NAN),
            );
            Ok(ExitCode::SUCCESS)
        }
        Command::Validate(a) => validate(a),
    }
}

fn validate(a: ValidateArgs) -> Result<ExitCode, Error> {
    use interact3d::validate::ci;
    let t = std::time::Instant::now();
    let mut entries = ci::discover(&a.paths)?;
    if let Some(r) = &a.changed_since {
        let read = interact3d::io::asset::ReadOptions {
            limits: a.limits.limits(),
            packages: a.packages.clone(),
            keep_welded: a.keep_welded,
        };
        entries = ci::changed_since(entries, &a.paths[0], r, &read)?;
    }
    let ci_flags = a.changed_since.is_some()
        || a.sarif.is_some()
        || a.github
        || a.baseline.is_some()
        || a.write_baseline.is_some()
        || a.fail_on.is_some();
    if let ([e], false) = (entries.as_slice(), ci_flags) {
        if e.kind == ci::Kind::Scene {
            // One scene or export folder: the scene report as before.
            let (assembly, v) = interact3d::pipeline::validate_path(
                &e.path,
                &a.limits.limits(),
                &a.build.options(),
                &a.check.options(),
            )?;
            eprint!("{}", interact3d::validate::table(&v));
            print_warnings_and_summary(
                &interact3d::report::Report::new(&assembly).warning_lines(Some(&v)),
                &format!(
                    "validated {} in {:.2} s: {}",
                    assembly.name,
                    t.elapsed().as_secs_f64(),
                    if v.passed { "PASS" } else { "FAIL" }
                ),
            );
            if a.json {
                let json =
                    serde_json::to_string_pretty(&v).map_err(|e| Error::Internal(e.to_string()))?;
                println!("{json}");
            }
            if let Some(f) = &a.junit {
                interact3d::fsutil::write_atomically(
                    f,
                    interact3d::validate::junit(&assembly.name, &v).as_bytes(),
                )?;
            }
            if let Some(dir) = &a.render {
                let json = serde_json::to_value(&v).map_err(|e| Error::Internal(e.to_string()))?;
                interact3d::render::render_to_dir(
                    &assembly,
                    dir,
                    &a.render_opts.options(),
                    Some(&json),
                    false,
                )?;
                eprintln!("pictures: {}", dir.join("index.html").display());
            }
            return Ok(if v.passed {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            });
        }
    }
    let mut opts = ci::RunOptions {
        scene_build: a.build.options(),
        scene_validate: a.check.options(),
        fail_on: a.fail_on,
        ..Default::default()
    };
    opts.asset.read.limits = a.limits.limits();
    opts.asset.read.packages = a.packages.clone();
    opts.asset.read.keep_welded = a.keep_welded;
    opts.asset.physics = !a.no_physics;
    opts.asset.settle = interact3d::physics::SettleOptions {
        perturbation_speed: opts.asset.settle.perturbation_speed,
        settle_max_time: opts.asset.settle.settle_max_time,
        ..a.check.options().settle
    };
    if let Some(b) = &a.baseline {
        opts.baseline = ci::read_baseline(b)?;
    }
    let run = ci::run(&entries, &opts);
    eprint!("{}", ci::table(&run));
    eprintln!(
        "validated {} assets in {:.2} s",
        run.reports.len(),
        t.elapsed().as_secs_f64()
    );
    let pretty = |v: &serde_json::Value| {
        serde_json::to_string_pretty(v).map_err(|e| Error::Internal(e.to_string()))
    };
    if a.json {
        println!("{}", pretty(&ci::json(&run))?);
    }
    if a.github {
        print!("{}", ci::github(&run));
    }
    if let Some(f) = &a.sarif {
        interact3d::fsutil::write_atomically(f, (pretty(&ci::sarif(&run))? + "\n").as_bytes())?;
    }
    if let Some(f) = &a.junit {
        interact3d::fsutil::write_atomically(f, ci::junit(&run).as_bytes())?;
    }
    if let Some(f) = &a.write_baseline {
        interact3d::fsutil::write_atomically(
            f,
            (pretty(&ci::baseline_json(&run))? + "\n").as_bytes(),
        )?;
    }
    Ok(ExitCode::from(ci::exit_code(&run)))
}

fn batch(a: BatchArgs) -> Result<ExitCode, Error> {
    use interact3d::batch;
    if a.merge_reports {
        let m = batch::merge_reports(&a.out, &a.inputs)?;
        for w in &m.warnings {
            eprintln!("warning: {w}");
        }
        eprintln!(
            "merged {} summaries: {} scenes: {} pass, {} fail, {} error -> {}",
            m.summary.run.merged_from.len(),
            m.summary.counts.scenes,
            m.summary.counts.pass,
            m.summary.counts.fail,
            m.summary.counts.error,
            a.out.join("summary.json").display()
        );
        return Ok(ExitCode::from(if m.incomplete {
            2
        } else {
            m.summary.exit_code
        }));
    }
    let [root] = a.inputs.as_slice() else {
        return Err(Error::Usage(
            "batch takes one ROOT folder (several only with --merge-reports)".into(),
        ));
    };
    let job = interact3d::pipeline::ExportJob {
        limits: a.limits.limits(),
        build: a.build.options(),
        export: interact3d::export::ExportOptions {
            templates: a.templates,
            force: false,
        },
        validate: Some(a.check.options()),
        keep_composed_pose: a.keep_composed_pose,
        render: a.render.then(|| a.render_opts.options()),
        ..Default::default()
    };
    let mut opts = batch::BatchOptions::new(root, &a.out, job);
    opts.include = a.include;
    opts.exclude = a.exclude;
    opts.jobs = a.jobs;
    if let Some(arg) = a.shard {
        let d = arg.resolve(a.shards)?;
        if matches!(arg, batch::ShardArg::Auto) {
            eprintln!("shard {} from {}", d.shard, d.source);
        }
        opts.shard = Some(d.shard);
    }
    opts.resume = a.resume;
    opts.force = a.force;
    opts.progress = match a.progress {
        ProgressArg::Auto => batch::Progress::Auto,
        ProgressArg::Bar => batch::Progress::Bar,
        ProgressArg::Lines => batch::Progress::Lines,
        ProgressArg::Quiet => batch::Progress::Quiet,
    };
    if a.list {
        for e in batch::scenes(&opts)? {
            println!("{}", e.rel);
        }
        return Ok(ExitCode::SUCCESS);
    }
    let s = batch::run(&opts)?;
    eprintln!("{}", batch::counts_line(&s));
    eprintln!(
        "summary: {}",
        a.out.join(batch::Summary::file_name(s.shard)).display()
    );
    Ok(ExitCode::from(s.exit_code))
}
