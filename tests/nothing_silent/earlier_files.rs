//! A file that lacks a setting gets the value of the build that wrote it.

use super::*;
use psa_experiment::models::EarlierModel;
use psa_sim::named::Named;
use psa_sim::psa::settings::defaults::Since;
use strum::VariantArray;

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

/// The files under `configs/` that are no earlier build's model: the fit's
/// starting point (the previous defaults with the paper's stagnation
/// rule) and the paper's words.
const NOT_MODELS: [&str; 2] = ["fit-stage1.toml", "text.toml"];

#[test]
fn each_earlier_model_has_a_file_under_configs_that_names_it_and_nothing_else() {
    let mut files: Vec<String> = std::fs::read_dir(repo("configs"))
        .unwrap()
        .map(|entry| entry.unwrap().file_name().into_string().unwrap())
        .collect();
    files.sort();
    let mut listed: Vec<String> = EarlierModel::names()
        .iter()
        .map(|name| format!("{name}.toml"))
        .collect();
    listed.extend(NOT_MODELS.iter().map(|file| file.to_string()));
    listed.sort();
    assert_eq!(files, listed, "configs/ against the earlier models and the two others");
    for model in EarlierModel::VARIANTS {
        let text = std::fs::read_to_string(repo("configs").join(format!("{model}.toml"))).unwrap();
        let table: toml::Table = toml::from_str(&text).unwrap();
        let expected: toml::Table = toml::from_str(&format!("model = \"{model}\"")).unwrap();
        assert_eq!(
            table, expected,
            "configs/{model}.toml sets its model's name and nothing else"
        );
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
    for (i, model) in EarlierModel::VARIANTS.iter().enumerate() {
        let Placement::Commit(build) = model.placement() else {
            continue;
        };
        let config = format!("configs/{model}.toml");
        let (recorded, mut old) = champion_of(dir.path(), &format!("run{i}"), &config, "1");
        // The champion as the build of its model would have written it:
        // none of the settings that build did not have yet.
        as_file_of(&mut old, &build);
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

#[test]
fn a_configuration_naming_an_unknown_model_is_refused_listing_the_models() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("model.toml");
    std::fs::write(&config, "model = \"positive\"\n").unwrap();
    let out = dir.path().join("run");
    let args = [
        "evolve",
        "--task",
        "1",
        "--generations",
        "1",
        "--config",
        config.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    refused(
        &psa_esp(&args),
        &["model.toml", "\"positive\"", "positive-wrap", "previous-defaults"],
    );
    assert!(!out.exists(), "nothing written");
    // A known one flies that model, under the file's own settings.
    std::fs::write(&config, "model = \"positive-wrap\"\n[esp]\nstagnation = 7\n").unwrap();
    ok(&psa_esp(&args));
    let recorded: toml::Table = toml::from_str(&std::fs::read_to_string(out.join("config.toml")).unwrap()).unwrap();
    assert_eq!(
        recorded["problem"]["sensors"]["heading_wrap"].as_str(),
        Some("positive")
    );
    assert_eq!(recorded["esp"]["stagnation"].as_integer(), Some(7));
    assert!(!recorded.contains_key("model"), "the run records the model resolved");
}
