//! The model's readings of the paper's text, declared once: each a setting
//! that picks between readings the text allows, with its key, its doc, its
//! tag, the `trial.cu` define that compiles it into the cuda kernel, how
//! reports name it and a value other than its default for the tests.
//! [`PsaSettings::describe_readings`], the kernel's
//! [`Specialisation`](crate::psa::cuda::Specialisation) and the tests'
//! settings under every reading iterate [`READINGS`]; a test holds
//! `docs/specification.md`'s table of readings to it, and another fails on
//! a discrete setting that is neither a row nor named as no reading.
//!
//! Adding a reading: its setting and its arithmetic (`fitness.rs`,
//! `sensors.rs`, and `trial.cu` where the kernel compiles it in), a row
//! here, and a row in the specification's table.

use std::fmt;
use strum::VariantArray;

use super::PsaSettings;
use crate::psa::fitness::{FitnessKind, FitnessState, Scoring, SlowingRule};
use crate::psa::sensors::{HeadingInput, HeadingWrap, NoiseStage};
use crate::psa::task::Task;

/// Where a reading's default comes from (`docs/specification.md`'s tags).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tag {
    /// What the paper says.
    Paper,
    /// Our choice where the paper is silent.
    Chosen,
    /// Fitted to the paper's tables (docs/model.md).
    Fitted,
}

impl fmt::Display for Tag {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Tag::Paper => "[paper]",
            Tag::Chosen => "[chosen]",
            Tag::Fitted => "[fitted]",
        })
    }
}

/// How a report names a reading ([`PsaSettings::describe_readings`]).
#[derive(Clone, Copy)]
pub enum Describe {
    /// Its lines: of the settings a grid evolved with, and those its
    /// champions are scored with, on the tasks the grid runs.
    Lines(fn(&PsaSettings, &PsaSettings, &[Task]) -> Vec<String>),
    /// Named in the lines of the row with this key.
    With(&'static str),
}

/// A `trial.cu` define that compiles a reading into the cuda kernel: `-DNAME=1`
/// where `on` holds for the settings a trial flies (a task's overrides in
/// place), else `-DNAME=0`.
#[derive(Clone, Copy)]
pub struct Define {
    /// The define's name.
    pub name: &'static str,
    /// Whether it is 1 for the settings.
    pub on: fn(&PsaSettings) -> bool,
}

/// One reading of the paper's text: a row of [`READINGS`].
#[derive(Clone, Copy)]
pub struct Reading {
    /// The setting's key under `[problem]` (`fitness.state`); a reading a
    /// task may override has the same key under `problem.taskN` without
    /// its section (`task3.fitness` for `fitness.kind`, [`Reading::task_key`]).
    pub key: &'static str,
    /// What it reads, as the specification's table says it.
    pub doc: &'static str,
    /// Where its default comes from.
    pub tag: Tag,
    /// The `trial.cu` define that compiles it into the cuda kernel (`None`
    /// where the kernel reads it at run time or not at all).
    pub define: Option<Define>,
    /// Its key under `problem.taskN` where a task may override it.
    pub task_key: Option<&'static str>,
    /// How a report names it.
    pub describe: Describe,
    /// Sets a value other than the default: through task 3's or task 1's
    /// override where the reading has one.
    pub set_test_value: fn(&mut PsaSettings),
}

impl fmt::Debug for Reading {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Reading")
            .field("key", &self.key)
            .field("tag", &self.tag)
            .finish()
    }
}

/// The name of a fitness function in a report.
fn fitness_name(kind: FitnessKind) -> &'static str {
    match kind {
        FitnessKind::Incremental => "incremental",
        FitnessKind::Original => "original",
    }
}

/// Each task's line, of the tasks run: the fitness it evolves on, over
/// how many steps, and the one its champions are scored on.
fn describe_tasks(evolved: &PsaSettings, scoring: &PsaSettings, tasks: &[Task]) -> Vec<String> {
    Task::VARIANTS
        .iter()
        .filter(|task| tasks.contains(task))
        .filter_map(|&task| {
            let s = evolved.for_task(task).ok()?;
            let scored = scoring.scoring_for(task).ok()?;
            Some(format!(
                "task {task}: evolved on the {} fitness over {} steps, scored on the {}",
                fitness_name(s.fitness.kind),
                s.steps,
                fitness_name(scored.fitness.kind)
            ))
        })
        .collect()
}

