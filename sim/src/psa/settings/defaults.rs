//! When each default changed: one table, so that a file this tool wrote
//! that lacks a setting (a network file, a run's `config.toml`, written
//! before the setting existed) gets the value the build that wrote it used,
//! not the reading build's default.
//!
//! A key is a dotted path of a run's configuration (`problem.sensors.heading_wrap`,
//! `esp.stagnation`); a network file's `problem` is the `problem.` part.
//! Each key has a row giving the value of the builds before the key
//! existed (`first`), then a row per later change of its default
//! (`changed`), in the order they were made. Rows are only ever appended:
//! every file written from now on records how many rows its build's table
//! had (`defaults` in a network file's provenance and in `run.json`'s
//! `build`), which places it exactly. Files written before that are placed
//! by their git commit in [`BUILDS`], the project's history up to the
//! commit that brought the table in (`git rev-list --parents`).
//!
//! A file lacking a key gets the value of the last row of that key its
//! build had: a `first` row applies to every build, a `changed` row to the
//! builds that had it. A file whose build cannot be placed (no `defaults`,
//! a commit outside [`BUILDS`], no provenance) and that lacks a key whose
//! default ever changed is refused, naming the key.
//!
//! Adding a row, when a default changes or a key is added, is one line at
//! the end of [`CHANGES`]: `first("esp.erase_at", r#""topology_change""#)` for a new
//! key whose absence means the earlier behaviour,
//! `changed("esp.stagnation", "", "60")` for a changed default (the
//! commit is left empty: builds from now on are placed by their row count).

use serde_json::Value;

/// Since when a row holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Since {
    /// Every build before the key existed (and after, until a change).
    First,
    /// The builds that descend from this commit (a prefix of its hash), or
    /// with an empty prefix, the builds whose table has the row.
    Commit(&'static str),
}

/// One row: from `since` on, `key` defaults to `value` (JSON).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Change {
    /// The dotted key of a run's configuration.
    pub key: &'static str,
    /// Since when.
    pub since: Since,
    /// The value, as JSON.
    pub value: &'static str,
}

/// The value `key` had before it existed as a setting.
pub const fn first(key: &'static str, value: &'static str) -> Change {
    Change {
        key,
        since: Since::First,
        value,
    }
}

/// `key`'s default became `value` at `commit` (empty: from the build that
/// adds the row on).
pub const fn changed(key: &'static str, commit: &'static str, value: &'static str) -> Change {
    Change {
        key,
        since: Since::Commit(commit),
        value,
    }
}

