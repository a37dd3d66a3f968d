//! The `interact3d` command: argument parsing only; the work is in the library.
//!
//! Exit codes: 0 pass, 1 a scene failed validation, 2 bad input or usage.

use clap::{Args, Parser, Subcommand};
use interact3d::body::Engine;
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
}

#[derive(Args)]
struct BuildArgs {
    /// Longest extent of one object in metres, NAME=METRES; scales the whole scene uniformly.
    #[arg(long = "size", value_name = "NAME=METRES", value_parser = parse_size)]
    sizes: Vec<(String, f64)>,
    /// Convex decomposition engine.
    #[arg(long, value_enum, default_value_t = Engine::Vhacd)]
    engine: Engine,
    /// Most convex hulls per object.
    #[arg(long, default_value_t = 32)]
    max_hulls: usize,
    /// Most vertices per hull (PhysX/Isaac accept 64).
    #[arg(long, default_value_t = 64)]
    max_hull_vertices: usize,
    /// V-HACD voxel resolution.
    #[arg(long, default_value_t = 64)]
    vhacd_resolution: u32,
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
    /// Folder of templates overriding the built-in ones (scene.xml.j2, object.xml.j2, object.urdf.j2).
    #[arg(long)]
    templates: Option<PathBuf>,
    /// Replace OUT even if it is not an earlier interact3d export.
    #[arg(long)]
    force: bool,
}

fn parse_size(s: &str) -> Result<(String, f64), String> {
    let (name, v) = s.split_once('=').ok_or("expected NAME=METRES")?;
    let v: f64 = v.parse().map_err(|_| format!("{v:?} is not a number"))?;
    if !(v.is_finite() && v > 0.0) {
        return Err("size must be a positive number of metres".into());
    }
    Ok((name.to_string(), v))
}

impl BuildArgs {
    fn options(&self) -> interact3d::body::BuildOptions {
        let mut o = interact3d::body::BuildOptions::default();
        o.prepare.sizes = self.sizes.iter().cloned().collect();
        o.engine = self.engine;
        o.decompose.max_hulls = self.max_hulls;
        o.decompose.max_vertices = self.max_hull_vertices;
        o.decompose.resolution = self.vhacd_resolution;
        o
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(match e {
                Error::Internal(_) => 2,
                _ => 2,
            })
        }
    }
}

fn run(cli: Cli) -> Result<ExitCode, Error> {
    match cli.command {
        Command::Export(a) => {
            let job = interact3d::pipeline::ExportJob {
                build: a.build.options(),
                export: interact3d::export::ExportOptions {
                    templates: a.templates,
                    force: a.force,
                },
                ..Default::default()
            };
            let t = std::time::Instant::now();
            let report = interact3d::pipeline::export_scene(&a.scene, &a.out, &job)?;
            for o in &report.objects {
                eprintln!(
                    "{:<16} mass {:>9.4} kg  hulls {:>3}  max verts {:>3}  {}",
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
            eprintln!(
                "exported {} to {} in {:.2} s",
                report.scene,
                a.out.display(),
                t.elapsed().as_secs_f64()
            );
            Ok(ExitCode::SUCCESS)
        }
    }
}
