//! `penumbra run`.

use std::process::ExitCode;

use crate::progress_bar::Bars;
use anyhow::Context;
use penumbra::RunResult;
use penumbra::export::{ExportFormat, export_run};
use penumbra::outputs::{Invocation, SvgSelection, write_outputs};
use penumbra::pipeline::{Kept, Stage};
use penumbra_scenes::LengthUnit;
use penumbra_solver::Interrupt;

use crate::failure::{Command, Failure, invalid_option, run_failure, usage};
use crate::run_args::RunArgs;
use crate::signals::Signals;
use crate::{load, obj_options};

/// `--svg`: `auto`, `all`, `none`, or surface names of `scene`, comma-separated.
fn svg_selection(spec: &str, scene: &penumbra_scenes::Scene) -> Result<SvgSelection, Failure> {
    match spec.trim() {
        "auto" => return Ok(SvgSelection::Auto),
        "all" => return Ok(SvgSelection::All),
        "none" => return Ok(SvgSelection::None),
        _ => {}
    }
    let names: Vec<String> = spec.split(',').map(|n| n.trim().to_owned()).collect();
    if names.iter().any(String::is_empty) {
        return Err(usage(anyhow::anyhow!(
            "--svg takes auto, all, none or surface names separated by commas, not {spec:?}"
        )));
    }
    SvgSelection::named(scene, &names).map_err(|unknown| {
        let shown: Vec<String> = unknown.iter().take(10).map(|n| format!("{n:?}")).collect();
        let more = match unknown.len().saturating_sub(shown.len()) {
            0 => String::new(),
            n => format!(" and {n} more"),
        };
        usage(anyhow::anyhow!(
            "--svg: the scene has no surface named {}{more} (names are exact; `penumbra check` \
             counts the surfaces, report.json and solution.json list them)",
            shown.join(", ")
        ))
    })
}

/// `--shard I/N`, checked against the other options of `run`.
fn shard_of(text: &str, args: &RunArgs) -> Result<penumbra::shard::Shard, Failure> {
    use penumbra::shard::{Shard, ShardError};
    let shard = Shard::parse(text).map_err(|e| usage(anyhow::anyhow!("--shard: {e}")))?;
    let refused = |flag: &str, e: ShardError| usage(anyhow::anyhow!("--shard with {flag}: {e}"));
    if !args.direct_only {
        return Err(usage(anyhow::anyhow!(
            "--shard needs --direct-only: {}",
            ShardError::NeedsDirectOnly
        )));
    }
    if args.refine_tol.is_some() {
        return Err(refused("--refine-tol", ShardError::Refinement));
    }
    if args.time_budget.is_some() {
        return Err(refused("--time-budget", ShardError::TimeBudget));
    }
    // The page goes with the render, which the merge makes; a bad name is refused later.
    let exports = ExportFormat::parse_list(&args.export).unwrap_or_default();
    if exports.iter().any(|&f| f != ExportFormat::Html) {
        return Err(usage(anyhow::anyhow!(
            "--shard with --export: a shard holds part of the solution; export the merged run \
             (`penumbra merge ... --out DIR`, then `penumbra export DIR`)"
        )));
    }
    if args.convergence {
        return Err(usage(anyhow::anyhow!(
            "--shard with --convergence: a direct-only run does not iterate, so there is no \
             convergence to write"
        )));
    }
    Ok(shard)
}

/// Most worker threads: more than any machine's cores only costs their stacks.
const MAX_THREADS: usize = 1024;

/// `penumbra run`, or `penumbra run --replay REPORT`.
pub(crate) fn run(args: &RunArgs) -> Result<ExitCode, Failure> {
    match &args.replay {
        Some(report) => {
            let recorded = crate::replay::recorded(report, args)?;
            run_with(&recorded.args, recorded.fingerprint.as_deref())
        }
        None => run_with(args, None),
    }
}