/// The heading input's line: what it measures and its range.
fn describe_heading(evolved: &PsaSettings, _: &PsaSettings, _: &[Task]) -> Vec<String> {
    let heading = match evolved.sensors.heading_input {
        HeadingInput::Error => "the heading error",
        HeadingInput::Absolute => "the absolute heading",
    };
    let range = match evolved.sensors.heading_wrap {
        HeadingWrap::Symmetric => "(-pi, pi]",
        HeadingWrap::Positive => "[0, 2 pi)",
    };
    vec![format!("heading input: {heading} in {range}")]
}

/// Every reading, in the order reports name them and the kernel's defines
/// are passed.
pub const READINGS: &[Reading] = &[
    Reading {
        key: "fitness.kind",
        doc: "the fitness evolution maximises: `incremental` (Høverstad's) or `original` (Sit's)",
        tag: Tag::Paper,
        define: Some(Define {
            name: "PSA_INCREMENTAL",
            on: |s| s.fitness.kind == FitnessKind::Incremental,
        }),
        task_key: Some("fitness"),
        describe: Describe::Lines(describe_tasks),
        set_test_value: |s| s.task3.fitness = Some(FitnessKind::Original),
    },
    Reading {
        key: "fitness.slowing",
        doc:
            "what counts as the spin slowing down: `magnitude` (its magnitude falls) or `signed` (the printed formula)",
        tag: Tag::Chosen,
        define: Some(Define {
            name: "PSA_SIGNED_SLOWING",
            on: |s| s.fitness.slowing == SlowingRule::Signed,
        }),
        task_key: None,
        describe: Describe::Lines(|s, _, _| match s.fitness.slowing {
            // Named only where it is not the default, as reports did before it was a row.
            SlowingRule::Magnitude => Vec::new(),
            SlowingRule::Signed => vec!["the spin slows when its signed value falls".into()],
        }),
        set_test_value: |s| s.fitness.slowing = SlowingRule::Signed,
    },
    Reading {
        key: "sensors.heading_input",
        doc: "the heading input: `error` (the heading minus the target's) or `absolute` (the heading itself)",
        tag: Tag::Chosen,
        define: Some(Define {
            name: "PSA_HEADING_ABSOLUTE",
            on: |s| s.sensors.heading_input == HeadingInput::Absolute,
        }),
        task_key: None,
        describe: Describe::Lines(describe_heading),
        set_test_value: |s| s.sensors.heading_input = HeadingInput::Error,
    },
    Reading {
        key: "sensors.heading_wrap",
        doc: "the heading input's range: `symmetric`, (-pi, pi], or `positive`, [0, 2 pi)",
        tag: Tag::Chosen,
        define: Some(Define {
            name: "PSA_HEADING_POSITIVE",
            on: |s| s.sensors.heading_wrap == HeadingWrap::Positive,
        }),
        task_key: None,
        describe: Describe::With("sensors.heading_input"),
        set_test_value: |s| s.sensors.heading_wrap = HeadingWrap::Positive,
    },
    Reading {
        key: "noise.on_bias",
        doc: "whether the input noise reaches the bias unit too (one of the seven input units)",
        tag: Tag::Paper,
        define: Some(Define {
            name: "PSA_BIAS_NOISE",
            on: |s| s.noise.on_bias,
        }),
        task_key: None,
        describe: Describe::Lines(|s, _, _| {
            vec![format!(
                "input noise on the bias: {}",
                if s.noise.on_bias { "yes" } else { "no" }
            )]
        }),
        set_test_value: |s| s.noise.on_bias = false,
    },
    Reading {
        key: "noise.stage",
        doc: "where the input noise enters: `scaled` (on the inputs, in input units) or `raw` (on what the sensors measure, before scaling)",
        tag: Tag::Chosen,
        define: Some(Define {
            name: "PSA_NOISE_RAW",
            on: |s| s.noise.stage == NoiseStage::Raw,
        }),
        task_key: None,
        describe: Describe::Lines(|s, _, _| {
            vec![format!(
                "input noise: {}",
                match s.noise.stage {
                    NoiseStage::Scaled => "on the scaled inputs",
                    NoiseStage::Raw => "on what the sensors measure, before scaling",
                }
            )]
        }),
        set_test_value: |s| s.noise.stage = NoiseStage::Raw,
    },
    Reading {
        key: "fitness.state",
        doc: "the state the fitness reads: `truth` or `sensed` (the inputs, noise included, over their scales)",
        tag: Tag::Fitted,
        define: Some(Define {
            name: "PSA_FITNESS_SENSED",
            on: |s| s.fitness.state == FitnessState::Sensed,
        }),
        task_key: None,
        describe: Describe::Lines(|s, _, _| {
            vec![format!(
                "the fitness reads the {} state",
                match s.fitness.state {
                    FitnessState::True => "true",
                    FitnessState::Sensed => "sensed",
                }
            )]
        }),
        set_test_value: |s| s.fitness.state = FitnessState::True,
    },
    Reading {
        key: "steps",
        doc: "a trial's length in steps",
        tag: Tag::Chosen,
        define: None,
        task_key: Some("steps"),
        describe: Describe::With("fitness.kind"),
        set_test_value: |s| s.task3.steps = Some(250),
    },
    Reading {
        key: "fitness.scoring",
        doc: "the fitness champions are scored with (Tables 1-7): `evolution`, `incremental` or `original`",
        tag: Tag::Fitted,
        define: None,
        task_key: Some("scoring"),
        describe: Describe::With("fitness.kind"),
        set_test_value: |s| s.task1.scoring = Some(Scoring::Incremental),
    },
];

