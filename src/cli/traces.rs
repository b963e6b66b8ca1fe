//! `psa-esp traces`: traced runs (`evolve --trace`) summarised by group.

use std::path::PathBuf;

use anyhow::Result;

use psa_experiment::trace::summary::write_summary;

/// Arguments of `traces`.
#[derive(Debug, clap::Args)]
pub struct TracesArgs {
    /// Folders of traces, one group each (named by the folder; by its path
    /// where two share a name): every `*.trace.csv` in it, as `psa-esp
    /// evolve --trace` writes them. A folder named twice is refused.
    #[arg(required = true)]
    pub dirs: Vec<PathBuf>,
    /// Where traces.md, traces.csv, traces-landing.csv and the figure traces-landing.svg/.png
    /// go: a new or empty folder.
    #[arg(long)]
    pub out: PathBuf,
    /// Sum a folder's traces even when their headers name different tasks,
    /// configurations, generation budgets or models (refused without it).
    #[arg(long)]
    pub pool: bool,
}

/// Runs `traces`: prints the summary table and the files written.
pub fn run(args: TracesArgs) -> Result<i32> {
    super::require_utf8_folder("--out", &args.out)?;
    let (markdown, written) = write_summary(&args.dirs, &args.out, args.pool)?;
    say!("{}", markdown.trim_end());
    for path in written {
        eprintln!("wrote {}", path.display());
    }
    Ok(0)
}
