//! `penumbra export DIR`: a finished run's solution in other tools' formats.

use std::path::PathBuf;

use penumbra::export::{ExportFormat, ExportSource, export};

use crate::failure::{Failure, usage};

#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:\n  penumbra export out --format vtp,ply\n  \
                        penumbra export out --format all")]
pub(crate) struct ExportArgs {
    /// The output directory of `penumbra run` (or `penumbra merge`): its solution.json and
    /// report.json are read, and the exports written beside them.
    dir: PathBuf,
    /// Comma-separated: `vtp` (solution.vtp, for ParaView), `ply` (MeshLab, Blender), `glb`
    /// (glTF: browsers, Blender), `obj` (with solution.mtl), `html` (index.html, the viewer
    /// page), or `all`.
    #[arg(long, default_value = "all", value_name = "FORMAT,...")]
    format: String,
    /// Print nothing.
    #[arg(long)]
    quiet: bool,
}

/// The formats `list` names, for `flag`.
pub(crate) fn formats(flag: &str, list: &str) -> Result<Vec<ExportFormat>, Failure> {
    ExportFormat::parse_list(list).map_err(|name| {
        let names: Vec<&str> = ExportFormat::ALL.iter().map(|f| f.name()).collect();
        usage(anyhow::anyhow!(
            "{flag}: {name:?} is not a format; give {}, all or none, separated by commas",
            names.join(", ")
        ))
    })
}

/// `penumbra export`.
pub(crate) fn export_run(args: &ExportArgs) -> Result<(), Failure> {
    let formats = formats("--format", &args.format)?;
    // What is wrong with a run's files is the input's: exit code 2.
    let source = ExportSource::read_run(&args.dir).map_err(usage)?;
    let files = export(&source, &formats).map_err(usage)?;
    let files: Vec<(PathBuf, Vec<u8>)> = files
        .into_iter()
        .map(|(name, bytes)| (args.dir.join(name), bytes))
        .collect();
    penumbra::outputs::write_all_atomic(&files)?;
    if !args.quiet {
        let names: Vec<String> = files
            .iter()
            .filter_map(|(path, _)| path.file_name())
            .map(|n| n.to_string_lossy().into_owned())
            .collect();
        println!("wrote {} to {}", names.join(", "), args.dir.display());
    }
    Ok(())
}