/// The row of `key`, if it is a reading.
pub fn reading(key: &str) -> Option<&'static Reading> {
    READINGS.iter().find(|r| r.key == key)
}

/// `settings` under every reading's test value at once.
pub fn every_test_value(mut settings: PsaSettings) -> PsaSettings {
    for row in READINGS {
        (row.set_test_value)(&mut settings);
    }
    settings
}

impl PsaSettings {
    /// The readings of the inputs and the fitness these settings fly, in
    /// words, for reports: the lines of every row of [`READINGS`] in order
    /// (per task of `tasks` the fitness evolved on, the trial's length and the fitness
    /// champions are scored on under `scoring`, these settings or the ones
    /// a re-scored grid tests with; the heading input; the noise on the
    /// bias; the state the fitness reads).
    pub fn describe_readings(&self, scoring: &PsaSettings, tasks: &[Task]) -> Vec<String> {
        READINGS
            .iter()
            .flat_map(|row| match row.describe {
                Describe::Lines(lines) => lines(self, scoring, tasks),
                Describe::With(_) => Vec::new(),
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeSet;

    use super::*;
    use crate::psa::cuda::KERNEL_SOURCE;
    use crate::psa::TaskOverrides;

    /// The discrete settings (a string or a boolean in a configuration
    /// file) that are no reading of the text, each with why.
    const NOT_READINGS: &[(&str, &str)] = &[
        ("backend", "the physics engine: every backend flies the same model"),
        ("random_init", "Table 3's random starts, a configuration of the paper's"),
        ("exponential", "the logistic units' polynomial, an arithmetic choice"),
        ("physics.stepper", "ODE's stepper, a choice of the engine"),
        ("physics.plane_constraint", "ODE's plane joint, a choice of the engine"),
        (
            "physics.ode_gyroscopic",
            "ODE's gyroscopic term, a choice of the engine",
        ),
        (
            "physics.start_quaternion",
            "how the start quaternion is set, a definition",
        ),
    ];

    /// Every leaf of `value` that is a string or a boolean, by its dotted key.
    fn discrete_leaves(prefix: &str, value: &serde_json::Value, out: &mut BTreeSet<String>) {
        match value {
            serde_json::Value::Object(map) => {
                for (k, v) in map {
                    let key = if prefix.is_empty() {
                        k.clone()
                    } else {
                        format!("{prefix}.{k}")
                    };
                    discrete_leaves(&key, v, out);
                }
            }
            serde_json::Value::String(_) | serde_json::Value::Bool(_) => {
                out.insert(prefix.to_string());
            }
            _ => {}
        }
    }

    #[test]
    fn every_discrete_setting_is_a_reading_or_named_as_none() {
        let mut leaves = BTreeSet::new();
        discrete_leaves("", &serde_json::to_value(PsaSettings::default()).unwrap(), &mut leaves);
        let readings: BTreeSet<String> = READINGS.iter().map(|r| r.key.to_string()).collect();
        let named: BTreeSet<String> = NOT_READINGS.iter().map(|(k, _)| k.to_string()).collect();
        let forgotten: Vec<&String> = leaves
            .iter()
            .filter(|k| !readings.contains(*k) && !named.contains(*k))
            .collect();
        assert!(
            forgotten.is_empty(),
            "settings neither a row of READINGS nor in NOT_READINGS: {forgotten:?}"
        );
        let stale: Vec<&String> = named.iter().filter(|k| !leaves.contains(*k)).collect();
        assert!(
            stale.is_empty(),
            "NOT_READINGS names settings that do not exist: {stale:?}"
        );
    }

    #[test]
    fn every_task_override_is_a_reading_s() {
        let all = TaskOverrides {
            steps: Some(1),
            fitness: Some(FitnessKind::Original),
            scoring: Some(Scoring::Original),
        };
        let serde_json::Value::Object(fields) = serde_json::to_value(all).unwrap() else {
            panic!("overrides are a table")
        };
        let overrides: BTreeSet<&str> = fields.keys().map(String::as_str).collect();
        let rows: BTreeSet<&str> = READINGS.iter().filter_map(|r| r.task_key).collect();
        assert_eq!(overrides, rows, "TaskOverrides' fields against the rows' task keys");
    }

    #[test]
    fn every_row_s_test_value_is_not_the_default_and_shows() {
        let default = PsaSettings::default();
        let resolved = |s: &PsaSettings| {
            Task::VARIANTS
                .iter()
                .map(|&t| s.for_task(t).unwrap())
                .collect::<Vec<_>>()
        };
        for row in READINGS {
            let mut s = PsaSettings::default();
            (row.set_test_value)(&mut s);
            assert_ne!(s, default, "{}", row.key);
            assert_ne!(
                s.describe_readings(&s, Task::VARIANTS),
                default.describe_readings(&default, Task::VARIANTS),
                "{} does not show in the report's readings",
                row.key
            );
            if let Some(define) = row.define {
                let on = define.on;
                let flips = resolved(&s)
                    .iter()
                    .zip(resolved(&default))
                    .any(|(a, b)| on(a) != on(&b));
                assert!(flips, "{}'s test value leaves {} as it was", row.key, define.name);
            }
        }
    }

    #[test]
    fn keys_and_defines_are_unique_and_shared_lines_have_an_owner() {
        let keys: BTreeSet<&str> = READINGS.iter().map(|r| r.key).collect();
        assert_eq!(keys.len(), READINGS.len());
        let defines: Vec<&str> = READINGS.iter().filter_map(|r| r.define.map(|d| d.name)).collect();
        assert_eq!(defines.iter().collect::<BTreeSet<_>>().len(), defines.len());
        for row in READINGS {
            if let Describe::With(owner) = row.describe {
                let owner = reading(owner).unwrap_or_else(|| panic!("{} is named with no row", row.key));
                assert!(matches!(owner.describe, Describe::Lines(_)), "{}", row.key);
            }
        }
    }

    #[test]
    fn the_kernel_s_defines_are_the_readings_and_its_shape() {
        const SHAPE: &[&str] = &[
            "PSA_HIDDEN",
            "PSA_NOISY",
            "PSA_FORCE_SUPPORT",
            "PSA_ARM_SUPPORT",
            "PSA_EXP_TERMS",
            "PSA_EXP_Q",
            "PSA_LN2_TERMS",
            "PSA_LN2_PARTS",
        ];
        let guard = KERNEL_SOURCE
            .split("#if !defined(")
            .nth(1)
            .and_then(|rest| rest.split("#error").next())
            .expect("trial.cu checks its defines");
        let required: BTreeSet<&str> = guard
            .split("defined(")
            .map(|part| part.split(')').next().unwrap_or(""))
            .chain(guard.split(')').next())
            .map(str::trim)
            .filter(|name| name.starts_with("PSA_"))
            .collect();
        let ours: BTreeSet<&str> = READINGS
            .iter()
            .filter_map(|r| r.define.map(|d| d.name))
            .chain(SHAPE.iter().copied())
            .collect();
        assert_eq!(
            required, ours,
            "trial.cu's required defines against READINGS and the shape"
        );
    }

    #[test]
    fn the_specification_s_table_of_readings_is_the_table() {
        let spec = include_str!("../../../../docs/specification.md");
        let table = spec
            .split("<!-- readings: the rows of psa::settings::readings::READINGS -->")
            .nth(1)
            .expect("the specification has the table of readings");
        let rows: Vec<String> = table
            .lines()
            .skip_while(|l| !l.starts_with('|'))
            .take_while(|l| l.starts_with('|'))
            .skip(2)
            .map(str::to_string)
            .collect();
        let expected: Vec<String> = READINGS
            .iter()
            .map(|r| {
                let task = r.task_key.map_or("–".to_string(), |k| format!("`taskN.{k}`"));
                let define = r.define.map_or("–".to_string(), |d| format!("`{}`", d.name));
                format!("| `{}` | {task} | {} | {} | {define} |", r.key, r.tag, r.doc)
            })
            .collect();
        assert_eq!(
            rows, expected,
            "docs/specification.md's table of readings against READINGS"
        );
    }
}
