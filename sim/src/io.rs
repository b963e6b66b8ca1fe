//! Reading input files safely (regular files only, of bounded size) and
//! writing result files safely (a file appears whole or not at all).

use std::fs;
use std::io::{BufWriter, Read, Write};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

use anyhow::{Context, Result};

/// The largest input file read (configuration, network, thrust file, grid
/// files): 64 MiB, far above any file the tool writes (a paper-sized
/// `records.csv` is about 200 KB) and small enough to hold in memory.
pub const MAX_INPUT_BYTES: u64 = 64 << 20;

/// Reads the text of the input file `path`, described as `what` in errors
/// ("cannot read {what} {path}: {problem}"); see [`read_input_text`].
pub fn read_input(path: &Path, what: &str) -> Result<String> {
    read_input_text(path).map_err(|problem| anyhow::anyhow!("cannot read {what} {}: {problem}", path.display()))
}

/// Reads the text of the input file `path`; the error is the problem alone.
///
/// Anything but a regular file (a FIFO, a device, a directory, a socket) is
/// refused by name before it is opened, since opening or reading one can
/// block forever or never end; so is a file larger than [`MAX_INPUT_BYTES`].
pub fn read_input_text(path: &Path) -> Result<String, String> {
    let meta = fs::metadata(path).map_err(|e| e.to_string())?;
    if !meta.is_file() {
        return Err(format!(
            "it is {}, not a regular file",
            describe_file_type(&meta.file_type())
        ));
    }
    if meta.len() > MAX_INPUT_BYTES {
        return Err(format!(
            "it holds {} bytes, more than the {MAX_INPUT_BYTES} an input file may",
            meta.len()
        ));
    }
    let file = fs::File::open(path).map_err(|e| e.to_string())?;
    let mut text = String::new();
    // `take` bounds a file that grows after the check.
    file.take(MAX_INPUT_BYTES + 1)
        .read_to_string(&mut text)
        .map_err(|e| e.to_string())?;
    if text.len() as u64 > MAX_INPUT_BYTES {
        return Err(format!("it grew past {MAX_INPUT_BYTES} bytes while being read"));
    }
    Ok(text)
}

/// "a directory", "a FIFO (named pipe)", ...: what a file that is not a
/// regular file is.
fn describe_file_type(kind: &fs::FileType) -> &'static str {
    if kind.is_symlink() {
        return "a symbolic link";
    }
    if kind.is_file() {
        return "a regular file";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if kind.is_char_device() || kind.is_block_device() {
            return "a device";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    if kind.is_dir() {
        "a directory"
    } else {
        "not a regular file"
    }
}

/// Checks that `path` may be written as an output file: a new name or a
/// regular file, never a symbolic link, a FIFO, a device, a socket or a
/// directory, since renaming a result over one would replace it (as root,
/// `--out /dev/null` would turn `/dev/null` into a regular file) and
/// writing through a link writes wherever it points. The error names the
/// path and what it is.
pub fn check_output_file(path: &Path) -> Result<()> {
    match fs::symlink_metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e).with_context(|| format!("cannot write {}", path.display())),
        Ok(meta) if meta.file_type().is_file() => Ok(()),
        Ok(meta) => anyhow::bail!(
            "cannot write {}: it is {}; an output file must be a regular file or a new name",
            path.display(),
            describe_file_type(&meta.file_type())
        ),
    }
}

/// Creates the output folder `dir` (and its parents) unless it exists; an
/// existing `dir` must be a directory (a symbolic link to a directory is
/// followed). Anything else (a regular file, a FIFO, a device, a link to
/// one, a dangling link) is refused with an error naming it.
pub fn create_output_dir(dir: &Path) -> Result<()> {
    match fs::metadata(dir) {
        Ok(meta) if meta.is_dir() => return Ok(()),
        Ok(meta) => anyhow::bail!(
            "cannot use {} as an output folder: it is {}, not a directory",
            dir.display(),
            describe_file_type(&meta.file_type())
        ),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => return Err(e).with_context(|| format!("cannot use {} as an output folder", dir.display())),
    }
    if fs::symlink_metadata(dir).is_ok() {
        anyhow::bail!(
            "cannot use {} as an output folder: it is a symbolic link to nothing",
            dir.display()
        );
    }
    fs::create_dir_all(dir).with_context(|| format!("cannot create output folder {}", dir.display()))
}

/// Writes `contents` to `path` atomically: into a temporary file in the same
/// directory, flushed to disk, then renamed over `path`, and the directory
/// flushed too. A crash leaves either the old file or the new one, never a
/// torn one. The temporary file's name holds the host, the process id and a
/// counter, so that processes on several hosts sharing a file system never
/// write into one another's (see [`temporary_name`]).
pub fn write_atomic(path: &Path, contents: &[u8]) -> Result<()> {
    write_atomic_with(path, |w| Ok(w.write_all(contents)?))
}

