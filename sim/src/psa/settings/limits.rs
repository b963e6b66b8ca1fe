//! The range of every physical setting and start state, in one table.
//!
//! Each row names a key (as written under `[problem]` in a configuration,
//! or `start.*` for the start state `simulate --start` takes), its range and
//! why; a sensible experiment never leaves it (a real PSA is a softball- to
//! volleyball-sized robot with 1 N thrusters; the paper's tasks start with
//! spins of 0.75 to 1 rad/s and speeds of up to 0.4 m/s and step at 0.05 s).
//! Settings are checked against it when a configuration or the command line
//! is read, with an error naming the key, the value and the range. Within
//! these ranges no trial comes near what the physics engines cannot
//! integrate (see `physics::StepGuard`). `docs/limits.md` lists the table.
//!
//! A new setting slots in as one more row, plus one line in the `validate`
//! of the settings it belongs to (a test checks that every row is enforced
//! from a configuration).

use std::f64::consts::PI;

/// One bounded setting: its key, its range, its unit and why.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limit {
    /// The key under `[problem]` (e.g. `body.max_force`), or `start.*`.
    pub key: &'static str,
    /// Smallest value allowed.
    pub min: f64,
    /// Largest value allowed.
    pub max: f64,
    /// The unit ("" for counts and pure numbers).
    pub unit: &'static str,
    /// Why the range is what it is.
    pub reason: &'static str,
}

/// The most steps of a trial (and of a cross-check's sequences).
pub const MAX_STEPS: u64 = 100_000;
/// The most trials of an evaluation, a robustness test or a replay.
pub const MAX_TRIALS: u64 = 1_000_000;

/// Positions and distances (m).
const POSITION: [f64; 2] = [-100.0, 100.0];
const POSITION_WHY: &str = "the PSA flies inside a space station module; the tasks' targets are 0.25-0.55 m away";
/// Headings (rad).
const HEADING: [f64; 2] = [-10.0, 10.0];
const HEADING_WHY: &str = "an angle: more than one and a half turns either way; headings are compared wrapped";
/// Linear speeds (m/s).
const SPEED: [f64; 2] = [-10.0, 10.0];
const SPEED_WHY: &str = "the tasks start at up to 0.4 m/s, the fastest flight mode of NASA's Astrobee; 1 N thrusters on a 3 kg body give 0.7 m/s^2";
/// Angular velocities (rad/s).
const SPIN: [f64; 2] = [-100.0, 100.0];
const SPIN_WHY: &str =
    "the start spins fitted to the paper are 0.75 to 1 rad/s either way; 100 rad/s is 16 turns a second";
/// Input scalings (input units per SI unit) and the bias input.
const SCALE: [f64; 2] = [-1000.0, 1000.0];
const SCALE_WHY: &str =
    "network inputs of O(1) (defaults 0.5-5 per SI unit, the bias 1); far beyond, every input saturates the sigmoid";

const fn row(key: &'static str, range: [f64; 2], unit: &'static str, reason: &'static str) -> Limit {
    Limit {
        key,
        min: range[0],
        max: range[1],
        unit,
        reason,
    }
}

