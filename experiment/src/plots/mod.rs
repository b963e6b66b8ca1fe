//! Pictures of the project's results, drawn with `plotters` (static SVG and
//! PNG figures) and by hand (animated SVG, SMIL only, no script).
//!
//! - [`trial`]: one recorded trial: [`write_trial_pictures`] writes the path
//!   in the x-y plane with the target box and heading arrows, the four
//!   thruster outputs and the heading error and angular velocity over time
//!   (`<stem>.svg`, `<stem>.png`), and an animation that replays the trial
//!   in real time (`<stem>-animation.svg`).
//!
//! Text needs a TrueType font, read at run time (see [`ensure_font`]): on
//! Debian and Ubuntu install `fonts-dejavu-core`, or name a `.ttf` file in
//! the environment variable `PSA_ESP_FONT`.

mod animation;
pub mod curves;
mod font;
mod output;
pub mod picture;
pub mod trial;

pub use font::{ensure_font, use_packaged_font, FONT_ENV_VAR, FONT_FAMILY, FONT_PACKAGE};
pub use picture::TrialPicture;
pub use trial::{trial_frame, write_trial_pictures, FIGURE_HEIGHT, FIGURE_WIDTH};