/// A run; `fingerprint` is the scene's as a replayed report recorded it.
fn run_with(args: &RunArgs, fingerprint: Option<&str>) -> Result<ExitCode, Failure> {
    start_threads(args.threads)?;
    let interrupt = Interrupt::default();
    let mut options = args.options(&interrupt);
    options
        .validate()
        .map_err(|e| invalid_option(&e, Command::Run))?;
    options.shard = args
        .shard
        .as_deref()
        .map(|text| shard_of(text, args))
        .transpose()?;
    let spec = args.scene.as_deref().unwrap_or_default();
    let mut loaded = load(spec, obj_options(args.no_merge))?;
    let unit = unit_of(args.unit.as_deref())?;
    if unit.is_some() {
        loaded.scene.unit = unit;
    }
    // The camera the options give, if any: it replaces the scene's, and a shard records it.
    let camera =
        crate::camera::camera(args, &loaded.scene).map_err(|e| usage(anyhow::anyhow!(e)))?;
    if camera.is_some() {
        loaded.scene.camera = camera;
    }
    if !args.quiet {
        warn_on_load(&loaded, spec, fingerprint);
    }
    let svgs = svg_selection(&args.svg, &loaded.scene)?;
    let exports = crate::export::formats("--export", &args.export)?;
    let signals = Signals::catch(&interrupt, args.out.clone()).context("cannot catch Ctrl-C")?;
    let bars = Bars::new(args.quiet);
    let mut result = match penumbra::run(loaded, &options, &bars) {
        Ok(result) => {
            signals.writing();
            result
        }
        Err(penumbra::RunError::Solve(penumbra_solver::SolveError::Interrupted)) => {
            drop(bars);
            eprintln!(
                "interrupted before a solution existed: nothing written, {} left as it was",
                args.out.display()
            );
            return Ok(signals.status());
        }
        Err(e) => return Err(run_failure(e, Command::Run)),
    };
    if !args.quiet {
        warn_on_result(&result);
    }
    result.invocation = Some(invocation(args)?);
    match options.shard {
        Some(shard) => {
            let origin = penumbra::shard::SceneOrigin {
                spec: spec.to_owned(),
                no_merge: args.no_merge,
                camera,
                unit,
            };
            write_shard(&result, shard, origin, args, &svgs)?;
        }
        None => write_run(&result, args, &svgs, &exports)?,
    }
    if interrupt.is_set() {
        if let Some(stopped) = result.stopped {
            eprintln!(
                "interrupted in the {} stage: wrote {} to {}, marked partial in report.json",
                stage_name(stopped.stage),
                match stopped.kept {
                    Kept::SolutionSoFar => "the solution so far",
                    Kept::LeastMeshDirect => "the scene's least mesh with its direct light",
                },
                args.out.display()
            );
        }
        return Ok(signals.status());
    }
    Ok(ExitCode::SUCCESS)
}

/// How `report.json` names a stage.
fn stage_name(stage: Stage) -> String {
    serde_json::to_value(stage)
        .ok()
        .and_then(|v| v.as_str().map(str::to_owned))
        .unwrap_or_default()
}