/// Every bounded setting, the ranges of the module doc.
pub const LIMITS: &[Limit] = &[
    row(
        "steps",
        [1.0, MAX_STEPS as f64],
        "",
        "500 in the paper (25 s); 100,000 steps are 83 minutes of flight at 0.05 s",
    ),
    row(
        "trials",
        [1.0, MAX_TRIALS as f64],
        "",
        "1-3 per evaluation and 500 per robustness test in the paper; each trial's fitness is kept",
    ),
    row(
        "body.hull_radius",
        [0.01, 1.0],
        "m",
        "a softball (0.05 m) to a volleyball (0.105 m); 0.10 by default",
    ),
    row("body.hull_height", [0.01, 1.0], "m", "as the hull's radius"),
    row(
        "body.thruster_size",
        [0.001, 0.5],
        "m",
        "each side of a thruster box, 0.02-0.04 m by default",
    ),
    row(
        "body.mount_radius",
        [0.0, 2.0],
        "m",
        "thrusters sit on the hull, 0.12 m from the centre by default",
    ),
    row(
        "body.density",
        [1.0, 25_000.0],
        "kg/m^3",
        "aerogel (a few kg/m^3) to osmium (22,600); 1000 by default",
    ),
    row(
        "body.max_force",
        [1e-4, 100.0],
        "N",
        "the paper's thrusters give 1 N; small fans and cold-gas thrusters 0.01-10 N",
    ),
    row(
        "physics.dt",
        [1e-4, 1.0],
        "s",
        "0.05 s in the paper; a controller stepping slower than once a second cannot fly the PSA, and below 0.1 ms a 25 s trial takes 250,000 steps",
    ),
    row(
        "physics.quick_step_iterations",
        [1.0, 1000.0],
        "",
        "20 by default; each iteration is one more sweep of ODE's QuickStep solver per step",
    ),
    row(
        "physics.rapier_solver_iterations",
        [1.0, 1000.0],
        "",
        "1 by default; each iteration is one more rapier substep per step",
    ),
    row("sensors.position_scale", SCALE, "", SCALE_WHY),
    row("sensors.velocity_scale", SCALE, "", SCALE_WHY),
    row("sensors.heading_scale", SCALE, "", SCALE_WHY),
    row("sensors.angular_velocity_scale", SCALE, "", SCALE_WHY),
    row("sensors.bias", SCALE, "", SCALE_WHY),
    row(
        "noise.input_sd",
        [0.0, 10.0],
        "",
        "0.05 in the paper, on inputs of O(1); 10 drowns every input",
    ),
    row(
        "noise.output_sd",
        [0.0, 10.0],
        "",
        "outputs are clamped to [0, 1]; 10 drowns every output",
    ),
    row("tasks.task1_spin", SPIN, "rad/s", SPIN_WHY),
    row("tasks.task2_target_heading", HEADING, "rad", HEADING_WHY),
    row("tasks.task2_spin", SPIN, "rad/s", SPIN_WHY),
    row("tasks.task2_velocity", SPEED, "m/s", SPEED_WHY),
    row("tasks.task3_speed", SPEED, "m/s", SPEED_WHY),
    row("tasks.task3_distance", POSITION, "m", POSITION_WHY),
    row("tasks.task3_target_heading", HEADING, "rad", HEADING_WHY),
    row("tasks.task3_random_distance", POSITION, "m", POSITION_WHY),
    row("fitness.box_half_width", [0.0, POSITION[1]], "m", POSITION_WHY),
    row(
        "fitness.heading_window",
        [0.0, PI],
        "rad",
        "0.05 in the paper; a window of pi takes in every heading",
    ),
    row("fitness.spin_window", [0.0, SPIN[1]], "rad/s", SPIN_WHY),
    row(
        "fitness.position_points",
        [0.0, 1000.0],
        "",
        "1 and 3 in the paper; fitness is reported in % of the maximum, so only their ratio matters",
    ),
    row(
        "fitness.heading_points",
        [0.0, 1000.0],
        "",
        "1 and 3 in the paper; fitness is reported in % of the maximum, so only their ratio matters",
    ),
    row("start.x", POSITION, "m", POSITION_WHY),
    row("start.y", POSITION, "m", POSITION_WHY),
    row("start.heading", HEADING, "rad", HEADING_WHY),
    row("start.vx", SPEED, "m/s", SPEED_WHY),
    row("start.vy", SPEED, "m/s", SPEED_WHY),
    row("start.omega", SPIN, "rad/s", SPIN_WHY),
];

/// The row of `key`, if there is one.
pub fn limit(key: &str) -> Option<&'static Limit> {
    LIMITS.iter().find(|l| l.key == key)
}

/// A number as the limits' messages show it: plain, or in exponent form
/// when very large or very small.
pub fn show(value: f64) -> String {
    if value == 0.0 || (1e-4..1e9).contains(&value.abs()) || !value.is_finite() {
        format!("{value}")
    } else {
        format!("{value:e}")
    }
}

impl Limit {
    /// Whether `value` is in range (NaN never is).
    pub fn contains(&self, value: f64) -> bool {
        (self.min..=self.max).contains(&value)
    }

