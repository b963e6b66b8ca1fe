//! `psa-esp sweep`: the replication grid once for each value (or each
//! combination of values) of any settings. Every variant is an ordinary
//! grid folder under `DIR/variants/`, with the variant's settings recorded
//! as its grid's overrides, so it resumes, reports and seeds exactly as a
//! `replicate` grid does (the same seeds in every variant: the variants
//! differ by their settings only).
//!
//! ```text
//! DIR/sweep.json                      the sweep's definition
//! DIR/variants/<variant>/grid.json    an ordinary grid (see `grid`)
//! DIR/variants/<variant>/runs/...
//! ```

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use psa_sim::named::Named;
use serde::{Deserialize, Serialize};

use crate::grid::replicate::{replicate_grids, GridJob, GridProgress, HeldRun, ReplicateOptions};
use crate::grid::shared::{shared_runs, write_shared};
use crate::grid::{GridSpec, RunKey};
use crate::RunConfig;

/// The `format` of `sweep.json`.
pub const SWEEP_FORMAT: &str = "psa-esp-sweep";
/// Its version.
pub const SWEEP_VERSION: u32 = 1;

/// The most variants a sweep may have.
pub const MAX_VARIANTS: usize = 10_000;

/// The longest variant folder name, in bytes: file systems allow 255; the
/// rest is left for the temporary names written beside it.
pub const MAX_VARIANT_NAME: usize = 200;

/// One varied setting: a dotted key of the configuration file and its values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Vary {
    /// The setting, e.g. `esp.stagnation` or `problem.tasks.task3_speed`.
    pub key: String,
    /// Its values, each written as a TOML value (`0.1`, `"phase_best"`, `[0.0, 0.1]`).
    pub values: Vec<String>,
}

/// How the varied settings combine.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Serialize,
    Deserialize,
    strum::VariantArray,
    strum::IntoStaticStr,
    strum::Display,
    strum::EnumString,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "kebab-case", parse_err_ty = String, parse_err_fn = Self::unknown)]
pub enum SweepMode {
    /// Every combination of the values (the Cartesian product).
    Combinations,
    /// One setting at a time, the others at the base; plus the base itself.
    OneAtATime,
}

impl Named for SweepMode {
    const WHAT: &'static str = "sweep mode";
}

/// One variant: its name (its folder) and its settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Variant {
    /// Folder name under `variants/`.
    pub name: String,
    /// (key, TOML value) for every varied setting the variant sets.
    pub settings: Vec<(String, String)>,
}

/// A sweep's definition, written to `sweep.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepSpec {
    /// Always [`SWEEP_FORMAT`].
    pub format: String,
    /// Always [`SWEEP_VERSION`].
    pub version: u32,
    /// The grid every variant runs (its `overrides` is the base configuration file, if any).
    pub grid: GridSpec,
    /// The varied settings.
    pub vary: Vec<Vary>,
    /// How they combine.
    pub mode: SweepMode,
}

/// Splits `KEY=V1,V2,...` into the key and its values; commas inside
/// brackets, braces or quotes belong to the value (`task2_velocity=[0.1,0],[0.2,0]`,
/// `problem.sensors={position_scale=10.0,heading_scale=1.0}`).
pub fn parse_vary(text: &str) -> Result<Vary> {
    let (key, values) = text
        .split_once('=')
        .with_context(|| format!("--vary {text:?}: expected KEY=VALUE,VALUE,..."))?;
    let key = key.trim();
    if key.is_empty() || !key.split('.').all(|part| !part.is_empty()) {
        bail!("--vary {text:?}: {key:?} is not a dotted setting name such as esp.stagnation");
    }
    let mut parts = Vec::new();
    let (mut depth, mut quoted, mut current) = (0i32, false, String::new());
    for c in values.chars() {
        match c {
            '"' => quoted = !quoted,
            '[' | '{' if !quoted => depth += 1,
            ']' | '}' if !quoted => depth -= 1,
            ',' if !quoted && depth == 0 => {
                parts.push(std::mem::take(&mut current));
                continue;
            }
            _ => {}
        }
        current.push(c);
    }
    parts.push(current);
    // One list alone makes as many variants as it has values (in either
    // mode): counted before any value is parsed.
    if parts.len() > MAX_VARIANTS {
        bail!(
            "--vary {key}: {} values make as many variants; at most {MAX_VARIANTS} are allowed",
            parts.len()
        );
    }
    let values: Vec<String> = parts.iter().map(|v| toml_value(v.trim())).collect::<Result<_>>()?;
    if values.iter().any(|v| v.is_empty()) {
        bail!("--vary {text:?}: an empty value");
    }
    // Each value once, in linear time: by its canonical form.
    let mut seen: std::collections::HashMap<String, &String> = std::collections::HashMap::new();
    for value in &values {
        if let Some(earlier) = seen.insert(canonical_value(value), value) {
            if earlier == value {
                bail!("--vary {key}: the value {value} is given twice");
            }
            bail!("--vary {key}: the values {earlier} and {value} are the same value");
        }
    }
    Ok(Vary {
        key: key.to_string(),
        values,
    })
}

