//! The font that plotters needs to lay out and rasterise text.
//!
//! plotters is built with its pure-Rust `ab_glyph` text backend, which does
//! not look for system fonts by itself: a TrueType file is read once at run
//! time and registered as the `"sans-serif"` family. The SVG files also need
//! it, since plotters measures text (for legends and titles) with it.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::style::FontStyle;

/// Environment variable naming a TrueType font file to use instead of the
/// system paths searched by [`ensure_font`].
pub const FONT_ENV_VAR: &str = "PSA_ESP_FONT";

/// The family name the font is registered under; every plot uses it.
pub const FONT_FAMILY: &str = "sans-serif";

/// Debian package that provides the first font searched for.
pub const FONT_PACKAGE: &str = "fonts-dejavu-core";

/// Where regular sans-serif TrueType fonts live on common systems, tried in order.
const FONT_CANDIDATES: &[&str] = &[
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu-sans-fonts/DejaVuSans.ttf",
    "/usr/local/share/fonts/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/usr/share/fonts/liberation-sans/LiberationSans-Regular.ttf",
    "/usr/share/fonts/truetype/freefont/FreeSans.ttf",
    "/Library/Fonts/Arial.ttf",
    "/System/Library/Fonts/Supplemental/Arial.ttf",
    "C:\\Windows\\Fonts\\arial.ttf",
];

static FONT: OnceLock<Result<PathBuf, String>> = OnceLock::new();

static PACKAGED_FONT: OnceLock<PathBuf> = OnceLock::new();

/// Names a font file shipped with the program (the Python wheel's copy of
/// DejaVu Sans), tried by [`ensure_font`] after [`FONT_ENV_VAR`] and before
/// the system's paths, so that a packaged program draws the same text on
/// every machine. Only the first call counts, and only before the first
/// [`ensure_font`].
pub fn use_packaged_font(path: PathBuf) {
    let _ = PACKAGED_FONT.set(path);
}

/// Loads a sans-serif TrueType font and registers it with plotters as
/// [`FONT_FAMILY`]; later calls return the first call's outcome at once.
///
/// The file named by the environment variable [`FONT_ENV_VAR`] is tried
/// first, then a packaged font ([`use_packaged_font`]), then the usual
/// system locations (DejaVu Sans first). Returns the
/// path of the font in use, or an error that names the package to install
/// ([`FONT_PACKAGE`] on Debian and Ubuntu).
pub fn ensure_font() -> anyhow::Result<&'static Path> {
    match FONT.get_or_init(load_font) {
        Ok(path) => Ok(path.as_path()),
        Err(message) => Err(anyhow::anyhow!("{message}")),
    }
}

fn load_font() -> Result<PathBuf, String> {
    let mut candidates: Vec<PathBuf> = Vec::new();
    if let Some(path) = std::env::var_os(FONT_ENV_VAR) {
        candidates.push(PathBuf::from(path));
    }
    candidates.extend(PACKAGED_FONT.get().cloned());
    candidates.extend(FONT_CANDIDATES.iter().map(PathBuf::from));
    let mut problems = Vec::new();
    for path in candidates {
        let Ok(bytes) = std::fs::read(&path) else {
            continue;
        };
        // plotters keeps a reference to the font for the life of the process.
        let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
        match plotters::style::register_font(FONT_FAMILY, FontStyle::Normal, bytes) {
            Ok(()) => return Ok(path),
            Err(_) => problems.push(format!("{} is not a usable TrueType font", path.display())),
        }
    }
    let mut message = format!(
        "no TrueType font found for the plots: install the package `{FONT_PACKAGE}` \
         (apt-get install {FONT_PACKAGE}), or name a .ttf file in the environment variable {FONT_ENV_VAR}"
    );
    if !problems.is_empty() {
        message.push_str(&format!(" ({})", problems.join("; ")));
    }
    Err(message)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn font_is_found_and_stable() {
        let first = ensure_font().expect("a font is installed on the test machine");
        assert!(first.exists());
        assert_eq!(ensure_font().unwrap(), first);
    }
}
