//! Runs that several variants of a sweep share: a variant whose change no
//! run of a task reads (task 2's start, in a task-1 run) flies that task's
//! runs exactly as an earlier variant does. The sweep runs each such run
//! once, in the earliest variant, and writes the others from it: the same
//! records, champion, robustness results and run summary, with the
//! variant's own configuration in `config.toml` and `champion.json` (the
//! files a run of that variant writes, byte for byte, but for run.json's
//! times, which are the source's).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{Context, Result};

use crate::grid::checkpoint::remove_checkpoint;
use crate::grid::claim::{clear_stale, CLAIM_FILE};
use crate::grid::{run_dir, run_status, settings_read_by, GridSpec, RunKey, RunStatus, FINISHED_MARKER};
use crate::{RunConfig, RunFiles};
use psa_sim::psa::NetworkFile;

/// A run of one grid that an earlier grid flies as well.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SharedRun {
    /// The grid (index into the sweep's grids) whose run is written from the other.
    pub grid: usize,
    /// The run.
    pub key: RunKey,
    /// The earlier grid that runs it.
    pub source: usize,
}

/// Every run of `grids` (folder, definition) that an earlier grid flies
/// as well: the same grid definition but for the overrides, the same
/// configuration, task and seed, and the same value of every setting that
/// task reads.
pub fn shared_runs(grids: &[(PathBuf, GridSpec)]) -> Result<Vec<SharedRun>> {
    let mut first: HashMap<String, usize> = HashMap::new();
    let mut shared = Vec::new();
    for (index, (_, spec)) in grids.iter().enumerate() {
        let definition = serde_json::to_string(&GridSpec {
            overrides: None,
            ..spec.clone()
        })?;
        let mut read: HashMap<(String, u8), String> = HashMap::new();
        for key in spec.runs() {
            let settings = match read.get(&(key.config.to_string(), key.task.number())) {
                Some(s) => s.clone(),
                None => {
                    let s = settings_read_by(key.task, &spec.run_config(key.config)?)?;
                    read.insert((key.config.to_string(), key.task.number()), s.clone());
                    s
                }
            };
            let identity = format!("{definition}\n{}\n{}\n{}\n{settings}", key.config, key.task, key.seed);
            match first.get(&identity) {
                Some(&source) => shared.push(SharedRun {
                    grid: index,
                    key,
                    source,
                }),
                None => {
                    first.insert(identity, index);
                }
            }
        }
    }
    Ok(shared)
}

/// Writes every shared run whose source is finished and whose own folder
/// is missing or unfinished (a killed run's, once its claim is stale by
/// `claim_timeout` or its process is gone);
/// returns how many it wrote.
pub fn write_shared(grids: &[(PathBuf, GridSpec)], shared: &[SharedRun], claim_timeout: Duration) -> Result<usize> {
    let mut written = 0;
    for run in shared {
        let (source_dir, _) = &grids[run.source];
        let (dir, spec) = &grids[run.grid];
        let (source, target) = (run_dir(source_dir, &run.key), run_dir(dir, &run.key));
        if !source.join(FINISHED_MARKER).is_file() {
            continue;
        }
        match run_status(dir, spec, &run.key)? {
            RunStatus::Finished => continue,
            RunStatus::Missing => {}
            // Left by a process killed while it flew the run itself (a
            // build before shared runs, or a sweep defined otherwise):
            // written over once its claim is stale, as a resume runs it again.
            RunStatus::Unfinished => {
                clear_stale(&target, claim_timeout)?;
                if target.join(CLAIM_FILE).exists() {
                    continue;
                }
                remove_checkpoint(&target)?;
            }
        }
        let config = spec.run_config(run.key.config)?;
        write_from(&source, &target, &config)
            .with_context(|| format!("writing run {} from {}", target.display(), source.display()))?;
        written += 1;
    }
    Ok(written)
}

/// Writes the run folder `target` from the finished run in `source`, as a
/// run under `config` writes it: `config.toml` first, robustness.json
/// (which marks it finished) last.
fn write_from(source: &Path, target: &Path, config: &RunConfig) -> Result<()> {
    let (from, to) = (RunFiles::in_dir(source), RunFiles::in_dir(target));
    std::fs::create_dir_all(target).with_context(|| format!("cannot create {}", target.display()))?;
    psa_sim::io::write_atomic(&to.config, config.to_toml()?.as_bytes())?;
    for (from, to) in [(&from.records, &to.records), (&from.summary, &to.summary)] {
        let bytes = std::fs::read(from).with_context(|| format!("cannot read {}", from.display()))?;
        psa_sim::io::write_atomic(to, &bytes)?;
    }
    let (mut champion, _) = NetworkFile::load(&from.champion)?;
    champion.input_scaling = config.problem.sensors;
    champion.problem = Some(config.problem.clone());
    champion.save(&to.champion)?;
    let marker = std::fs::read(source.join(FINISHED_MARKER))?;
    psa_sim::io::write_atomic(&target.join(FINISHED_MARKER), &marker)
}