/// A TOML value (as [`toml_value`] writes it) in one form per value:
/// `1` and `1.0` are one value (as are `0.0` and `-0.0`), as are arrays
/// of such, so two values are the same value when their forms are equal.
fn canonical_value(text: &str) -> String {
    fn form(value: &toml::Value) -> String {
        use toml::Value::{Array, Float, Integer};
        match value {
            Integer(x) => x.to_string(),
            Float(x) if x.fract() == 0.0 && x.abs() < 9.2e18 => (*x as i64).to_string(),
            Float(x) => format!("{x:?}"),
            Array(items) => format!("[{}]", items.iter().map(form).collect::<Vec<_>>().join(",")),
            other => other.to_string(),
        }
    }
    match format!("v = {text}").parse::<toml::Table>() {
        Ok(mut table) => table.remove("v").map_or_else(|| text.to_string(), |v| form(&v)),
        Err(_) => text.to_string(),
    }
}

/// Refuses varied keys that overlap (`problem.fitness` beside
/// `problem.fitness.scoring`: one would silently win over the other).
fn check_keys(vary: &[Vary]) -> Result<()> {
    for a in vary {
        for b in vary {
            if b.key.len() > a.key.len() && b.key.starts_with(&a.key) && b.key[a.key.len()..].starts_with('.') {
                bail!(
                    "--vary {} and --vary {} overlap: the first sets the table the second is in; vary the settings inside it instead",
                    a.key,
                    b.key
                );
            }
        }
    }
    Ok(())
}

/// The keys a grid sets itself (`--backend`, `--generations`): varied,
/// they become the variant grid's own setting.
const GRID_KEYS: [&str; 3] = ["problem.backend", "esp.generations", "hill_climb.cycles"];

/// `text` as a TOML value: as written when it parses as one (numbers,
/// booleans, arrays, quoted strings), else as a string (`phase_best`).
fn toml_value(text: &str) -> Result<String> {
    if text.is_empty() {
        return Ok(String::new());
    }
    let parsed = format!("v = {text}").parse::<toml::Table>();
    match parsed {
        Ok(table) => Ok(table["v"].to_string()),
        Err(_) if text.chars().all(|c| c.is_ascii_alphanumeric() || "_-.".contains(c)) => {
            Ok(toml::Value::String(text.to_string()).to_string())
        }
        Err(e) => bail!("{text:?} is not a TOML value: {}", e.message()),
    }
}

impl SweepSpec {
    /// A sweep of `grid` over `vary`, checked: distinct keys, every
    /// variant a valid configuration (the error names the variant and key).
    pub fn new(grid: GridSpec, vary: Vec<Vary>, mode: SweepMode) -> Result<SweepSpec> {
        if vary.is_empty() {
            bail!("a sweep needs at least one --vary KEY=VALUES");
        }
        for (i, v) in vary.iter().enumerate() {
            if vary[..i].iter().any(|w| w.key == v.key) {
                bail!("--vary {}: the setting is varied twice", v.key);
            }
        }
        let spec = SweepSpec {
            format: SWEEP_FORMAT.into(),
            version: SWEEP_VERSION,
            grid,
            vary,
            mode,
        };
        spec.check_new()?;
        Ok(spec)
    }

