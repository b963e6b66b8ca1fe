//! `psa-esp traces`: traced runs (`evolve --trace`) summarised by group.

use std::path::PathBuf;

use anyhow::Result;

use psa_experiment::trace::summary::write_summary;

/// Arguments of `traces`.
#[derive(Debug, clap::Args)]
pub struct TracesArgs {
    /// Folders of traces, one group each (named by the folder): every
    /// `*.trace.csv` in it, as `psa-esp evolve --trace` writes them.
    #[arg(required = true)]
    pub dirs: Vec<PathBuf>,
    /// Where traces.md, traces.csv and the figure traces-landing.svg/.png go.
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs `traces`: prints the summary table and the files written.
pub fn run(args: TracesArgs) -> Result<i32> {
    let (markdown, written) = write_summary(&args.dirs, &args.out)?;
    say!("{}", markdown.trim_end());
    for path in written {
        eprintln!("wrote {}", path.display());
    }
    Ok(0)
}
