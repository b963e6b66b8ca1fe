//! The model fitted to the paper's evidence (docs/model.md): what doing
//! nothing scores, the earlier defaults kept as a configuration file that
//! repeats earlier runs byte for byte, champions that carry their model,
//! and sweeps end to end.

use std::path::{Path, PathBuf};
use std::process::Output;

use esp_neuroevolution::network::Network;
use esp_neuroevolution::rng::stream;
use psa_experiment::models::EarlierModel;
use psa_sim::named::Named;
use psa_sim::physics::BackendKind;
use psa_sim::psa::{PsaSettings, Task, TrialRunner};

mod common;

use common::psa_esp;

fn ok(o: &Output) -> String {
    assert!(
        o.status.success(),
        "exit {:?}: {}",
        o.status.code(),
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// A network whose four outputs are all about 1e-13: it does nothing.
fn idle_network() -> Network {
    let mut genes = vec![0.0; 6];
    genes.push(6.0); // the hidden unit sits near 1
    genes.extend([-30.0; 4]);
    Network::from_genes(7, 4, genes).unwrap()
}

#[test]
fn doing_nothing_scores_under_1_percent_on_task_2_and_a_few_on_tasks_1_and_3() {
    for backend in [BackendKind::Ode, BackendKind::Native] {
        let settings = PsaSettings {
            backend,
            ..PsaSettings::default()
        };
        let score = |task| {
            TrialRunner::new(&settings, task)
                .unwrap()
                .evaluate(&idle_network(), &mut stream(1, &[]))
                .unwrap()
        };
        // A stagnated task-2 run whose champion earns 1 point of 2000 (the
        // paper's section 5.1) needs a start where doing nothing earns nothing.
        assert!(score(Task::Turn) < 1.0, "{backend}: task 2 {}", score(Task::Turn));
        assert!(
            score(Task::StopRotation) <= 3.0,
            "{backend}: task 1 {}",
            score(Task::StopRotation)
        );
        // Task 3: coasting through the box at 0.3 m/s on the target heading.
        assert!(
            score(Task::StopAtPosition) <= 5.5,
            "{backend}: task 3 {}",
            score(Task::StopAtPosition)
        );
    }
}

/// Asserts that `config` laid over each of `presets` repeats the records
/// in `tests/golden/GOLDEN/PRESET-tTASK.csv` on every task, byte for byte
/// (seed 7, 120 generations, native).
fn assert_repeats_the_golden_records(config: &str, golden: &str, presets: &[&str]) {
    for preset in presets {
        for task in ["1", "2", "3"] {
            assert_repeats_one_golden_record(&repo(config), golden, preset, preset, task);
        }
    }
}

/// Asserts that `config` laid over `preset` repeats the records in
/// `tests/golden/GOLDEN/LABEL-tTASK.csv` on `task`, byte for byte (seed 7,
/// 120 generations, native).
fn assert_repeats_one_golden_record(config: &Path, golden: &str, preset: &str, label: &str, task: &str) {
    let records = golden_run_records(Some(config), preset, task);
    let recorded = std::fs::read(repo(&format!("tests/golden/{golden}/{label}-t{task}.csv"))).unwrap();
    assert!(
        records == recorded,
        "{label} task {task}: records.csv differs from the one recorded in tests/golden/{golden}"
    );
}

#[test]
fn the_previous_defaults_file_repeats_the_earlier_records_byte_for_byte() {
    // Recorded by the build before the fit (6631aa9).
    assert_repeats_the_golden_records(
        "configs/previous-defaults.toml",
        "previous-defaults",
        &["baseline", "max-credit", "hill-climb"],
    );
}

#[test]
fn the_fit_stage1_file_repeats_the_records_of_an_earlier_build_byte_for_byte() {
    // Recorded by build 55317a7 (before input noise reached the bias):
    // the file pins every setting whose default changed since the
    // starting point of sweeps S1-S6, so every build repeats them.
    assert_repeats_the_golden_records("configs/fit-stage1.toml", "fit-stage1", &["baseline"]);
}

#[test]
fn the_fitted_incremental_file_repeats_the_records_of_the_model_before_the_readings_byte_for_byte() {
    // Recorded by build bf1d0de, whose defaults the file pins.
    assert_repeats_the_golden_records(
        "configs/fitted-incremental.toml",
        "fitted-incremental",
        &["baseline", "max-credit"],
    );
}

#[test]
fn the_scored_on_original_file_repeats_the_records_of_the_first_original_scoring_grid_byte_for_byte() {
    // Recorded by build 030dd52, whose defaults the file pins; evolution
    // from random starts too.
    let config = "configs/scored-on-original.toml";
    assert_repeats_the_golden_records(config, "scored-on-original", &["baseline", "max-credit"]);
    assert_repeats_the_random_start_records(config, "scored-on-original");
}

#[test]
fn the_symmetric_heading_file_repeats_the_records_of_the_model_before_the_positive_wrap_byte_for_byte() {
    // Recorded by build aeb463d (the code of 82f0df7), whose defaults the file pins; evolution
    // from random starts too.
    let config = "configs/symmetric-heading.toml";
    assert_repeats_the_golden_records(config, "symmetric-heading", &["baseline", "max-credit"]);
    assert_repeats_the_random_start_records(config, "symmetric-heading");
}

#[test]
fn the_positive_heading_file_repeats_the_records_of_the_model_before_the_readings_of_esp_byte_for_byte() {
    // Recorded by build 44b0cee, whose defaults the file pins: the
    // hill-climber's first chosen mutation, and evolution from random starts.
    let config = "configs/positive-heading.toml";
    assert_repeats_the_golden_records(config, "positive-heading", &["baseline", "max-credit", "hill-climb"]);
    assert_repeats_the_random_start_records(config, "positive-heading");
    // Erasing the best network on a topology change only: with b = 5 the
    // 120 generations hold bursts, lesion tests and erasures.
    let dir = tempfile::tempdir().unwrap();
    let frequent = dir.path().join("frequent-bursts.toml");
    let text = std::fs::read_to_string(repo(config)).unwrap();
    std::fs::write(&frequent, format!("{text}\n[esp]\nstagnation = 5\n")).unwrap();
    for task in ["1", "2", "3"] {
        assert_repeats_one_golden_record(&frequent, "positive-heading", "erase-best", "erase-best-b5", task);
    }
}

#[test]
fn the_task2_towards_target_file_repeats_the_records_of_the_refit_byte_for_byte() {
    // Recorded by build ad8db97, whose defaults the file pins: task 2
    // starting at 1.0 rad/s, towards its target.
    let config = "configs/task2-towards-target.toml";
    assert_repeats_the_golden_records(config, "task2-towards-target", &["baseline", "max-credit"]);
    // Today's defaults start task 2 elsewhere, and fly another run.
    let recorded = std::fs::read(repo("tests/golden/task2-towards-target/baseline-t2.csv")).unwrap();
    assert!(
        golden_run_records(None, "baseline", "2") != recorded,
        "task 2's default start did not move"
    );
}

#[test]
fn the_clockwise_start_file_repeats_the_records_of_sweeps_s33_to_s35_byte_for_byte() {
    // Recorded by build 8360a43, whose defaults the file pins: the sensor
    // scales 10, 10, 1, 1 and task 2 starting at -1.5 rad/s.
    let config = "configs/clockwise-start.toml";
    assert_repeats_the_golden_records(config, "clockwise-start", &["baseline", "max-credit"]);
    // Today's defaults scale the inputs by half and start task 2 at
    // -0.75 rad/s: every task flies another run.
    for task in ["1", "2", "3"] {
        let recorded = std::fs::read(repo(&format!("tests/golden/clockwise-start/baseline-t{task}.csv"))).unwrap();
        assert!(
            golden_run_records(None, "baseline", task) != recorded,
            "task {task}: the defaults did not move"
        );
    }
}

#[test]
fn the_noiseless_bias_file_repeats_the_records_of_sweeps_s41_to_s46_byte_for_byte() {
    // Recorded by build 55317a7, whose defaults the file pins: input noise
    // on the six sensed inputs, not on the bias. Evolution under input
    // noise (Table 3's configuration) is the run that reads it.
    let dir = tempfile::tempdir().unwrap();
    let noisy = |name: &str, model: &str| {
        let path = dir.path().join(name);
        std::fs::write(
            &path,
            format!("{model}[problem]\ntrials = 3\n[problem.noise]\ninput_sd = 0.05\n"),
        )
        .unwrap();
        path
    };
    let pinned = noisy(
        "noiseless-bias.toml",
        &std::fs::read_to_string(repo("configs/noiseless-bias.toml")).unwrap(),
    );
    let defaults = noisy("defaults.toml", "");
    for task in ["1", "2", "3"] {
        assert_repeats_one_golden_record(&pinned, "noiseless-bias", "baseline", "input-noise", task);
        // Today's defaults put the noise on the bias too: another run.
        let recorded = std::fs::read(repo(&format!("tests/golden/noiseless-bias/input-noise-t{task}.csv"))).unwrap();
        assert!(
            golden_run_records(Some(&defaults), "baseline", task) != recorded,
            "task {task}: the defaults did not move"
        );
    }
}

#[test]
fn the_positive_wrap_file_repeats_the_records_of_the_confirmed_grid_byte_for_byte() {
    // Recorded by build 373ef90, whose defaults the file pins: the heading
    // error wrapped to [0, 2 pi).
    let config = "configs/positive-wrap.toml";
    assert_repeats_the_golden_records(config, "positive-wrap", &["baseline", "max-credit"]);
    // Today's defaults wrap it to (-pi, pi]: every task flies another run.
    assert_the_defaults_move_on("positive-wrap", [true, true, true]);
}

#[test]
fn the_heading_error_file_repeats_the_records_of_the_confirmed_grid_byte_for_byte() {
    // Recorded by build a35a2bb, whose defaults the file pins: the heading
    // input is the heading minus the target's.
    let config = "configs/heading-error.toml";
    assert_repeats_the_golden_records(config, "heading-error", &["baseline", "max-credit"]);
    // Today's defaults read the heading itself (tasks 1 and 3 aim at
    // heading 0, where the two inputs are the same number; task 2 at pi/2),
    // and since S52 at the text's scales: every task moves.
    assert_the_defaults_move_on("heading-error", [true, true, true]);
}

#[test]
fn the_halved_scales_file_repeats_the_records_of_the_full_grid_of_s51_byte_for_byte() {
    // Recorded by build a3905c5, whose defaults the file pins: the sensor
    // scales halved.
    let config = "configs/halved-scales.toml";
    assert_repeats_the_golden_records(config, "halved-scales", &["baseline", "max-credit"]);
    // Today's defaults read the sensors at the text's scales: every task moves.
    assert_the_defaults_move_on("halved-scales", [true, true, true]);
}

/// Asserts that today's defaults fly another baseline run than the one
/// recorded in `tests/golden/GOLDEN/` on exactly the tasks (1 to 3) that
/// `moves` marks, and the same run on the others.
fn assert_the_defaults_move_on(golden: &str, moves: [bool; 3]) {
    for (task, moves) in ["1", "2", "3"].into_iter().zip(moves) {
        let recorded = std::fs::read(repo(&format!("tests/golden/{golden}/baseline-t{task}.csv"))).unwrap();
        assert_eq!(
            golden_run_records(None, "baseline", task) != recorded,
            moves,
            "task {task}: the defaults moved or stayed against tests/golden/{golden}"
        );
    }
}

#[test]
fn every_earlier_model_and_the_fits_starting_point_have_golden_records_and_nothing_else_has() {
    let mut folders: Vec<String> = std::fs::read_dir(repo("tests/golden"))
        .unwrap()
        .map(|entry| entry.unwrap().file_name().into_string().unwrap())
        .collect();
    folders.sort();
    let mut models: Vec<String> = EarlierModel::names().iter().map(|name| name.to_string()).collect();
    models.push("fit-stage1".into());
    models.sort();
    assert_eq!(
        folders, models,
        "tests/golden/ against the earlier models and configs/fit-stage1.toml"
    );
}

/// The `records.csv` of the golden records' run (seed 7, 120 generations,
/// native) of `preset` on `task`, with `config` laid over it if given.
fn golden_run_records(config: Option<&Path>, preset: &str, task: &str) -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let mut args = vec![
        "evolve",
        "--task",
        task,
        "--preset",
        preset,
        "--seed",
        "7",
        "--generations",
        "120",
        "--backend",
        "native",
        "--out",
        out.to_str().unwrap(),
    ];
    if let Some(config) = config {
        args.extend(["--config", config.to_str().unwrap()]);
    }
    ok(&psa_esp(&args));
    std::fs::read(out.join("records.csv")).unwrap()
}

/// Asserts that `config` with random starts repeats the records in
/// `tests/golden/GOLDEN/random-init-tTASK.csv` on tasks 1 and 3 (the tasks
/// the paper starts at random), byte for byte.
fn assert_repeats_the_random_start_records(config: &str, golden: &str) {
    let dir = tempfile::tempdir().unwrap();
    let random_starts = dir.path().join("random-starts.toml");
    let text = std::fs::read_to_string(repo(config)).unwrap();
    std::fs::write(&random_starts, format!("{text}\n[problem]\nrandom_init = true\n")).unwrap();
    for task in ["1", "3"] {
        assert_repeats_one_golden_record(&random_starts, golden, "baseline", "random-init", task);
    }
}

#[test]
fn replay_flies_a_champion_on_the_model_it_was_evolved_under() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("model.toml");
    // A model unlike the default: faster task-3 start, other input scaling.
    std::fs::write(
        &config,
        "[problem.tasks]\ntask3_speed = 0.25\n[problem.sensors]\nposition_scale = 3.0\n",
    )
    .unwrap();
    let out = dir.path().join("run");
    let args = [
        "evolve",
        "--task",
        "3",
        "--generations",
        "6",
        "--backend",
        "native",
        "--config",
        config.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    ok(&psa_esp(&args));
    let run: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    let evolved = run["champion_fitness"].as_f64().unwrap();
    let champion = out.join("champion.json");
    let replay = |extra: &[&str]| common::replayed_fitness(&champion, "native", &dir.path().join("replay"), extra);
    assert_eq!(replay(&[]), evolved, "the recorded model gives the evolved fitness");
    let on_default = replay(&["--default-model"]);
    assert_ne!(on_default, evolved, "the default model is another model");
    // --config lays settings over the recorded model: setting them back to
    // the default model's values gives the default model's score.
    let back = dir.path().join("back.toml");
    let defaults = PsaSettings::default();
    std::fs::write(
        &back,
        format!(
            "[problem.tasks]\ntask3_speed = {:?}\n[problem.sensors]\nposition_scale = {:?}\n",
            defaults.tasks.task3_speed, defaults.sensors.position_scale
        ),
    )
    .unwrap();
    assert_eq!(replay(&["--config", back.to_str().unwrap()]), on_default);
}

#[test]
fn a_sweep_runs_a_grid_per_variant_and_reports_the_distance_and_sensitivity() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sweep");
    let args = [
        "sweep",
        "--vary",
        "esp.stagnation=3,5",
        "--vary",
        "problem.tasks.task3_speed=0.1,0.2",
        "--configs",
        "baseline,max-credit",
        "--seeds",
        "2",
        "--generations",
        "12",
        "--robustness-trials",
        "4",
        "--out",
        out.to_str().unwrap(),
    ];
    let o = psa_esp(&args);
    let first = ok(&o);
    assert!(first.contains("4 variants, 48 runs"), "{first}");
    // All variants run together: each finished run's line names its variant.
    let lines = String::from_utf8_lossy(&o.stderr);
    assert!(
        lines.contains("v3-esp.stagnation=5+problem.tasks.task3_speed=0.2: finished max-credit task 3 seed 2"),
        "{lines}"
    );
    // Again: resumed, nothing to do.
    let again = ok(&psa_esp(&args));
    assert!(again.contains("48 already finished, 0 run now"), "{again}");
    // Another definition on the same folder is refused.
    let mut other = args.to_vec();
    other[2] = "esp.stagnation=3,6";
    let o = psa_esp(&other);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("another definition"));
    // Each variant is an ordinary grid with its settings recorded.
    let variant = out.join("variants/v1-esp.stagnation=3+problem.tasks.task3_speed=0.2");
    let config = std::fs::read_to_string(variant.join("runs/baseline/task3/seed1/config.toml")).unwrap();
    assert!(
        config.contains("stagnation = 3") && config.contains("task3_speed = 0.2"),
        "{config}"
    );
    // The same seed gives the same run in a variant that only changes task 3's start on another task.
    let records =
        |v: &str| std::fs::read(out.join(format!("variants/{v}/runs/baseline/task1/seed2/records.csv"))).unwrap();
    assert_eq!(
        records("v0-esp.stagnation=3+problem.tasks.task3_speed=0.1"),
        records("v1-esp.stagnation=3+problem.tasks.task3_speed=0.2")
    );
    let report = ok(&psa_esp(&["report", out.to_str().unwrap()]));
    assert!(report.contains("# Sweep report"), "{report}");
    assert!(report.contains("| `esp.stagnation` | 3, 5 |"), "{report}");
    assert!(report.contains("Closest to the paper"), "{report}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("sweep-report.json")).unwrap()).unwrap();
    let variants = json["variants"].as_array().unwrap();
    assert_eq!(variants.len(), 4);
    for v in variants {
        let d = &v["distance"];
        // Table 1 (3) + Table 2 (5) + both burst totals, their 8 sds and the burst ratio: every term has runs here.
        assert_eq!(d["terms"].as_array().unwrap().len(), 19, "{d}");
        let total: f64 = d["terms"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| t["z"].as_f64().unwrap().powi(2))
            .sum();
        assert!((total - d["total"].as_f64().unwrap()).abs() < 1e-9);
        // The three parts add up to the total; each holds its own terms.
        let parts: f64 = ["means", "spreads", "burst_ratio"]
            .iter()
            .map(|p| d[p].as_f64().unwrap())
            .sum();
        assert!((parts - total).abs() < 1e-9, "{d}");
        let part_sum = |part: &str| -> f64 {
            d["terms"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|t| t["part"] == part)
                .map(|t| t["z"].as_f64().unwrap().powi(2))
                .sum()
        };
        assert_eq!(part_sum("spread"), d["spreads"].as_f64().unwrap());
        assert_eq!(part_sum("burst_ratio"), d["burst_ratio"].as_f64().unwrap());
    }
}