    /// Checks every variant's grid.
    pub fn validate(&self) -> Result<()> {
        // Counted before any is built: four keys of 100 values each are
        // 10^8 variants, which would not fit in memory.
        let count = self.variant_count();
        if count > MAX_VARIANTS as u128 {
            bail!("the sweep has {count} variants; at most {MAX_VARIANTS} are allowed");
        }
        for variant in &self.variants() {
            self.variant_grid(variant)
                .and_then(|grid| grid.validate())
                .with_context(|| format!("variant {}", variant.name))?;
        }
        Ok(())
    }

    /// The checks of a sweep about to be run, beyond [`SweepSpec::validate`]
    /// (which sweeps an earlier build wrote must pass to be read): no
    /// overlapping keys, every variant grid's [`GridSpec::check_new`], and
    /// no two variants that run the same runs.
    pub fn check_new(&self) -> Result<()> {
        self.validate()?;
        check_keys(&self.vary)?;
        let variants = self.variants();
        // Variants that would run the same runs (a setting that does
        // nothing, such as one a configuration overrides) are refused,
        // naming the settings: else they are named as if they differed.
        // One at a time, a value equal to the base's is a row of its own
        // in the sensitivity table (the base's value, named).
        let mut seen: std::collections::HashMap<String, &Variant> = std::collections::HashMap::new();
        let mut base = None;
        for variant in &variants {
            let grid = self
                .variant_grid(variant)
                .and_then(|grid| grid.check_new().map(|_| grid))
                .with_context(|| format!("variant {}", variant.name))?;
            let identity = grid_identity(&grid)?;
            if self.mode == SweepMode::OneAtATime {
                let configs = run_configs(&grid)?;
                if variant.settings.is_empty() {
                    base = Some((identity, configs));
                    continue;
                }
                if let Some((base_identity, base_configs)) = &base {
                    if *base_identity == identity {
                        // The base's own value, named: a row of its own.
                        if *base_configs == configs {
                            continue;
                        }
                        bail!(
                            "variant {} runs the same runs as the base: {} changes nothing in this grid's configurations (no task or algorithm of it reads it)",
                            variant.name,
                            variant
                                .settings
                                .iter()
                                .map(|(k, v)| format!("{k} = {v}"))
                                .collect::<Vec<_>>()
                                .join(", ")
                        );
                    }
                }
            }
            if let Some(other) = seen.get(&identity) {
                let differ: Vec<String> = variant
                    .settings
                    .iter()
                    .filter(|s| !other.settings.contains(s))
                    .map(|(k, v)| format!("{k} = {v}"))
                    .collect();
                bail!(
                    "variants {} and {} run the same runs: {} changes nothing in this grid's configurations",
                    other.name,
                    variant.name,
                    if differ.is_empty() {
                        "the base".to_string()
                    } else {
                        differ.join(", ")
                    }
                );
            }
            seen.insert(identity, variant);
        }
        Ok(())
    }

    /// How many variants the sweep has, counted without building them
    /// (saturating: far above [`MAX_VARIANTS`] is all that matters).
    pub fn variant_count(&self) -> u128 {
        let counts = self.vary.iter().map(|v| v.values.len() as u128);
        match self.mode {
            SweepMode::Combinations => counts.fold(1u128, |a, n| a.saturating_mul(n)),
            SweepMode::OneAtATime => counts.fold(1u128, |a, n| a.saturating_add(n)),
        }
    }

    /// The variants, in a fixed order.
    pub fn variants(&self) -> Vec<Variant> {
        let settings: Vec<Vec<(String, String)>> = match self.mode {
            SweepMode::Combinations => self.vary.iter().fold(vec![Vec::new()], |acc, v| {
                acc.iter()
                    .flat_map(|prefix| {
                        v.values.iter().map(move |value| {
                            let mut s = prefix.clone();
                            s.push((v.key.clone(), value.clone()));
                            s
                        })
                    })
                    .collect()
            }),
            SweepMode::OneAtATime => std::iter::once(Vec::new())
                .chain(
                    self.vary
                        .iter()
                        .flat_map(|v| v.values.iter().map(|value| vec![(v.key.clone(), value.clone())])),
                )
                .collect(),
        };
        let width = settings.len().to_string().len();
        settings
            .into_iter()
            .enumerate()
            .map(|(i, settings)| Variant {
                name: variant_name(i, width, &settings),
                settings,
            })
            .collect()
    }

