//! A lockstep run's checkpoint: the file in its folder that holds its
//! whole search state while it is unfinished, written by the lockstep
//! executor ([`crate::grid::lockstep`]) every few rounds, read back when the
//! grid resumes, and removed once the run is finished (by either executor).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use rayon::prelude::*;

use esp_neuroevolution::{AnyRun, AskTell};

/// A lockstep run's saved state, in its folder while it is unfinished.
pub const CHECKPOINT: &str = "checkpoint.json";

/// Saves every unfinished run of `runs` to its checkpoint file (of
/// `files`), in parallel; a run that cannot be saved goes on unsaved.
pub(crate) fn save_checkpoints(runs: &[AnyRun], files: &[PathBuf]) {
    runs.par_iter().zip(files).with_max_len(1).for_each(|(run, file)| {
        if run.ending().is_none() {
            let saved = serde_json::to_vec(run).map_err(anyhow::Error::from).and_then(|json| {
                // One that could not be read back is not written.
                anyhow::ensure!(
                    json.len() as u64 <= psa_sim::io::MAX_INPUT_BYTES,
                    "the run's state takes {} bytes, more than the {} an input file may",
                    json.len(),
                    psa_sim::io::MAX_INPUT_BYTES
                );
                Ok(json)
            });
            if let Err(e) = saved.and_then(|json| psa_sim::io::write_atomic(file, &json)) {
                log::warn!("cannot save {}: {e:#}", file.display());
            }
        }
    });
}

/// Refuses a run whose checkpoint is there but not a regular file (a
/// directory, a FIFO, a link): it could be neither read nor removed; or a
/// damaged one, by every executor alike (the run is never restarted over a
/// file that cannot be read: [`resume`]'s rule). A checkpoint that reads is
/// left to the executor (an executor that does not resume runs the run
/// from its start, to the same results, and removes it when finished).
pub(crate) fn check_checkpoint(folder: &Path) -> Result<()> {
    let file = folder.join(CHECKPOINT);
    match std::fs::symlink_metadata(&file) {
        Ok(meta) if meta.file_type().is_file() => {
            let json = psa_sim::io::read_input_text(&file).map_err(|problem| {
                anyhow::anyhow!("{}: {problem}; remove it to start the run afresh", file.display())
            })?;
            match serde_json::from_str::<AnyRun>(&json) {
                Ok(_) => Ok(()),
                Err(e) => anyhow::bail!(
                    "{}: damaged, not a saved run ({e}); remove it to start the run afresh",
                    file.display()
                ),
            }
        }
        Ok(meta) if !meta.file_type().is_file() => anyhow::bail!(
            "{}: it is not a regular file (a {}); remove it to run the run",
            file.display(),
            if meta.is_dir() {
                "directory"
            } else if meta.file_type().is_symlink() {
                "symbolic link"
            } else {
                "FIFO, device or socket"
            }
        ),
        _ => Ok(()),
    }
}

/// Removes a finished run's checkpoint, if any.
pub(crate) fn remove_checkpoint(folder: &Path) -> Result<()> {
    match std::fs::remove_file(folder.join(CHECKPOINT)) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            Err(e).with_context(|| format!("cannot remove {}", folder.join(CHECKPOINT).display()))
        }
        _ => Ok(()),
    }
}

/// The run that `folder`'s checkpoint saved, when there is one of the
/// same search as `fresh` (else `fresh`: a checkpoint of another search is
/// ignored, with a warning). A checkpoint is an
/// input file as any other (docs/limits.md): anything but a regular file
/// (a FIFO, a link, a directory, a device) or a file over
/// [`psa_sim::io::MAX_INPUT_BYTES`] is refused, and the run with it, by an
/// error naming it, before the run starts; so is every damaged one
/// (garbage, not UTF-8, zeroed, truncated, empty): one rule for all damage.
pub(crate) fn resume(folder: &Path, fresh: AnyRun) -> Result<AnyRun> {
    let file = folder.join(CHECKPOINT);
    match std::fs::symlink_metadata(&file) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(fresh),
        // Anything else but a regular file is refused by read_input_text
        // below, naming what it is; a link is refused even when it points at
        // a regular file.
        Ok(meta) if meta.file_type().is_symlink() => {
            anyhow::bail!(
                "{}: it is a symbolic link, not a regular file; remove it to start the run afresh",
                file.display()
            );
        }
        _ => {}
    }
    let json = psa_sim::io::read_input_text(&file)
        .map_err(|problem| anyhow::anyhow!("{}: {problem}; remove it to start the run afresh", file.display()))?;
    Ok(match serde_json::from_str::<AnyRun>(&json) {
        Ok(saved) if saved.same_search(&fresh) => {
            log::info!(
                "{}: resumed after generation {}",
                folder.display(),
                saved.records().len()
            );
            saved
        }
        Ok(_) => {
            log::warn!("{}: of another search, ignored", file.display());
            fresh
        }
        Err(e) => anyhow::bail!(
            "{}: damaged, not a saved run ({e}); remove it to start the run afresh",
            file.display()
        ),
    })
}
