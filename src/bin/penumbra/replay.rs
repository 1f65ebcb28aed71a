//! `penumbra run --replay REPORT`: a run again, from the options its `report.json` records.

use std::path::Path;

use clap::Parser;
use penumbra::report::Report;

use crate::failure::{Failure, usage};
use crate::run_args::RunArgs;

/// A recorded run's arguments, and the fingerprint of the scene it loaded.
pub(crate) struct Recorded {
    pub(crate) args: RunArgs,
    pub(crate) fingerprint: Option<String>,
}

/// The run `report` records, to be written where `given` says (`--out`, `--quiet`: the only
/// options that may come with `--replay`).
pub(crate) fn recorded(report: &Path, given: &RunArgs) -> Result<Recorded, Failure> {
    refuse_other_options(given)?;
    let bad = |why: String| usage(anyhow::anyhow!("--replay {}: {why}", report.display()));
    let text = std::fs::read_to_string(report).map_err(|e| bad(format!("cannot read it: {e}")))?;
    let recorded = Report::parse(&text).map_err(|e| bad(e.to_string()))?;
    let version = recorded.version.as_str();
    let Some(invocation) = &recorded.invocation else {
        return Err(bad(
            "it records no command line to replay (it was not written by `penumbra run`)".into(),
        ));
    };
    let mut args: RunArgs = serde_json::from_value(invocation.options.clone()).map_err(|e| {
        bad(format!(
            "its options are not those of this version ({}; it was written by penumbra \
             {version}): {e}",
            penumbra::outputs::VERSION
        ))
    })?;
    args.out.clone_from(&given.out);
    args.quiet = given.quiet;
    args.replay = None;
    if let Some(scene) = &args.scene {
        args.scene = Some(resolve(scene, Path::new(&invocation.working_directory)));
    }
    if version != penumbra::outputs::VERSION && !given.quiet {
        eprintln!(
            "warning: {} was written by penumbra {version}, this is {}: results may differ",
            report.display(),
            penumbra::outputs::VERSION
        );
    }
    Ok(Recorded {
        args,
        fingerprint: Some(recorded.scene.fingerprint.clone()),
    })
}

/// A scene path of the recorded run: relative to its working directory when it is not found
/// from here (built-in names are left alone).
fn resolve(scene: &str, recorded_dir: &Path) -> String {
    let there = recorded_dir.join(scene);
    if Path::new(scene).is_relative() && !Path::new(scene).exists() && there.exists() {
        there.display().to_string()
    } else {
        scene.to_owned()
    }
}

/// `--replay` takes its options from the report: any other option given is refused, named.
fn refuse_other_options(given: &RunArgs) -> Result<(), Failure> {
    #[derive(Parser)]
    struct Plain {
        #[command(flatten)]
        args: RunArgs,
    }
    let plain = Plain::parse_from(["run", "--replay", "report.json"]).args;
    let (given, plain) = (serde_json::to_value(given)?, serde_json::to_value(&plain)?);
    let extra: Vec<String> = given
        .as_object()
        .into_iter()
        .flatten()
        .filter(|(name, value)| {
            !matches!(name.as_str(), "out" | "quiet") && plain.get(name.as_str()) != Some(value)
        })
        .map(|(name, _)| match name.as_str() {
            "scene" => "SCENE".to_owned(),
            name => format!("--{}", name.replace('_', "-")),
        })
        .collect();
    if extra.is_empty() {
        return Ok(());
    }
    Err(usage(anyhow::anyhow!(
        "--replay runs the recorded options as they were; only --out and --quiet may come with \
         it, not {}",
        extra.join(", ")
    )))
}
