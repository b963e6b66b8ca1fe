//! Network files: exact round trips, and a clear error for each kind of malformed file.

use esp_neuroevolution::network::Network;
use psa_sim::numeric::Exponential;
use psa_sim::psa::{NetworkFile, PsaSettings, Task};
use rand::RngExt;

fn sample_network() -> Network {
    let mut rng = esp_neuroevolution::rng::stream(5, &[]);
    // Awkward values on purpose: they must survive the trip bit for bit.
    let mut genes: Vec<f64> = (0..5 * 11).map(|_| rng.random_range(-6.0..6.0)).collect();
    genes[0] = 0.1 + 0.2;
    genes[1] = -1e-300;
    genes[2] = 5e-324;
    let mut net = Network::from_genes(7, 4, genes).unwrap();
    net.set_lesioned(3, true);
    net
}

#[test]
fn save_and_load_round_trip_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("net.json");
    let net = sample_network();
    let mut extra = serde_json::Map::new();
    extra.insert("seed".into(), 42.into());
    let file = NetworkFile::new(
        &net,
        Task::StopAtPosition,
        &PsaSettings::default(),
        &psa_experiment::build_info(),
        extra,
    );
    file.save(&path).unwrap();
    let (loaded_file, loaded) = NetworkFile::load(&path).unwrap();
    assert_eq!(loaded, net);
    assert_eq!(loaded_file, file);
    assert!(loaded
        .genes()
        .iter()
        .zip(net.genes())
        .all(|(a, b)| a.to_bits() == b.to_bits()));
    assert_eq!(loaded_file.task, Task::StopAtPosition);
    assert_eq!(loaded_file.provenance["seed"], 42);
    for key in ["tool_version", "git_commit", "libode_version"] {
        assert!(loaded_file.provenance[key].is_string(), "provenance lacks {key}");
    }
    // Saving what was loaded gives the same bytes.
    let again = dir.path().join("again.json");
    loaded_file.save(&again).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), std::fs::read(&again).unwrap());
}

fn valid_json() -> serde_json::Value {
    let file = NetworkFile::new(
        &sample_network(),
        Task::Turn,
        &PsaSettings::default(),
        &psa_experiment::build_info(),
        serde_json::Map::new(),
    );
    serde_json::to_value(&file).unwrap()
}

/// Makes `file` one of the build before commit `changed` (a file lacking
/// a setting gets the value of the build that wrote it: `psa::settings::defaults`).
fn as_written_before(file: &mut serde_json::Value, changed: &str) {
    let line = psa_sim::psa::settings::defaults::BUILDS
        .lines()
        .find(|l| l.starts_with(changed))
        .unwrap();
    let parent = line.split(' ').nth(1).unwrap();
    let provenance = file["provenance"].as_object_mut().unwrap();
    provenance.remove("defaults");
    provenance.insert("git_commit".into(), parent.into());
}

#[test]
fn files_from_before_the_exponential_setting_load_with_the_accurate_one() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("net.json");
    let mut old = valid_json();
    old["problem"].as_object_mut().unwrap().remove("exponential").unwrap();
    as_written_before(&mut old, "b450d06");
    std::fs::write(&path, old.to_string()).unwrap();
    let (file, _) = NetworkFile::load(&path).unwrap();
    assert_eq!(file.problem.unwrap().exponential, Exponential::Accurate);
    // A file that names it keeps it.
    let new = valid_json();
    assert_eq!(new["problem"]["exponential"], "fast");
    std::fs::write(&path, new.to_string()).unwrap();
    let (file, _) = NetworkFile::load(&path).unwrap();
    assert_eq!(file.problem.unwrap().exponential, Exponential::Fast);
}

#[test]
fn files_from_before_the_readings_of_the_fitness_load_scored_on_their_evolution_fitness_from_the_true_state() {
    use psa_sim::psa::{FitnessState, Scoring};
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("net.json");
    let mut old = valid_json();
    let fitness = old["problem"]["fitness"].as_object_mut().unwrap();
    fitness.remove("scoring").unwrap();
    fitness.remove("state").unwrap();
    as_written_before(&mut old, "d8e86a8");
    std::fs::write(&path, old.to_string()).unwrap();
    let problem = NetworkFile::load(&path).unwrap().0.problem.unwrap();
    assert_eq!(
        (problem.fitness.scoring, problem.fitness.state),
        (Scoring::Evolution, FitnessState::True)
    );
    // Today's files name them, and keep the defaults.
    let new = valid_json();
    assert_eq!(
        (
            new["problem"]["fitness"]["scoring"].as_str(),
            new["problem"]["fitness"]["state"].as_str()
        ),
        (Some("original"), Some("sensed"))
    );
    std::fs::write(&path, new.to_string()).unwrap();
    let problem = NetworkFile::load(&path).unwrap().0.problem.unwrap();
    assert_eq!(
        (problem.fitness.scoring, problem.fitness.state),
        (Scoring::Original, FitnessState::Sensed)
    );
}

#[test]
fn malformed_files_are_rejected_with_the_file_and_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let mut cases: Vec<(&str, String, &str)> = vec![
        ("not-json", "this is not json".into(), "not valid JSON"),
        (
            "nan",
            valid_json()
                .to_string()
                .replacen("\"weights\":[", "\"weights\":[NaN,", 1),
            "not valid JSON",
        ),
        (
            "huge",
            valid_json()
                .to_string()
                .replacen("\"weights\":[", "\"weights\":[1e999,", 1),
            "not valid JSON",
        ),
    ];
    type Mutation = (&'static str, fn(&mut serde_json::Value), &'static str);
    let mutations: Vec<Mutation> = vec![
        ("version", |v| v["version"] = 99.into(), "unknown version 99"),
        (
            "format",
            |v| v["format"] = "something-else".into(),
            "format is \"something-else\"",
        ),
        (
            "no-format",
            |v| drop(v.as_object_mut().unwrap().remove("format")),
            "not a psa-esp network file",
        ),
        (
            "hidden-count",
            |v| v["topology"]["hidden"] = 6.into(),
            "topology says 6 hidden neurons, the file has 5",
        ),
        (
            "neuron-size",
            |v| drop(v["neurons"][2]["weights"].as_array_mut().unwrap().pop()),
            "hidden neuron 2 has 10 weights",
        ),
        (
            "string-weight",
            |v| v["neurons"][0]["weights"][4] = "NaN".into(),
            "invalid type",
        ),
        ("activation", |v| v["activation"] = "tanh".into(), "activation \"tanh\""),
        ("task", |v| v["task"] = 4.into(), "task must be 1, 2 or 3"),
        ("unknown-field", |v| v["extra"] = 1.into(), "unknown field `extra`"),
        (
            "inputs",
            |v| v["topology"]["inputs"] = 0.into(),
            "inputs and outputs must be >= 1",
        ),
    ];
    for (name, mutate, needle) in mutations {
        let mut v = valid_json();
        mutate(&mut v);
        cases.push((name, v.to_string(), needle));
    }
    for (name, text, needle) in cases {
        let path = dir.path().join(format!("{name}.json"));
        std::fs::write(&path, text).unwrap();
        let err = NetworkFile::load(&path).unwrap_err().to_string();
        assert!(err.contains(path.to_str().unwrap()), "{name}: {err}");
        assert!(err.contains(needle), "{name}: {err}");
    }
    let missing = dir.path().join("missing.json");
    let err = NetworkFile::load(&missing).unwrap_err().to_string();
    assert!(err.contains("missing.json") && err.contains("cannot read"), "{err}");
}
