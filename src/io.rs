//! Reading input files safely (regular files only, of bounded size) and
//! writing result files safely (a file appears whole or not at all).

use std::fs;
use std::io::{BufWriter, Read, Write};
use std::path::Path;

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

/// Writes `contents` to `path` atomically: into a temporary file in the same
/// directory, flushed to disk, then renamed over `path`. A crash leaves
/// either the old file or the new one, never a torn one.
pub fn write_atomic(path: &Path, contents: &[u8]) -> Result<()> {
    write_atomic_with(path, |w| Ok(w.write_all(contents)?))
}

/// As [`write_atomic`], the contents written by `write` as it goes (so that
/// a long output never has to be held in memory). When `write` fails,
/// `path` is left as it was and its error is returned.
pub fn write_atomic_with(path: &Path, write: impl FnOnce(&mut dyn Write) -> Result<()>) -> Result<()> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .with_context(|| format!("{} is not a file path", path.display()))?;
    let tmp = dir.join(format!(".{}.tmp-{}", name.to_string_lossy(), std::process::id()));
    let result = (|| -> Result<()> {
        let mut file = BufWriter::new(fs::File::create(&tmp)?);
        write(&mut file)?;
        let file = file.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        fs::rename(&tmp, path)?;
        Ok(())
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result.with_context(|| format!("cannot write {}", path.display()))
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
}
