//! A file that lacks a setting gets the value of the build that wrote it.

use super::*;
use psa_sim::psa::settings::defaults::Since;

/// `json` as a file of the build `commit` that knew none of the table's
/// keys: each taken out of its problem.
fn as_file_of(json: &mut serde_json::Value, commit: &str) {
    let provenance = json["provenance"].as_object_mut().unwrap();
    provenance.remove("defaults");
    provenance.insert("git_commit".into(), commit.into());
    for row in CHANGES {
        // The input scaling is the problem's sensors, as old as they are.
        if let Some(key) = row.key.strip_prefix("problem.sensors.") {
            json["input_scaling"].as_object_mut().unwrap().remove(key);
        }
        if let Some(path) = row.key.strip_prefix("problem.") {
            let mut parts: Vec<&str> = path.split('.').collect();
            let last = parts.pop().unwrap();
            let mut at = &mut json["problem"];
            for part in parts {
                at = &mut at[part];
            }
            if let Some(object) = at.as_object_mut() {
                object.remove(last);
            }
        }
    }
}

#[test]
fn a_network_file_from_before_a_setting_loads_with_the_value_its_build_used() {
    let dir = tempfile::tempdir().unwrap();
    // Written before the readings of the fitness were settings (d8e86a8).
    let mut old = network_json(&PsaSettings::default());
    as_file_of(&mut old, &parent_of("d8e86a8"));
    let problem = load_json(dir.path(), &old).unwrap();
    assert_eq!(problem.sensors.heading_wrap, HeadingWrap::Symmetric);
    assert_eq!(problem.fitness.scoring, Scoring::Evolution);
    assert_eq!(problem.fitness.state, FitnessState::True);
    assert_eq!(problem.physics.start_quaternion, StartQuaternion::Raw);
    assert_eq!(problem.tasks.task1_spin, 2.0);
    // A dirty build of the same commit likewise.
    let mut dirty = old.clone();
    dirty["provenance"]["git_commit"] = format!("{}-dirty", parent_of("d8e86a8")).into();
    assert_eq!(load_json(dir.path(), &dirty).unwrap(), problem);
    // A build that cannot be placed is refused, naming the key.
    let mut unknown = old.clone();
    unknown["provenance"]["git_commit"] = "0123456789abcdef0123456789abcdef01234567".into();
    let err = load_json(dir.path(), &unknown).unwrap_err();
    assert!(err.contains("problem.") && err.contains("0123456789abcdef"), "{err}");
    // Today's files name every setting and load as written.
    let new = network_json(&PsaSettings::default());
    assert_eq!(load_json(dir.path(), &new).unwrap(), PsaSettings::default());
}