/// As [`write_atomic`], the contents written by `write` as it goes (so that
/// a long output never has to be held in memory). When `write` fails,
/// `path` is left as it was and its error is returned.
pub fn write_atomic_with(path: &Path, write: impl FnOnce(&mut dyn Write) -> Result<()>) -> Result<()> {
    check_output_file(path)?;
    let (dir, tmp) = temporary_beside(path)?;
    let result = (|| -> Result<()> {
        let mut file = BufWriter::new(fs::File::create(&tmp)?);
        write(&mut file)?;
        let file = file.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        fs::rename(&tmp, path)?;
        sync_dir(dir)?;
        Ok(())
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result.with_context(|| format!("cannot write {}", path.display()))
}

/// The folder of `path` and a fresh temporary file name in it (see
/// [`temporary_name`]), for writing `path` under another name first.
fn temporary_beside(path: &Path) -> Result<(&Path, std::path::PathBuf)> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .with_context(|| format!("{} is not a file path", path.display()))?;
    let tmp = dir.join(temporary_name(&name.to_string_lossy()));
    Ok((dir, tmp))
}

/// Creates `path` with `contents` unless it exists: `Ok(true)` when this
/// call created it, `Ok(false)` when it was already there (its contents
/// untouched). The file appears whole: it is written under a temporary name
/// and hard-linked to `path`, which fails when `path` exists; on a file
/// system without hard links it is created exclusively and then written.
/// Several processes on several hosts may race for one `path`: exactly one
/// creates it.
pub fn create_new_atomic(path: &Path, contents: &[u8]) -> Result<bool> {
    check_output_file(path)?;
    let (dir, tmp) = temporary_beside(path)?;
    let result = (|| -> std::io::Result<bool> {
        let mut file = fs::File::create(&tmp)?;
        file.write_all(contents)?;
        file.sync_all()?;
        let created = match fs::hard_link(&tmp, path) {
            Ok(()) => true,
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => false,
            Err(_) => match fs::File::create_new(path) {
                Ok(mut file) => {
                    file.write_all(contents)?;
                    file.sync_all()?;
                    true
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => false,
                Err(e) => return Err(e),
            },
        };
        if created {
            sync_dir(dir)?;
        }
        Ok(created)
    })();
    let _ = fs::remove_file(&tmp);
    result.with_context(|| format!("cannot create {}", path.display()))
}

/// The name of a temporary file beside `name`: `.NAME.tmp-HOST-PID-N`, with
/// N counting this process's temporary files. Unique across the processes
/// and hosts that share a file system.
pub fn temporary_name(name: &str) -> String {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    format!(
        ".{name}.tmp-{}-{}-{}",
        crate::provenance::host_name(),
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    )
}

/// Removes the temporary files (see [`temporary_name`]) that processes of
/// this host which are no longer running left in `dir` when they were
/// killed; those of live processes and of other hosts are left alone.
/// Returns how many it removed.
pub fn remove_stale_temporaries(dir: &Path) -> usize {
    let Ok(entries) = fs::read_dir(dir) else {
        return 0;
    };
    let marker = format!(".tmp-{}-", crate::provenance::host_name());
    let mut removed = 0;
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let Some(at) = name.find(&marker).filter(|_| name.starts_with('.')) else {
            continue;
        };
        let pid: String = name[at + marker.len()..]
            .chars()
            .take_while(char::is_ascii_digit)
            .collect();
        let Ok(pid) = pid.parse::<u32>() else { continue };
        let gone = pid != std::process::id()
            && Path::new("/proc/self").exists()
            && !Path::new(&format!("/proc/{pid}")).exists();
        if gone && entry.file_type().is_ok_and(|t| t.is_file()) && fs::remove_file(entry.path()).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// Flushes the directory `dir` to disk, so that a rename into it survives
/// a crash (on Unix; elsewhere there is nothing to flush).
pub fn sync_dir(dir: &Path) -> std::io::Result<()> {
    #[cfg(unix)]
    fs::File::open(dir)?.sync_all()?;
    #[cfg(not(unix))]
    let _ = dir;
    Ok(())
}

/// Writes `value` to `path` atomically as pretty JSON with a final newline.
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> Result<()> {
    let mut json = serde_json::to_string_pretty(value)?;
    json.push('\n');
    write_atomic(path, json.as_bytes())
}

/// Reads the JSON document at `path` whose `"format"` field must be
/// `format` and `"version"` field `version` (the error names the file and
/// calls it `what`, e.g. "grid").
pub fn read_versioned_json<T: serde::de::DeserializeOwned>(
    path: &Path,
    format: &str,
    version: u32,
    what: &str,
) -> Result<T> {
    let text = read_input(path, &format!("{what} file"))?;
    let value: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not valid JSON", path.display()))?;
    if value.get("format").and_then(|f| f.as_str()) != Some(format) {
        anyhow::bail!(
            "{}: not a psa-esp {what} file (no \"format\": {format:?})",
            path.display()
        );
    }
    if value.get("version").and_then(|v| v.as_u64()) != Some(version as u64) {
        anyhow::bail!(
            "{}: unknown {what} version; this build reads version {version}",
            path.display()
        );
    }
    serde_json::from_value(value).with_context(|| format!("{}", path.display()))
}

/// Seeds as decimal strings in JSON (tools that read numbers as doubles
/// lose digits above 2^53): the search crate's, so that both write them
/// alike. Use with `#[serde(with = "crate::io::u64_string")]`.
pub use esp_neuroevolution::rng::u64_string;

#[cfg(test)]
mod tests {
    use super::*;
    use anyhow::bail;

    #[test]
    fn only_regular_files_of_bounded_size_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("config.toml");
        fs::write(&file, "a = 1\n").unwrap();
        assert_eq!(read_input(&file, "configuration").unwrap(), "a = 1\n");
        let err = read_input(dir.path(), "configuration").unwrap_err().to_string();
        assert!(err.contains("configuration") && err.contains("a directory"), "{err}");
        let err = read_input(&dir.path().join("missing"), "network file")
            .unwrap_err()
            .to_string();
        assert!(err.contains("network file") && err.contains("missing"), "{err}");
        let big = dir.path().join("big");
        fs::File::create(&big).unwrap().set_len(MAX_INPUT_BYTES + 1).unwrap();
        let err = read_input(&big, "thrust file").unwrap_err().to_string();
        assert!(err.contains("more than"), "{err}");
        #[cfg(unix)]
        {
            let err = read_input(Path::new("/dev/zero"), "configuration")
                .unwrap_err()
                .to_string();
            assert!(err.contains("a device"), "{err}");
        }
    }

    #[test]
    fn a_failed_streaming_write_leaves_the_old_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.csv");
        write_atomic(&path, b"old\n").unwrap();
        let err = write_atomic_with(&path, |w| {
            w.write_all(b"new, partial")?;
            bail!("stopped half-way")
        })
        .unwrap_err();
        assert!(format!("{err:#}").contains("stopped half-way"), "{err:#}");
        assert_eq!(fs::read_to_string(&path).unwrap(), "old\n");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1, "no temporary file left");
        write_atomic_with(&path, |w| Ok(w.write_all(b"new\n")?)).unwrap();
        assert_eq!(fs::read_to_string(&path).unwrap(), "new\n");
    }

    #[derive(Debug, PartialEq, serde::Serialize, serde::Deserialize)]
    struct Seeded {
        #[serde(with = "u64_string")]
        seed: u64,
    }

    #[test]
    fn seeds_are_written_as_strings_and_read_from_either_form() {
        for seed in [0, 1, (1 << 53) + 1, u64::MAX] {
            let json = serde_json::to_string(&Seeded { seed }).unwrap();
            assert_eq!(json, format!("{{\"seed\":\"{seed}\"}}"));
            assert_eq!(serde_json::from_str::<Seeded>(&json).unwrap().seed, seed);
            let number = format!("{{\"seed\":{seed}}}");
            assert_eq!(serde_json::from_str::<Seeded>(&number).unwrap().seed, seed);
        }
        for bad in [
            r#"{"seed":"-1"}"#,
            r#"{"seed":"18446744073709551616"}"#,
            r#"{"seed":1.5}"#,
            r#"{"seed":"x"}"#,
        ] {
            assert!(serde_json::from_str::<Seeded>(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn a_new_file_is_created_once_and_never_overwritten() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("grid.json");
        assert!(create_new_atomic(&path, b"first\n").unwrap());
        assert!(!create_new_atomic(&path, b"second\n").unwrap());
        assert_eq!(fs::read_to_string(&path).unwrap(), "first\n");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1, "no temporary file left");
    }

    #[test]
    fn temporary_names_hold_host_and_pid() {
        let (a, b) = (temporary_name("run.json"), temporary_name("run.json"));
        assert_ne!(a, b);
        let host = crate::provenance::host_name();
        assert!(
            a.starts_with(&format!(".run.json.tmp-{host}-{}-", std::process::id())),
            "{a}"
        );
    }
}