#[test]
fn the_text_model_sets_exactly_the_settings_the_papers_words_decide_each_with_its_words() {
    let path = repo("configs/text.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let defaults = psa_experiment::RunConfig::baseline_with("").unwrap();
    let model = psa_experiment::RunConfig::baseline_with(&text).unwrap();
    let mut changed: Vec<String> = psa_experiment::grid::differences(&defaults, &model)
        .unwrap()
        .into_iter()
        .map(|(key, _, _)| key)
        .collect();
    changed.sort();
    // Noise on the bias too (`noise.on_bias`) is the text's reading and
    // the default: the file sets it, with its words, and changes nothing.
    assert!(text.contains("\non_bias = true\n"));
    // So is the heading itself as the heading input (`heading_input`),
    // and so are the scales at k = 1.
    assert!(text.contains("\nheading_input = \"absolute\"\n"));
    assert!(text.contains("\nposition_scale = 10.0\n"));
    assert_eq!(
        changed,
        [
            "problem.fitness.scoring",
            "problem.fitness.slowing",
            "problem.fitness.state",
            "problem.tasks.task2_spin",
        ]
    );
    // Every setting follows a comment that quotes the paper and names its section.
    let mut comment = String::new();
    for line in text.lines() {
        if let Some(c) = line.strip_prefix('#') {
            comment.push_str(c);
        } else if line.contains(" = ") {
            assert!(
                comment.contains('"') && comment.contains('§'),
                "{line}: no quoted words before it"
            );
            comment.clear();
        } else if line.trim().is_empty() || line.starts_with('[') {
            comment.clear();
        }
    }
    // It flies every task.
    let tmp = tempfile::tempdir().unwrap();
    for task in ["1", "2", "3"] {
        let out = tmp.path().join(task);
        ok(&psa_esp(&[
            "evolve",
            "--task",
            task,
            "--generations",
            "2",
            "--config",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]));
    }
}