/// Where an earlier model stands in the table of defaults.
enum Build {
    /// The defaults of the builds before this commit (its parent's).
    Before(&'static str),
    /// The defaults of the builds before the table's row that set `key` to
    /// `value` (rows added after the table came in name no commit).
    BeforeRow(&'static str, &'static str),
}

impl Build {
    fn placement(&self) -> Placement {
        match *self {
            Build::Before(commit) => Placement::of(None, Some(&parent_of(commit))),
            Build::BeforeRow(key, value) => {
                let row = CHANGES
                    .iter()
                    .rposition(|row| row.key == key && row.value == value)
                    .unwrap_or_else(|| panic!("no row sets {key} to {value}"));
                Placement::Rows(row)
            }
        }
    }
}

/// Every earlier model under `configs/` and the builds that had it as
/// their defaults.
const MODELS: [(&str, Build); 9] = [
    ("previous-defaults.toml", Build::Before("95ee59b")),
    ("fitted-incremental.toml", Build::Before("d497677")),
    ("scored-on-original.toml", Build::Before("a1ccaad")),
    ("symmetric-heading.toml", Build::Before("a70d696")),
    ("positive-heading.toml", Build::Before("8cf59c9")),
    (
        "task2-towards-target.toml",
        Build::BeforeRow("problem.tasks.task2_spin", "-1.5"),
    ),
    (
        "clockwise-start.toml",
        Build::BeforeRow("problem.tasks.task2_spin", "-0.75"),
    ),
    ("noiseless-bias.toml", Build::BeforeRow("problem.noise.on_bias", "true")),
    (
        "positive-wrap.toml",
        Build::BeforeRow("problem.sensors.heading_wrap", r#""symmetric""#),
    ),
];

/// The files under `configs/` that are no build's defaults: the fit's
/// starting point (the previous defaults with the paper's stagnation
/// rule) and the paper's words.
const NOT_MODELS: [&str; 2] = ["fit-stage1.toml", "text.toml"];

/// A table value (TOML) and the defaults table's (JSON) are the same value.
fn same_value(file: &toml::Value, table: &serde_json::Value) -> bool {
    let file = serde_json::to_value(file).unwrap();
    match (file.as_f64(), table.as_f64()) {
        (Some(a), Some(b)) => a == b,
        _ => file == *table,
    }
}

#[test]
fn the_table_of_defaults_gives_each_earlier_model_of_configs_exactly_its_values() {
    // Every file under configs/ is listed, as a build's model or as none.
    let mut files: Vec<String> = std::fs::read_dir(repo("configs"))
        .unwrap()
        .map(|entry| entry.unwrap().file_name().into_string().unwrap())
        .collect();
    files.sort();
    let mut listed: Vec<String> = MODELS.iter().map(|(file, _)| file.to_string()).collect();
    listed.extend(NOT_MODELS.iter().map(|file| file.to_string()));
    listed.sort();
    assert_eq!(files, listed, "configs/ against the lists of this test");

    let today = Placement::Rows(CHANGES.len());
    for (file, build) in &MODELS {
        let text = std::fs::read_to_string(repo("configs").join(file)).unwrap();
        let table: toml::Table = toml::from_str(&text).unwrap();
        let placement = build.placement();
        let keys: std::collections::BTreeSet<&str> = CHANGES.iter().map(|row| row.key).collect();
        for key in keys {
            let mut at = Some(&table);
            let mut parts: Vec<&str> = key.split('.').collect();
            let last = parts.pop().unwrap();
            for part in parts {
                at = at.and_then(|t| t.get(part)).and_then(|v| v.as_table());
            }
            let then = value_at(key, &placement).unwrap().unwrap();
            match at.and_then(|t| t.get(last)) {
                // The file sets the key: to the model's value.
                Some(value) => assert!(
                    same_value(value, &then),
                    "configs/{file}: {key} = {value} there, {then} in the table"
                ),
                // It leaves it to the defaults: which must be the model's.
                None => {
                    let now = value_at(key, &today).unwrap().unwrap();
                    assert_eq!(
                        now, then,
                        "configs/{file} does not set {key}, whose default has changed since"
                    );
                }
            }
        }
    }
}

/// Evolves a 2-generation champion of `task` on the model of `config` into
/// `dir/name`: its recorded fitness and its champion file's JSON.
fn champion_of(dir: &Path, name: &str, config: &str, task: &str) -> (f64, serde_json::Value) {
    let out = dir.join(name);
    ok(&psa_esp(&[
        "evolve",
        "--task",
        task,
        "--generations",
        "2",
        "--backend",
        "native",
        "--config",
        repo(config).to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]));
    let read = |file: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(out.join(file)).unwrap()).unwrap()
    };
    (
        read("run.json")["champion_fitness"].as_f64().unwrap(),
        read("champion.json"),
    )
}

/// The fitness `psa-esp replay` prints for the network file `json`,
/// written into `dir/name.json`.
fn replayed(dir: &Path, name: &str, json: &serde_json::Value) -> f64 {
    let champion = dir.join(format!("{name}.json"));
    std::fs::write(&champion, json.to_string()).unwrap();
    common::replayed_fitness(&champion, "native", &dir.join(format!("{name}-replay")), &[])
}

#[test]
fn a_champion_of_each_earlier_model_replays_to_its_recorded_fitness_bit_for_bit_as_an_old_file() {
    let dir = tempfile::tempdir().unwrap();
    // The models of the builds before the table (whose files name their
    // commit, not the table's rows).
    for (i, (file, build)) in MODELS.iter().enumerate() {
        let Build::Before(changed) = build else { continue };
        let config = format!("configs/{file}");
        let (recorded, mut old) = champion_of(dir.path(), &format!("run{i}"), &config, "1");
        // The champion as the build of its model would have written it:
        // none of the settings that build did not have yet.
        as_file_of(&mut old, &parent_of(changed));
        let replayed = replayed(dir.path(), &format!("old{i}"), &old);
        assert_eq!(
            replayed.to_bits(),
            recorded.to_bits(),
            "{config}: {replayed} against {recorded}"
        );
    }
}

/// The size of the table of defaults of the build of the model before the
/// refit (`configs/positive-heading.toml`): the rows before the refit's
/// task-2 spin, the first change a build placed by its rows made.
fn positive_heading_rows() -> usize {
    CHANGES
        .iter()
        .position(|row| row.key == "problem.tasks.task2_spin" && row.since == Since::Commit(""))
        .expect("the refit's row")
}

#[test]
fn a_task_2_champion_of_the_model_before_the_refit_replays_to_its_recorded_fitness_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let (recorded, mut old) = champion_of(dir.path(), "run", "configs/positive-heading.toml", "2");
    assert_eq!(old["problem"]["tasks"]["task2_spin"], 0.75, "the model's own start");
    // Its build wrote every problem setting and the size of its table.
    old["provenance"]["defaults"] = positive_heading_rows().into();
    let replayed = replayed(dir.path(), "old", &old);
    assert_eq!(replayed.to_bits(), recorded.to_bits(), "{replayed} against {recorded}");
}
