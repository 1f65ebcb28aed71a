//! `penumbra form-factors`: every form-factor method against closed forms.

use std::path::PathBuf;

use anyhow::Context;
use penumbra_solver::SolverOptions;

use crate::failure::{Command, Failure, invalid_option};

#[derive(clap::Args, Debug)]
#[command(
    after_help = "Examples:\n  penumbra form-factors                         every method, the default ladders\n  penumbra form-factors --samples 64,1024 --resolutions 64,256 --out ff"
)]
pub(crate) struct FormFactorArgs {
    /// Output directory (created if missing).
    #[arg(long, default_value = "out/form-factors")]
    out: PathBuf,
    /// Rays per point–patch pair for the analytic method's visibility fraction.
    #[arg(long, default_value_t = SolverOptions::default().visibility_rays)]
    rays: usize,
    /// Monte Carlo sample counts to measure (comma-separated).
    #[arg(long, value_delimiter = ',', default_values_t = [64, 256, 4096])]
    samples: Vec<usize>,
    /// Hemicube resolutions to measure (comma-separated, even).
    #[arg(long, value_delimiter = ',', default_values_t = [32, 64, 128, 256, 512])]
    resolutions: Vec<usize>,
    /// Independent random streams the stochastic methods' errors are averaged over.
    #[arg(long, default_value_t = 16)]
    streams: usize,
    /// Triangles of the unit cube's mesh.
    #[arg(long, default_value_t = 2400)]
    cube_elements: usize,
}

pub(crate) fn form_factors(args: &FormFactorArgs) -> Result<(), Failure> {
    let options = penumbra::experiments::form_factors::StudyOptions {
        rays: args.rays,
        samples: args.samples.clone(),
        resolutions: args.resolutions.clone(),
        streams: args.streams,
        cube_elements: args.cube_elements,
    };
    use penumbra::experiments::form_factors::{StudyError, run_study};
    let study = run_study(&options).map_err(|e| match e {
        StudyError::InvalidOption(e) => invalid_option(&e, Command::FormFactors),
        e => Failure::from(e),
    })?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let path = args.out.join("form-factors.json");
    let json = serde_json::to_vec_pretty(&study)?;
    penumbra::outputs::write_atomic(&path, &json)
        .with_context(|| format!("cannot write {}", path.display()))?;
    #[allow(clippy::print_stdout)] // the tables are this command's output
    {
        println!("{}", study.markdown());
    }
    eprintln!("wrote {}", path.display());
    Ok(())
}