    /// The grid of `variant`: the sweep's grid with the variant's settings
    /// laid over its base configuration file.
    pub fn variant_grid(&self, variant: &Variant) -> Result<GridSpec> {
        let mut table: toml::Table = match &self.grid.overrides {
            Some(text) => text.parse().context("the base configuration")?,
            None => toml::Table::new(),
        };
        let mut grid = self.grid.clone();
        for (key, value) in &variant.settings {
            if GRID_KEYS.contains(&key.as_str()) {
                set_grid_key(&mut grid, key, value)?;
                continue;
            }
            set_dotted(&mut table, key, value)?;
        }
        // Unknown keys and bad values are named here, before any run.
        RunConfig::baseline_with(&toml::to_string(&table)?).with_context(|| {
            let settings: Vec<String> = variant.settings.iter().map(|(k, v)| format!("{k} = {v}")).collect();
            format!("settings {}", settings.join(", "))
        })?;
        grid.overrides = (!table.is_empty()).then(|| toml::to_string(&table)).transpose()?;
        Ok(grid)
    }

    /// Reads `DIR/sweep.json`, checking its format and version.
    pub fn load(dir: &Path) -> Result<SweepSpec> {
        let path = sweep_file(dir);
        let spec: SweepSpec = psa_sim::io::read_versioned_json(&path, SWEEP_FORMAT, SWEEP_VERSION, "sweep")?;
        spec.validate().with_context(|| format!("{}", path.display()))?;
        Ok(spec)
    }

    /// Writes `DIR/sweep.json` atomically.
    pub fn save(&self, dir: &Path) -> Result<()> {
        psa_sim::io::write_json(&sweep_file(dir), self)
    }
}

/// `DIR/sweep.json`.
pub fn sweep_file(dir: &Path) -> PathBuf {
    dir.join("sweep.json")
}

/// The folder of a variant.
pub fn variant_dir(dir: &Path, variant: &Variant) -> PathBuf {
    dir.join("variants").join(&variant.name)
}

/// `v03-esp.stagnation=40+problem.tasks.task3_speed=0.2`, with characters
/// that do not belong in a folder name replaced by `_`; `v00-base` for none.
fn variant_name(index: usize, width: usize, settings: &[(String, String)]) -> String {
    let body = if settings.is_empty() {
        "base".to_string()
    } else {
        settings
            .iter()
            .map(|(k, v)| format!("{k}={v}"))
            .collect::<Vec<_>>()
            .join("+")
    };
    let clean: String = body
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "._=+-".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    let mut name = format!("v{index:0width$}-{clean}");
    if name.len() > MAX_VARIANT_NAME {
        // The index alone tells variants apart; the settings in the name
        // are for the eye (sweep.json and each grid.json hold them whole).
        let keep = MAX_VARIANT_NAME - "+etc".len();
        name.truncate(keep);
        name.push_str("+etc");
    }
    name
}

/// What a grid runs, in one string: its definition but the overrides,
/// and, for each configuration and task, the settings that task reads.
fn grid_identity(grid: &GridSpec) -> Result<String> {
    let mut identity = serde_json::to_string(&GridSpec {
        overrides: None,
        ..grid.clone()
    })?;
    // Each run judged on the settings its task reads: a variant that
    // changes only task 2's start runs the same runs in a task-1 grid.
    for &config in &grid.configs {
        let run = grid.run_config(config)?;
        for &task in grid.tasks.iter().filter(|&&t| config.applies_to(t)) {
            identity.push_str(&crate::grid::settings_read_by(task, &run)?);
        }
    }
    Ok(identity)
}

/// Every configuration a grid runs, whole, in one string: two grids with
/// the same string set every setting alike.
fn run_configs(grid: &GridSpec) -> Result<String> {
    let mut all = String::new();
    for &config in &grid.configs {
        all.push_str(&serde_json::to_string(&grid.run_config(config)?)?);
    }
    Ok(all)
}