/// Every change of a default, oldest first; append only.
pub const CHANGES: &[Change] = &[
    first("problem.exponential", r#""accurate""#),
    changed("problem.exponential", "b450d06", r#""fast""#),
    first("problem.physics.start_quaternion", r#""raw""#),
    changed("problem.physics.start_quaternion", "a1ccaad", r#""normalised""#),
    first("problem.fitness.scoring", r#""evolution""#),
    changed("problem.fitness.scoring", "d497677", r#""original""#),
    first("problem.fitness.state", r#""truth""#),
    changed("problem.fitness.state", "d497677", r#""sensed""#),
    first("problem.sensors.heading_input", r#""error""#),
    first("problem.sensors.heading_wrap", r#""symmetric""#),
    changed("problem.sensors.heading_wrap", "a70d696", r#""positive""#),
    first("problem.noise.on_bias", "false"),
    first("problem.tasks.task1_spin", "1.0"),
    changed("problem.tasks.task1_spin", "e34b1bb", "2.0"),
    changed("problem.tasks.task1_spin", "d497677", "1.0"),
    first("problem.tasks.task2_spin", "0.0"),
    changed("problem.tasks.task2_spin", "95ee59b", "1.0"),
    changed("problem.tasks.task2_spin", "b5269e4", "1.25"),
    changed("problem.tasks.task2_spin", "72d28cb", "0.75"),
    first("problem.tasks.task2_velocity", "[0.0, 0.0]"),
    first("problem.tasks.task3_speed", "0.1"),
    changed("problem.tasks.task3_speed", "95ee59b", "0.3"),
    changed("problem.tasks.task3_speed", "72d28cb", "0.4"),
    first("problem.tasks.task3_target_heading", "3.141592653589793"),
    changed("problem.tasks.task3_target_heading", "95ee59b", "0.0"),
    first("esp.stagnation", "20"),
    changed("esp.stagnation", "95ee59b", "40"),
    changed("esp.stagnation", "a70d696", "50"),
    first("esp.stagnation_rule", r#""all_time_best""#),
    changed("esp.stagnation_rule", "95ee59b", r#""phase_best""#),
    first("esp.erase_at", r#""topology_change""#),
    changed("esp.erase_at", "8cf59c9", r#""burst""#),
    first("esp.relesion", r#""pending""#),
    changed("problem.tasks.task2_spin", "", "1.0"),
    first("hill_climb.alpha", "1.0"),
    changed("hill_climb.alpha", "", "0.3"),
    changed("problem.tasks.task2_spin", "", "-1.5"),
    first("problem.noise.stage", r#""scaled""#),
    changed("problem.tasks.task2_spin", "", "-0.75"),
    first("problem.sensors.position_scale", "10.0"),
    changed("problem.sensors.position_scale", "", "5.0"),
    first("problem.sensors.velocity_scale", "10.0"),
    changed("problem.sensors.velocity_scale", "", "5.0"),
    first("problem.sensors.heading_scale", "1.0"),
    changed("problem.sensors.heading_scale", "", "0.5"),
    first("problem.sensors.angular_velocity_scale", "1.0"),
    changed("problem.sensors.angular_velocity_scale", "", "0.5"),
    changed("problem.noise.on_bias", "", "true"),
    changed("problem.sensors.heading_wrap", "", r#""symmetric""#),
    changed("problem.sensors.heading_input", "", r#""absolute""#),
    changed("problem.sensors.position_scale", "", "10.0"),
    changed("problem.sensors.velocity_scale", "", "10.0"),
    changed("problem.sensors.heading_scale", "", "1.0"),
    changed("problem.sensors.angular_velocity_scale", "", "1.0"),
];

/// How many rows this build's table has: recorded in every file it writes.
pub fn rows() -> usize {
    CHANGES.len()
}

/// The project's history up to the commit that brought the table in: each
/// line a commit and its parents (`git rev-list --parents HEAD`).
pub const BUILDS: &str = include_str!("builds.txt");

/// Where a file's build stands in the table.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Placement {
    /// Its build's table had this many rows.
    Rows(usize),
    /// Its build is this commit of [`BUILDS`] (a full hash).
    Commit(String),
    /// It cannot be placed; the text says why.
    Unknown(String),
}

impl Placement {
    /// The placement of a file whose provenance records `defaults` (rows)
    /// and `git_commit` (a `-dirty` build is placed as its commit).
    pub fn of(defaults: Option<u64>, git_commit: Option<&str>) -> Placement {
        if let Some(rows) = defaults {
            return Placement::Rows(rows as usize);
        }
        let Some(commit) = git_commit else {
            return Placement::Unknown("it records no build".into());
        };
        let bare = commit.trim_end_matches("-dirty");
        if bare.len() >= 7 && BUILDS.lines().any(|line| line.starts_with(bare)) {
            let full = BUILDS
                .lines()
                .find(|line| line.starts_with(bare))
                .and_then(|line| line.split(' ').next())
                .unwrap_or(bare);
            Placement::Commit(full.to_string())
        } else {
            Placement::Unknown(format!(
                "its build (commit {commit}) is not in this build's history of defaults"
            ))
        }
    }

    /// The builds just before `commit` (a prefix of a commit of [`BUILDS`]):
    /// its first parent. `None` when [`BUILDS`] has no such commit.
    pub fn before_commit(commit: &str) -> Option<Placement> {
        let line = BUILDS.lines().find(|line| line.starts_with(commit))?;
        Some(Placement::Commit(line.split(' ').nth(1)?.to_string()))
    }

    /// The builds just before the row that set `key` to `value` (JSON), the
    /// last such row: a table of that many rows. `None` when no row does.
    pub fn before_row(key: &str, value: &str) -> Option<Placement> {
        CHANGES
            .iter()
            .rposition(|row| row.key == key && row.value == value)
            .map(Placement::Rows)
    }

    /// The placement of a file whose provenance is the JSON object `provenance`.
    /// A file without one says so: its provenance is missing.
    pub fn of_json(provenance: Option<&serde_json::Map<String, Value>>) -> Placement {
        if provenance.is_none() {
            return Placement::Unknown("the file has no \"provenance\", which names the build that wrote it".into());
        }
        let defaults = provenance.and_then(|p| p.get("defaults")).and_then(Value::as_u64);
        let commit = provenance.and_then(|p| p.get("git_commit")).and_then(Value::as_str);
        Placement::of(defaults, commit)
    }

    /// Whether the row at `index` of [`CHANGES`] holds for this build
    /// (`None`: cannot be told).
    fn has(&self, index: usize) -> Option<bool> {
        let row = &CHANGES[index];
        match (row.since, self) {
            (Since::First, _) => Some(true),
            (_, Placement::Rows(rows)) => Some(index < *rows),
            (Since::Commit(""), Placement::Commit(_)) => Some(false),
            (Since::Commit(prefix), Placement::Commit(build)) => Some(descends(build, prefix)),
            (_, Placement::Unknown(_)) => None,
        }
    }
}

/// Whether `build` (a full hash in [`BUILDS`]) is the commit `prefix` or
/// descends from it.
fn descends(build: &str, prefix: &str) -> bool {
    let parents = |commit: &str| -> Vec<&'static str> {
        BUILDS
            .lines()
            .find(|line| line.starts_with(commit))
            .map(|line| line.split(' ').skip(1).collect())
            .unwrap_or_default()
    };
    let mut seen = std::collections::HashSet::new();
    let mut stack = vec![build.to_string()];
    while let Some(commit) = stack.pop() {
        if commit.starts_with(prefix) {
            return true;
        }
        if seen.insert(commit.clone()) {
            stack.extend(parents(&commit).into_iter().map(String::from));
        }
    }
    false
}

/// The value the build at `placement` used for `key`: `Ok(None)` when the
/// table has no row for it (its default never changed: every build's holds),
/// an error naming the key when the build cannot be placed.
pub fn value_at(key: &str, placement: &Placement) -> Result<Option<Value>, String> {
    let rows: Vec<usize> = (0..CHANGES.len()).filter(|&i| CHANGES[i].key == key).collect();
    if rows.is_empty() {
        return Ok(None);
    }
    let mut value = None;
    for &i in &rows {
        match placement.has(i) {
            Some(true) => value = Some(i),
            Some(false) => {}
            None if rows.len() == 1 => value = Some(i),
            None => {
                let why = match placement {
                    Placement::Unknown(why) => why.as_str(),
                    _ => "",
                };
                return Err(format!(
                    "{key} is missing and its default has changed; {why}, so the value it was written with is not known (add {key} to the file)"
                ));
            }
        }
    }
    Ok(value.map(|i| serde_json::from_str(CHANGES[i].value).expect("the table's values are JSON")))
}

/// Fills in `doc` (a JSON object laid out as a run's configuration, or
/// its part under `prefix`: `"problem."` for a network file's `problem`)
/// every key of the table it lacks, with the value the build at
/// `placement` used. Keys whose table (`problem.fitness`) is itself
/// missing are left alone. The error names the first key that cannot be
/// filled.
pub fn fill(doc: &mut Value, prefix: &str, placement: &Placement) -> Result<(), String> {
    let mut done = std::collections::HashSet::new();
    for row in CHANGES {
        let Some(path) = row.key.strip_prefix(prefix) else {
            continue;
        };
        if !done.insert(row.key) {
            continue;
        }
        let mut parts: Vec<&str> = path.split('.').collect();
        let last = parts.pop().expect("keys are not empty");
        let mut table = &mut *doc;
        let mut found = true;
        for part in parts {
            if !table.get(part).is_some_and(Value::is_object) {
                found = false;
                break;
            }
            table = table.get_mut(part).expect("checked just above");
        }
        let Some(object) = table.as_object_mut().filter(|_| found) else {
            continue;
        };
        if object.contains_key(last) {
            continue;
        }
        if let Some(value) = value_at(row.key, placement)? {
            object.insert(last.to_string(), value);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_commit_of_the_table_is_in_the_history_and_values_are_json() {
        for row in CHANGES {
            serde_json::from_str::<Value>(row.value).unwrap_or_else(|e| panic!("{}: {e}", row.key));
            if let Since::Commit(prefix) = row.since {
                assert!(
                    prefix.is_empty() || BUILDS.lines().any(|l| l.starts_with(prefix)),
                    "{}: {prefix} is not in builds.txt",
                    row.key
                );
            }
        }
        for (i, row) in CHANGES.iter().enumerate() {
            if row.since != Since::First {
                assert!(
                    CHANGES[..i].iter().any(|r| r.key == row.key && r.since == Since::First),
                    "{}: a change before its first row",
                    row.key
                );
            }
        }
    }

    #[test]
    fn a_build_gets_the_default_of_its_time_and_an_unknown_one_is_refused() {
        let at = |commit: &str| Placement::of(None, Some(commit));
        let wrap = "problem.sensors.heading_wrap";
        // Before the setting (and its change), at the change, and a dirty build after it.
        assert_eq!(value_at(wrap, &at("95ee59b")).unwrap(), Some("symmetric".into()));
        assert_eq!(value_at(wrap, &at("a70d696")).unwrap(), Some("positive".into()));
        let head = BUILDS.lines().next().unwrap().split(' ').next().unwrap();
        assert_eq!(
            value_at(wrap, &at(&format!("{head}-dirty"))).unwrap(),
            Some("positive".into())
        );
        // Back to (-pi, pi] by a later row.
        let back = CHANGES.iter().rposition(|row| row.key == wrap).unwrap();
        assert_eq!(value_at(wrap, &Placement::Rows(back)).unwrap(), Some("positive".into()));
        assert_eq!(
            value_at(wrap, &Placement::Rows(back + 1)).unwrap(),
            Some("symmetric".into())
        );
        assert_eq!(value_at(wrap, &Placement::Rows(10)).unwrap(), Some("symmetric".into()));
        let err = value_at(wrap, &at("0123456789abcdef")).unwrap_err();
        assert!(err.contains(wrap) && err.contains("0123456789abcdef"), "{err}");
        // A key whose default never changed needs no placement.
        assert_eq!(
            value_at("problem.tasks.task2_velocity", &at("unknown")).unwrap(),
            Some(serde_json::json!([0.0, 0.0]))
        );
        assert_eq!(value_at("problem.steps", &at("unknown")).unwrap(), None);
    }
}
