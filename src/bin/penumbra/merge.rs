//! `penumbra merge`: the shards of a run joined into one.

use std::path::PathBuf;

use penumbra_scenes::load_scene_with;

use crate::failure::{Failure, usage};
use crate::obj_options;

#[derive(clap::Args, Debug)]
#[command(
    after_help = "Examples:\n  penumbra run boxworld-1000 --direct-only --shard 0/2 --out s0\n  penumbra run boxworld-1000 --direct-only --shard 1/2 --out s1\n  penumbra merge s0 s1 --out whole"
)]
pub(crate) struct MergeArgs {
    /// The output directories of the shards (`run --shard I/N --out DIR`), every shard once.
    #[arg(required = true)]
    dirs: Vec<PathBuf>,
    /// Output directory.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    /// The scene the shards were run on, to render the joined solution (default: as the shards
    /// were given it; checked against their fingerprint).
    #[arg(long)]
    scene: Option<String>,
    /// No summary.
    #[arg(long)]
    quiet: bool,
}

pub(crate) fn merge(args: &MergeArgs) -> Result<(), Failure> {
    use penumbra::shard::{MergeError, check_shards, merge, read_shard, write_merged};
    let fail = |e: MergeError| {
        if e.is_usage() {
            usage(e)
        } else {
            Failure::from(e)
        }
    };
    let mut shards = Vec::with_capacity(args.dirs.len());
    for dir in &args.dirs {
        shards.push((dir.clone(), read_shard(dir).map_err(fail)?));
    }
    let shards = check_shards(shards).map_err(fail)?;
    let origin = shards
        .first()
        .map(|(_, f)| f.scene.clone())
        .ok_or_else(|| fail(MergeError::Nothing))?;
    let spec = args.scene.clone().unwrap_or(origin.spec);
    let mut loaded = load_scene_with(&spec, &obj_options(origin.no_merge)).map_err(|e| {
        usage(anyhow::anyhow!(
            "{}; give the scene with --scene",
            MergeError::Scene(e)
        ))
    })?;
    if origin.camera.is_some() {
        loaded.scene.camera = origin.camera;
    }
    if origin.unit.is_some() {
        loaded.scene.unit = origin.unit;
    }
    let merged = merge(shards, &loaded).map_err(|e| match e {
        MergeError::SceneChanged { .. } if args.scene.is_none() => usage(anyhow::anyhow!(
            "{e}; give the scene the shards were run on with --scene"
        )),
        e => fail(e),
    })?;
    let written = write_merged(&merged, &args.out)?;
    if !args.quiet {
        println!(
            "{}: {} shards joined: {} surfaces, {} triangles, {} vertices",
            merged.scene_name, merged.shards, merged.surfaces, merged.triangles, merged.vertices
        );
        println!("wrote {} files to {}", written.len(), args.out.display());
    }
    Ok(())
}