/// Sets one of [`GRID_KEYS`] on the grid itself.
fn set_grid_key(grid: &mut GridSpec, key: &str, value: &str) -> Result<()> {
    let parsed: toml::Table = format!("v = {value}")
        .parse()
        .with_context(|| format!("{key} = {value}"))?;
    let value = parsed["v"].clone();
    if key == "problem.backend" {
        grid.backend = value.try_into().with_context(|| format!("{key}: not a backend"))?;
    } else {
        let generations: usize = value.try_into().with_context(|| format!("{key}: not a count"))?;
        grid.generations = generations;
    }
    Ok(())
}

/// Sets `a.b.c = value` in `table`, creating the tables on the way; a
/// table value is laid over the table there, key by key, as a `--config`
/// file is.
fn set_dotted(table: &mut toml::Table, key: &str, value: &str) -> Result<()> {
    let parsed: toml::Table = format!("v = {value}")
        .parse()
        .with_context(|| format!("{key} = {value}"))?;
    let value = parsed["v"].clone();
    let mut parts: Vec<&str> = key.split('.').collect();
    let last = parts.pop().context("an empty key")?;
    let mut current = table;
    for part in parts {
        let entry = current
            .entry(part.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        current = entry
            .as_table_mut()
            .with_context(|| format!("{key}: {part} is a value, not a table"))?;
    }
    match (current.get_mut(last), value) {
        (Some(toml::Value::Table(existing)), toml::Value::Table(added)) => crate::config::merge(existing, added),
        (_, value) => {
            current.insert(last.to_string(), value);
        }
    }
    Ok(())
}

/// What [`sweep`] did.
#[derive(Debug, Clone)]
pub struct SweepSummary {
    /// Variants.
    pub variants: usize,
    /// Runs a variant shares with an earlier variant (run once, there).
    pub shared: usize,
    /// Shared runs written now from their earlier variant's.
    pub written_from_shared: usize,
    /// Runs over all variants.
    pub total: usize,
    /// Runs already finished.
    pub skipped: usize,
    /// Runs done now.
    pub ran: usize,
    /// Runs other processes were running, left to them (with their variant).
    pub held: Vec<(String, HeldRun)>,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// Runs every variant's grid in `dir` (a new folder gets `sweep.json`; an
/// existing sweep must have the same definition), all variants' runs
/// together ([`replicate_grids`]: in lockstep, one pass for the whole
/// sweep). `options.shard` splits the sweep's whole run order (the
/// variants' run orders one after another), round-robin as a grid's.
pub fn sweep(
    dir: &Path,
    spec: &SweepSpec,
    options: &ReplicateOptions,
    progress: &dyn GridProgress,
) -> Result<SweepSummary> {
    prepare(dir, spec)?;
    let variants = spec.variants();
    let mut grids = Vec::new();
    for variant in &variants {
        let grid = spec
            .variant_grid(variant)
            .with_context(|| format!("variant {}", variant.name))?;
        grids.push((variant_dir(dir, variant), grid));
    }
    // Runs a variant shares with an earlier one run once, there.
    let shared = shared_runs(&grids)?;
    let elsewhere: Vec<Vec<RunKey>> = (0..grids.len())
        .map(|g| shared.iter().filter(|s| s.grid == g).map(|s| s.key).collect())
        .collect();
    let mut before = 0;
    let jobs: Vec<GridJob> = grids
        .iter()
        .zip(&elsewhere)
        .map(|((folder, grid), elsewhere)| {
            let shard = options.shard.after(before);
            before += grid.runs().len();
            GridJob {
                dir: folder,
                spec: grid,
                shard,
                elsewhere,
            }
        })
        .collect();
    // replicate_grids prepares every variant's folder; the shared runs are
    // then written from their sources (those finished before this process too).
    let summaries = replicate_grids(&jobs, options, progress)?;
    let written = write_shared(&grids, &shared, options.claim_timeout)?;
    let seconds = summaries.first().map_or(0.0, |s| s.seconds);
    // Every run of this process's shard, shared or not.
    let mut before = 0;
    let total = grids
        .iter()
        .map(|(_, grid)| {
            let runs = grid.runs();
            let mine = options.shard.after(before).select(&runs).len();
            before += runs.len();
            mine
        })
        .sum();
    let mut summary = SweepSummary {
        variants: variants.len(),
        shared: shared.len(),
        written_from_shared: written,
        total,
        skipped: 0,
        ran: 0,
        held: Vec::new(),
        seconds,
    };
    for (variant, grid) in variants.iter().zip(summaries) {
        summary.skipped += grid.skipped;
        summary.ran += grid.ran;
        summary
            .held
            .extend(grid.held.into_iter().map(|h| (variant.name.clone(), h)));
    }
    Ok(summary)
}

/// Creates `dir` with `sweep.json` (of processes starting together,
/// exactly one writes it), or checks that it holds the same sweep.
fn prepare(dir: &Path, spec: &SweepSpec) -> Result<()> {
    // The folder's contents first: they appear only after its sweep.json.
    if dir.read_dir().is_ok_and(|mut d| d.next().is_some()) && !sweep_file(dir).exists() {
        bail!(
            "{} exists and is not a sweep folder (no sweep.json); use another --out",
            dir.display()
        );
    }
    psa_sim::io::create_output_dir(dir)?;
    psa_sim::io::remove_stale_temporaries(dir);
    let mut json = serde_json::to_string_pretty(spec)?;
    json.push('\n');
    if !sweep_file(dir).exists() && psa_sim::io::create_new_atomic(&sweep_file(dir), json.as_bytes())? {
        return Ok(());
    }
    let existing = SweepSpec::load(dir)?;
    if existing != *spec {
        bail!(
            "{} holds a sweep with another definition; resume it with the same options or use another --out",
            dir.display()
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::GridPreset;

    #[test]
    fn values_split_at_top_level_commas_and_read_as_toml() {
        let v = parse_vary("problem.tasks.task2_velocity=[0.1, 0],[0.2,0]").unwrap();
        assert_eq!(v.values, ["[0.1, 0]", "[0.2, 0]"]);
        let v = parse_vary("esp.stagnation_rule=phase_best,all_time_best").unwrap();
        assert_eq!(v.values, ["\"phase_best\"", "\"all_time_best\""]);
        let v = parse_vary("esp.stagnation=20,40").unwrap();
        assert_eq!(v.values, ["20", "40"]);
        let v = parse_vary("problem.sensors={position_scale=10.0,heading_scale=1.0},{position_scale=5.0}").unwrap();
        assert_eq!(v.values.len(), 2, "{:?}", v.values);
        assert!(v.values[0].contains("heading_scale"));
        assert!(parse_vary("esp.stagnation").is_err());
        assert!(parse_vary("esp.stagnation=20,20").is_err());
        assert!(parse_vary("esp..x=1").is_err());
        assert!(parse_vary("esp.stagnation=20,,40").is_err());
    }

    fn spec(mode: SweepMode) -> Result<SweepSpec> {
        SweepSpec::new(
            GridSpec::from_preset(GridPreset::Quick),
            vec![
                parse_vary("esp.stagnation=20,40")?,
                parse_vary("problem.tasks.task3_speed=0.1,0.2,0.3")?,
            ],
            mode,
        )
    }

    #[test]
    fn combinations_and_one_at_a_time_enumerate_their_variants() {
        let all = spec(SweepMode::Combinations).unwrap().variants();
        assert_eq!(all.len(), 6);
        assert_eq!(all[0].name, "v0-esp.stagnation=20+problem.tasks.task3_speed=0.1");
        assert_eq!(all[5].settings[1], ("problem.tasks.task3_speed".into(), "0.3".into()));
        let one = spec(SweepMode::OneAtATime).unwrap().variants();
        assert_eq!(one.len(), 6, "base, 2 stagnations, 3 speeds");
        assert_eq!(one[0].name, "v0-base");
        assert!(one[1..].iter().all(|v| v.settings.len() == 1));
    }

    #[test]
    fn a_variant_sets_its_values_over_the_base_file() {
        let mut s = spec(SweepMode::Combinations).unwrap();
        s.grid.overrides = Some("[esp]\nsubpop_size = 20\n".into());
        let variants = s.variants();
        let grid = s.variant_grid(&variants[3]).unwrap();
        let config = grid.run_config(crate::GridConfig::InputNoise).unwrap();
        assert_eq!(config.esp.subpop_size, 20);
        assert_eq!(config.esp.stagnation, 40);
        assert_eq!(config.problem.tasks.task3_speed, 0.1);
        assert_eq!(config.problem.noise.input_sd, crate::PAPER_NOISE_SD);
    }

    #[test]
    fn every_reading_of_the_fitness_and_the_inputs_can_be_varied() {
        use psa_sim::psa::{FitnessKind, FitnessState, HeadingInput, HeadingWrap, Scoring, Task};
        let vary = [
            "problem.fitness.kind=incremental,original",
            "problem.fitness.scoring=evolution,original",
            "problem.fitness.state=truth,sensed",
            "problem.sensors.heading_input=error,absolute",
            "problem.sensors.heading_wrap=positive,symmetric",
            "problem.noise.on_bias=false,true",
            "problem.task3.fitness=original",
            "problem.task3.scoring=incremental",
            "problem.task2.steps=2000",
        ];
        let s = SweepSpec::new(
            GridSpec::from_preset(GridPreset::Quick),
            vary.iter().map(|v| parse_vary(v).unwrap()).collect(),
            SweepMode::OneAtATime,
        )
        .unwrap();
        // The base, then the second value of each two-valued setting and the single ones.
        let problem = |i: usize| {
            let variants = s.variants();
            let grid = s.variant_grid(&variants[i]).unwrap();
            grid.run_config(crate::GridConfig::Preset(crate::Preset::Baseline))
                .unwrap()
                .problem
        };
        let variants = s.variants();
        let at = |setting: &str| {
            let (key, value) = setting.split_once('=').unwrap();
            variants
                .iter()
                .position(|v| {
                    v.settings
                        .first()
                        .is_some_and(|(k, v)| k == key && v.trim_matches('"') == value)
                })
                .unwrap_or_else(|| panic!("no variant {setting}"))
        };
        assert_eq!(
            problem(at("problem.fitness.kind=original")).fitness.kind,
            FitnessKind::Original
        );
        assert_eq!(
            problem(at("problem.fitness.scoring=original")).fitness.scoring,
            Scoring::Original
        );
        assert_eq!(
            problem(at("problem.fitness.state=sensed")).fitness.state,
            FitnessState::Sensed
        );
        assert_eq!(
            problem(at("problem.sensors.heading_input=absolute"))
                .sensors
                .heading_input,
            HeadingInput::Absolute
        );
        assert_eq!(
            problem(at("problem.sensors.heading_wrap=symmetric"))
                .sensors
                .heading_wrap,
            HeadingWrap::Symmetric
        );
        assert!(problem(at("problem.noise.on_bias=true")).noise.on_bias);
        let task3 = problem(at("problem.task3.fitness=original"));
        assert_eq!(
            task3.for_task(Task::StopAtPosition).unwrap().fitness.kind,
            FitnessKind::Original
        );
        assert_eq!(
            task3.for_task(Task::Turn).unwrap().fitness.kind,
            FitnessKind::Incremental
        );
        assert!(problem(at("problem.task3.scoring=incremental")).task3.scoring == Some(Scoring::Incremental));
        assert_eq!(
            problem(at("problem.task2.steps=2000"))
                .for_task(Task::Turn)
                .unwrap()
                .steps,
            2000
        );
        assert_eq!(problem(0).fitness.state, FitnessState::default());
    }

    #[test]
    fn a_bad_key_or_value_is_named_before_anything_runs() {
        let grid = GridSpec::from_preset(GridPreset::Quick);
        let e = SweepSpec::new(
            grid.clone(),
            vec![parse_vary("esp.stagnaton=20").unwrap()],
            SweepMode::Combinations,
        )
        .unwrap_err();
        assert!(format!("{e:#}").contains("stagnaton"), "{e:#}");
        let e = SweepSpec::new(
            grid,
            vec![parse_vary("esp.mutation_rate=0.5,2").unwrap()],
            SweepMode::Combinations,
        )
        .unwrap_err();
        assert!(format!("{e:#}").contains("mutation_rate"), "{e:#}");
    }
}