/// `--threads`: the worker pool's size, if given.
fn start_threads(threads: Option<usize>) -> Result<(), Failure> {
    let Some(n) = threads else {
        return Ok(());
    };
    if !(1..=MAX_THREADS).contains(&n) {
        return Err(usage(anyhow::anyhow!(
            "--threads must be from 1 to {MAX_THREADS}, not {n}"
        )));
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build_global()
        .context("cannot start the worker threads")?;
    Ok(())
}

/// The loader's warnings, and one when a replayed run's scene is not the one it recorded
/// (`fingerprint`).
fn warn_on_load(loaded: &penumbra_scenes::LoadedScene, spec: &str, fingerprint: Option<&str>) {
    for w in &loaded.warnings {
        eprintln!("warning: {w}");
    }
    if let Some(recorded) = fingerprint
        && recorded != penumbra::shard::scene_fingerprint(loaded)
    {
        eprintln!(
            "warning: {spec} is not the scene the recorded run loaded (its fingerprint \
             differs): the results will differ"
        );
    }
}

/// The run's warnings worth saying at once: energy that does not balance, direct light
/// estimated by rays.
fn warn_on_result(result: &RunResult) {
    let stats = &result.solution.stats;
    let energy = penumbra::energy::EnergyBalance::of(stats).warning();
    for w in energy
        .into_iter()
        .chain(penumbra::outputs::estimated_direct_warning(stats))
    {
        eprintln!("warning: {w}");
    }
}

/// A shard's files, and what it lit.
fn write_shard(
    result: &RunResult,
    shard: penumbra::shard::Shard,
    origin: penumbra::shard::SceneOrigin,
    args: &RunArgs,
    svgs: &SvgSelection,
) -> Result<(), Failure> {
    let written = penumbra::shard::write_shard(result, shard, origin, &args.out, svgs)?;
    if args.quiet {
        return Ok(());
    }
    let on = result.surfaces_of(shard);
    let lit = |count: fn(&penumbra_meshing::SurfaceMesh) -> usize| -> usize {
        result
            .mesh
            .surfaces
            .iter()
            .zip(&on)
            .filter(|(_, on)| **on)
            .map(|(m, _)| count(m))
            .sum()
    };
    println!(
        "{}: shard {shard}: {} of {} surfaces, {} triangles, {} vertices lit; direct light \
         {:.2} s, {:.2} s in all",
        result.loaded.scene.name,
        on.iter().filter(|&&b| b).count(),
        on.len(),
        lit(penumbra_meshing::SurfaceMesh::triangle_count),
        lit(penumbra_meshing::SurfaceMesh::vertex_count),
        result.times.direct,
        result.times.total
    );
    println!(
        "wrote {} files to {} (join the shards with `penumbra merge`)",
        written.len(),
        args.out.display()
    );
    Ok(())
}

/// A whole run's files: its own, then its exports (the run's files are written even when its
/// exports cannot be).
fn write_run(
    result: &RunResult,
    args: &RunArgs,
    svgs: &SvgSelection,
    exports: &[ExportFormat],
) -> Result<(), Failure> {
    let mut extra = if args.convergence {
        penumbra::outputs::convergence_files(result)?
    } else {
        Vec::new()
    };
    let exported = export_run(result, svgs, exports);
    if let Ok(files) = &exported {
        extra.extend(files.iter().cloned());
    }
    let written = write_outputs(result, &args.out, svgs, extra)?;
    if !args.quiet {
        let stats = &result.solution.stats;
        println!(
            "{}: {} mesh, {} discontinuity segments, {} triangles, {} vertices, {} patches; {} iterations ({:?}), \
             residual {:.2e}; {:.2} s",
            result.loaded.scene.name,
            if result.mesh.discontinuity_stats.is_some() {
                "discontinuity"
            } else {
                "uniform"
            },
            result.mesh.segment_count(),
            result.mesh.triangle_count(),
            result.mesh.vertex_count(),
            stats.patches,
            stats.iterations,
            stats.stop,
            stats.residual,
            result.times.total
        );
        println!("wrote {} files to {}", written.len(), args.out.display());
    }
    if let Err(e) = exported {
        return Err(anyhow::anyhow!(
            "wrote the run's files to {}, but not its exports: {e}",
            args.out.display()
        )
        .into());
    }
    Ok(())
}

/// The command line of this run, for `report.json`.
fn invocation(args: &RunArgs) -> Result<Invocation, Failure> {
    Ok(Invocation {
        arguments: std::env::args_os()
            .map(|a| a.to_string_lossy().into_owned())
            .collect(),
        working_directory: std::env::current_dir()
            .map(|d| d.display().to_string())
            .unwrap_or_default(),
        options: serde_json::to_value(args)?,
    })
}

/// `--unit`'s unit, if given.
fn unit_of(text: Option<&str>) -> Result<Option<LengthUnit>, Failure> {
    let Some(text) = text else {
        return Ok(None);
    };
    LengthUnit::from_symbol(text).map(Some).ok_or_else(|| {
        let symbols: Vec<&str> = LengthUnit::ALL.iter().map(|u| u.symbol()).collect();
        usage(anyhow::anyhow!(
            "--unit {text:?}: not a unit; give one of {}",
            symbols.join(", ")
        ))
    })
}
