//! `penumbra`: radiosity with exact direct light from area sources, from the command line.
//!
//! Exit codes: 0 success, 1 the run failed, 2 bad input or usage.
#![allow(clippy::print_stdout, clippy::print_stderr)]

mod camera;
mod export;
mod failure;
mod form_factors;
mod merge;
mod progress_bar;
mod replay;
mod run;
mod run_args;
mod signals;
mod sweep;

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use penumbra::DEFAULT_MAX_ELEMENTS;
use penumbra::outputs::DEFAULT_SVG_SURFACES;
use penumbra_meshing::FIT_TRIANGLES_PER_SURFACE;
use penumbra_scenes::{ObjOptions, SceneError, builtin, load_scene_with};

use crate::export::ExportArgs;
use crate::failure::{Failure, usage};
use crate::form_factors::FormFactorArgs;
use crate::merge::MergeArgs;
use crate::run_args::RunArgs;
use crate::sweep::SweepArgs;

// The help texts below give these figures in words.
const _: () = assert!(
    DEFAULT_MAX_ELEMENTS == 10_000
        && penumbra::HIERARCHICAL_MAX_ELEMENTS == 25_000
        && FIT_TRIANGLES_PER_SURFACE == 1
        && DEFAULT_SVG_SURFACES == 24
);

/// The top-level help's examples.
const EXAMPLES: &str = "\
Examples:
  penumbra run cornell                      mesh, solve and render the Cornell box into out/
  penumbra scenes                           the built-in scenes
  penumbra scenes --dump cornell > my.json  a built-in scene as JSON, to start your own from
  penumbra check my.json                    every problem of a scene file at once
  penumbra run my.json --out my             your scene: out/solution.json, report.json, render.png
  penumbra sweep cornell --direct-only      error against elements and time, charted
  penumbra export out --format vtp,glb      a finished run for ParaView and Blender
Each command's own help (penumbra run --help) lists its options and more examples.";

#[derive(Parser, Debug)]
#[command(
    version,
    about = "Radiosity meshes that respect where shadows change",
    after_help = EXAMPLES
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Mesh, solve and render a scene; write solution.json, report.json, render.png and the
    /// SVGs of the surfaces worth looking at (--svg).
    Run(Box<RunArgs>),
    /// Run uniform, uniform + adaptive, discontinuity and discontinuity + adaptive meshes over a
    /// ladder of element budgets and score each against a reference; write sweep.csv,
    /// sweep.json and samples.csv.
    Sweep(Box<SweepArgs>),
    /// Measure every form-factor method (analytic, Monte Carlo, hemicube) against closed forms:
    /// error against cost, point by point, the hemicube's aliasing, the 1 x 2 x 3 box's face
    /// factors and dense solutions of a unit cube; write form-factors.json and print the tables.
    FormFactors(FormFactorArgs),
    /// Write a finished run's solution for other tools: solution.vtp (ParaView), .ply
    /// (MeshLab), .glb (glTF), .obj + .mtl, and index.html (a page to explore it in a browser).
    Export(ExportArgs),
    /// Join the outputs of the shards of a run (`run --shard I/N`) into one: solution.json (the
    /// run not split's, unless the shards refined their own meshes), report.json with the
    /// shards' figures joined, render.png and the shards' SVGs.
    Merge(MergeArgs),
    /// List the built-in scenes, or print one as JSON to start a scene of your own from.
    #[command(
        after_help = "Examples:\n  penumbra scenes\n  penumbra scenes --dump textbook > my.json"
    )]
    Scenes {
        /// Print this built-in scene as JSON (the scene format of `penumbra run`) instead.
        #[arg(long, value_name = "NAME")]
        dump: Option<String>,
    },
    /// Load and validate a scene, reporting every problem at once.
    #[command(
        after_help = "Examples:\n  penumbra check my.json\n  penumbra check model.obj --no-merge"
    )]
    Check {
        /// A .json, .obj, .gltf or .glb file, or the name of a built-in scene.
        scene: String,
        /// OBJ and glTF files: keep every face as its own surface (by default coplanar adjacent
        /// faces of one material are merged where the union is a simple polygon).
        #[arg(long)]
        no_merge: bool,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match dispatch(cli) {
        Ok(code) => code,
        Err(f) => {
            eprintln!("error: {}", failure::message(&f.error));
            ExitCode::from(if f.usage { 2 } else { 1 })
        }
    }
}

fn dispatch(cli: Cli) -> Result<ExitCode, Failure> {
    match cli.command {
        Command::Scenes { dump: None } => {
            for (name, description) in builtin::NAMES {
                println!("{name:<10} {description}");
            }
        }
        Command::Scenes { dump: Some(name) } => dump(&name)?,
        Command::Check { scene, no_merge } => check(&scene, obj_options(no_merge))?,
        Command::Run(args) => return run::run(&args),
        Command::Sweep(args) => sweep::sweep(&args)?,
        Command::Merge(args) => merge::merge(&args)?,
        Command::Export(args) => export::export_run(&args)?,
        Command::FormFactors(args) => form_factors::form_factors(&args)?,
    }
    Ok(ExitCode::SUCCESS)
}

pub(crate) fn obj_options(no_merge: bool) -> ObjOptions {
    ObjOptions {
        merge_coplanar: !no_merge,
    }
}

pub(crate) fn load(
    spec: &str,
    options: ObjOptions,
) -> Result<penumbra_scenes::LoadedScene, Failure> {
    // Every scene error (unreadable, malformed, invalid) is the input's: exit code 2.
    load_scene_with(spec, &options).map_err(|e| {
        // What loading repaired often explains what validation then refused.
        if let SceneError::Invalid { warnings, .. } = &e {
            for w in warnings {
                eprintln!("warning: {w}");
            }
        }
        usage(e)
    })
}

fn check(spec: &str, options: ObjOptions) -> Result<(), Failure> {
    let loaded = load(spec, options)?;
    for w in &loaded.warnings {
        eprintln!("warning: {w}");
    }
    let s = &loaded.scene;
    println!(
        "{}: valid scene \"{}\": {} surfaces, {} emitting, total area {:.6e}, bounding-box diagonal {:.6e}",
        loaded.source,
        s.name,
        s.surfaces.len(),
        s.emitters().count(),
        s.total_area(),
        s.diagonal()
    );
    Ok(())
}

/// `penumbra scenes --dump NAME`: a built-in scene as JSON, on standard output.
fn dump(name: &str) -> Result<(), Failure> {
    let scene = builtin::builtin(name).ok_or_else(|| {
        let names: Vec<&str> = builtin::NAMES.iter().map(|(n, _)| *n).collect();
        usage(anyhow::anyhow!(
            "--dump: there is no built-in scene {name:?}; they are: {}",
            names.join(", ")
        ))
    })?;
    print!("{}", penumbra_scenes::to_json(&scene));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every option's flag ([`penumbra::OptionId::flag`]) is one some command takes, so a
    /// refused value is told by a flag the user can find.
    #[test]
    fn every_option_flag_is_a_flag_of_the_command_line() {
        use clap::CommandFactory;
        let cli = Cli::command();
        let flags: Vec<String> = cli
            .get_subcommands()
            .flat_map(|c| c.get_arguments())
            .filter_map(|a| a.get_long().map(|l| format!("--{l}")))
            .collect();
        for option in penumbra::OptionId::ALL {
            for flag in option.flag().split('/') {
                assert!(
                    flags.iter().any(|f| f == flag),
                    "{option}: {flag} is no flag"
                );
            }
        }
    }
}