    /// Checks `value`, named `shown` in the error (the key, or the
    /// command-line argument it came from).
    pub fn check_as(&self, shown: &str, value: f64) -> Result<(), String> {
        if self.contains(value) {
            return Ok(());
        }
        let unit = if self.unit.is_empty() {
            String::new()
        } else {
            format!(" {}", self.unit)
        };
        Err(format!(
            "{shown} = {} is outside [{}, {}]{unit} ({})",
            show(value),
            show(self.min),
            show(self.max),
            self.reason
        ))
    }
}

/// Checks `value` against the row of `key`, naming it `shown` in the error.
pub fn check_as(key: &str, shown: &str, value: f64) -> Result<(), String> {
    match limit(key) {
        Some(l) => l.check_as(shown, value),
        None => Err(format!(
            "{shown}: no range is defined for key {key:?} (a bug: add it to psa::settings::limits::LIMITS)"
        )),
    }
}

/// Checks every `(key, value)` against its row; the error names the first
/// value out of range by its key.
pub fn check_all(values: &[(&str, f64)]) -> Result<(), String> {
    values.iter().try_for_each(|&(key, value)| check_as(key, key, value))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_unique_and_ranges_ordered() {
        for (i, l) in LIMITS.iter().enumerate() {
            assert!(l.min <= l.max, "{l:?}");
            assert!(LIMITS[..i].iter().all(|o| o.key != l.key), "{} twice", l.key);
        }
    }

    /// The dotted keys of the numbers in `value` (a number or an array of
    /// numbers is one key), under `prefix`.
    fn numeric_keys(value: &serde_json::Value, prefix: &str, keys: &mut Vec<String>) {
        use serde_json::Value;
        match value {
            Value::Number(_) => keys.push(prefix.to_string()),
            Value::Array(items) if items.iter().all(Value::is_number) => keys.push(prefix.to_string()),
            Value::Object(fields) => {
                for (name, field) in fields {
                    let key = if prefix.is_empty() {
                        name.clone()
                    } else {
                        format!("{prefix}.{name}")
                    };
                    numeric_keys(field, &key, keys);
                }
            }
            _ => {}
        }
    }

    /// A numeric setting added to [`PsaSettings`](crate::psa::PsaSettings)
    /// without a row would take any value, NaN included. (The tasks'
    /// `steps`, absent from the defaults, are checked against `steps`.)
    #[test]
    fn every_numeric_setting_has_a_row() {
        let defaults = serde_json::to_value(crate::psa::PsaSettings::default()).unwrap();
        let mut keys = Vec::new();
        numeric_keys(&defaults, "", &mut keys);
        assert!(keys.len() > 30, "{keys:?}");
        let missing: Vec<&String> = keys.iter().filter(|k| limit(k).is_none()).collect();
        assert!(missing.is_empty(), "settings without a row in LIMITS: {missing:?}");
    }

    #[test]
    fn the_documentation_lists_every_key() {
        let doc = include_str!("../../../../docs/limits.md");
        for l in LIMITS {
            assert!(doc.contains(&format!("`{}`", l.key)), "docs/limits.md lacks {}", l.key);
        }
    }

    #[test]
    fn a_value_out_of_range_is_named_with_its_range() {
        assert!(check_as("body.max_force", "body.max_force", 1.0).is_ok());
        let err = check_as("body.max_force", "body.max_force", 1e308).unwrap_err();
        assert_eq!(
            err,
            "body.max_force = 1e308 is outside [0.0001, 100] N (the paper's thrusters give 1 N; small fans and cold-gas thrusters 0.01-10 N)"
        );
        let err = check_as("start.omega", "--start omega", f64::NAN).unwrap_err();
        assert!(
            err.starts_with("--start omega = NaN is outside [-100, 100] rad/s"),
            "{err}"
        );
        let err = check_all(&[("steps", 500.0), ("trials", 0.0)]).unwrap_err();
        assert!(err.starts_with("trials = 0 is outside [1, 1000000]"), "{err}");
        assert!(check_as("no.such.key", "x", 0.0).unwrap_err().contains("no.such.key"));
    }
}
