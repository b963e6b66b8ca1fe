//! The command line end to end.

use std::process::{Command, Output};

fn psa_esp(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_psa-esp"))
        .args(args)
        .output()
        .expect("run psa-esp")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn version_names_the_commit_and_the_libode_version() {
    let o = psa_esp(&["--version"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let info = psa_experiment::build_info();
    assert_eq!(
        stdout(&o).trim(),
        format!(
            "psa-esp {} (commit {}, libode {})",
            info.tool_version, info.git_commit, info.libode_version
        )
    );
    assert!(info.libode_version.starts_with("0."), "{}", info.libode_version);
}

#[test]
fn simulate_writes_the_trajectory_csv() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("traj.csv");
    for backend in ["ode", "native"] {
        let o = psa_esp(&[
            "simulate",
            "--backend",
            backend,
            "--thrust",
            "1,0,1,0",
            "--steps",
            "40",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let csv = std::fs::read_to_string(&out).unwrap();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines[0], "t,x,y,heading,vx,vy,omega");
        assert_eq!(lines.len(), 42, "header + start + 40 steps");
        let last: Vec<f64> = lines[41].split(',').map(|v| v.parse().unwrap()).collect();
        assert!(
            (last[0] - 2.0).abs() < 1e-12 && last[1] > 0.0 && last[2] == 0.0 && last[6] == 0.0,
            "{last:?}"
        );
        // The size was said before anything was written, and it bounds the file's rows.
        let said = stderr(&o);
        assert!(
            said.starts_with("simulate: 41 states, at most 5.7 kB of trajectory to "),
            "{said}"
        );
        let rows: usize = lines[1..].iter().map(|l| l.len() + 1).sum();
        assert!(rows <= 41 * 140, "{rows}");
    }
}

#[test]
fn simulate_reads_a_thrust_file_and_prints_to_stdout() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("thrust.txt");
    std::fs::write(&file, "# u0 u1 u2 u3\n1 0 0 0\n1,0,0,0\n0 0 0 0\n").unwrap();
    let o = psa_esp(&[
        "simulate",
        "--thrust-file",
        file.to_str().unwrap(),
        "--start",
        "0,0,0,0,0.1,0",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    let rows: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 4);
    assert!(rows[3][6] > 0.0, "thruster 0 spins the body anticlockwise: {rows:?}");
    assert!(
        rows[3][2] > 0.0,
        "the start velocity 0.1 m/s along y carries it: {rows:?}"
    );
}

#[test]
fn bad_arguments_get_a_clear_error_and_a_nonzero_exit() {
    let dir = tempfile::tempdir().unwrap();
    let bad_file = dir.path().join("bad.txt");
    std::fs::write(&bad_file, "1 0 0\n").unwrap();
    let bad_file = bad_file.to_str().unwrap();
    let cases: [(&[&str], &str); 6] = [
        (&["simulate", "--thrust", "nan,0,0,0"], "NaN"),
        (&["simulate", "--thrust", "0,2,0,0"], "thruster 1: 2"),
        (&["simulate", "--thrust", "0,0,0"], "4 comma-separated"),
        (&["simulate", "--thrust", "0,0,0,0", "--dt", "-1"], "dt"),
        (&["simulate", "--thrust-file", bad_file], "line 1: expected 4"),
        (
            &["simulate", "--thrust-file", "/nonexistent/thrust.txt"],
            "/nonexistent/thrust.txt",
        ),
    ];
    for (args, needle) in cases {
        let o = psa_esp(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        assert!(stderr(&o).contains(needle), "{args:?}: {}", stderr(&o));
        assert!(!stderr(&o).contains("panicked"), "{args:?}");
    }
    let o = psa_esp(&["simulate", "--backend", "bullet", "--thrust", "0,0,0,0"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("bullet"));
}

#[test]
fn crosscheck_reports_every_backend_against_ode() {
    let o = psa_esp(&["crosscheck", "--sequences", "5", "--steps", "200", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let comparisons = report["comparisons"].as_array().unwrap();
    let expected = if cfg!(feature = "rapier") { 2 } else { 1 };
    assert_eq!(comparisons.len(), expected);
    for c in comparisons {
        assert_eq!(c["passed"], true, "{c}");
        assert!(c["deviation"]["position"].as_f64().unwrap() >= 0.0);
    }
    let o = psa_esp(&["crosscheck", "--sequences", "2", "--steps", "50"]);
    assert!(o.status.success());
    assert!(stdout(&o).contains("native"), "{}", stdout(&o));
}

#[test]
fn bench_prints_ns_per_step_for_every_backend_and_the_logistic_share() {
    let o = psa_esp(&[
        "bench",
        "--steps",
        "1000",
        "--rounds",
        "1",
        "--generations",
        "10",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let rows = report["physics_step"].as_array().unwrap();
    assert_eq!(rows.len(), psa_sim::physics::BackendKind::available().len());
    assert!(rows.iter().all(|r| r["median_ns_per_step"].as_f64().unwrap() > 0.0));
    let logistic = &report["logistic_function"];
    assert!(logistic["ns_per_value"].as_f64().unwrap() > 0.0, "{logistic}");
    assert_eq!(logistic["per_network_step"], 9, "{logistic}");
    let share = logistic["percent_of_batched_network_step"].as_f64().unwrap();
    assert!(share > 0.0 && share.is_finite(), "{logistic}");
    // The paper's noisy configurations have rows of their own: native's
    // scalar path and its best batched one under input noise.
    let noisy: Vec<_> = report["psa_evaluation"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["path"]["input_noise"] == true)
        .collect();
    assert_eq!(noisy.len(), 2, "{noisy:?}");
    assert!(noisy.iter().all(|e| e["path"]["backend"] == "native"), "{noisy:?}");
    assert!(noisy
        .iter()
        .all(|e| e["ns_per_network_step_1_thread"].as_f64().unwrap() > 0.0));
}

#[test]
fn bench_speedup_floor_exits_0_at_or_above_the_floor_and_1_below_it() {
    let run = |floor: &str| {
        psa_esp(&[
            "bench",
            "--speedup-floor",
            floor,
            "--networks",
            "32",
            "--rounds",
            "3",
            "--json",
        ])
    };
    let low = run("0.01");
    assert_eq!(low.status.code(), Some(0), "{}", stderr(&low));
    let report: serde_json::Value = serde_json::from_str(&stdout(&low)).unwrap();
    let speedup = report["speedup"].as_f64().unwrap();
    assert!(speedup > 0.0 && speedup.is_finite(), "{report}");
    assert_eq!(report["passed"], true, "{report}");
    let high = run("1000");
    assert_eq!(high.status.code(), Some(1), "{}", stderr(&high));
    let report: serde_json::Value = serde_json::from_str(&stdout(&high)).unwrap();
    assert_eq!(report["passed"], false, "{report}");
    // What the check cannot honour is refused.
    for args in [
        &["bench", "--speedup-floor", "0"][..],
        &["bench", "--speedup-floor", "4", "--steps", "1000"],
        &["bench", "--speedup-level", "portable"],
    ] {
        let o = psa_esp(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
    }
}

/// A hand-made 7-3-4 spin damper: neuron 0 fires thrusters 2 and 3
/// (clockwise torque) when omega > 0, neuron 1 fires 0 and 1 when omega < 0,
/// neuron 2 is a constant that keeps every output near 0 otherwise.
fn spin_damper() -> esp_neuroevolution::network::Network {
    let omega = |w: f64, bias: f64, out: [f64; 4]| {
        let mut genes = vec![0.0, 0.0, 0.0, 0.0, 0.0, w, bias];
        genes.extend(out);
        genes
    };
    esp_neuroevolution::network::Network::from_neurons(
        7,
        4,
        &[
            omega(20.0, -2.0, [0.0, 0.0, 8.0, 8.0]),
            omega(-20.0, -2.0, [8.0, 8.0, 0.0, 0.0]),
            omega(0.0, 10.0, [-8.0, -8.0, -8.0, -8.0]),
        ],
    )
    .unwrap()
}

/// The spin damper's network file in `dir` (`damper.json`).
///
/// The damper is made for task 1's earlier start spin of 1 rad/s (at the
/// default 2 rad/s its full thrust pushes the PSA out of the box before
/// the spin stops) and for a spin input of 1 per rad/s (its weights of
/// 20 saturate the braking neurons; the default scale halves them); the
/// file records that model, and replay flies on it.
fn damper_file(dir: &std::path::Path) -> std::path::PathBuf {
    use psa_sim::psa::{NetworkFile, PsaSettings, Task};
    let net_path = dir.join("damper.json");
    let mut model = PsaSettings::default();
    model.tasks.task1_spin = 1.0;
    model.sensors.angular_velocity_scale = 1.0;
    NetworkFile::new(
        &spin_damper(),
        Task::StopRotation,
        &model,
        &psa_experiment::build_info(),
        serde_json::Map::new(),
    )
    .save(&net_path)
    .unwrap();
    net_path
}

#[test]
fn replay_flies_the_config_files_noise_trials_and_starts_and_an_option_wins_over_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let net_path = damper_file(dir.path());
    let config = dir.path().join("noisy.toml");
    std::fs::write(
        &config,
        "[problem]\ntrials = 4\nbackend = \"native\"\n\n[problem.noise]\ninput_sd = 0.05\n",
    )
    .unwrap();
    let replay = |extra: &[&str]| -> serde_json::Value {
        let out = dir.path().join("replay");
        let mut args = vec![
            "replay",
            net_path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--json",
        ];
        args.extend(extra);
        let o = psa_esp(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        serde_json::from_str(&stdout(&o)).unwrap()
    };
    // The file's noise, trials and backend fly, as the same options would.
    let from_file = replay(&["--config", config.to_str().unwrap()]);
    let from_options = replay(&["--input-noise", "0.05", "--trials", "4", "--backend", "native"]);
    assert_eq!(from_file["input_noise"], 0.05);
    assert_eq!(from_file["trials"], 4);
    assert_eq!(from_file["backend"], "native");
    assert!(from_file["fitness_percent_sd"].as_f64().unwrap() > 0.0, "{from_file}");
    assert_eq!(
        from_file["fitness_percent_per_trial"],
        from_options["fitness_percent_per_trial"]
    );
    // An option given wins over the file: no noise, one trial.
    let quiet = replay(&[
        "--config",
        config.to_str().unwrap(),
        "--input-noise",
        "0",
        "--trials",
        "1",
    ]);
    assert_eq!(quiet["input_noise"], 0.0);
    assert_eq!(
        quiet["fitness_percent_per_trial"],
        replay(&["--backend", "native"])["fitness_percent_per_trial"]
    );
    // A file's random starts on a task without them are refused, naming the file's setting.
    std::fs::write(&config, "[problem]\nrandom_init = true\n").unwrap();
    let o = psa_esp(&[
        "replay",
        net_path.to_str().unwrap(),
        "--task",
        "2",
        "--config",
        config.to_str().unwrap(),
        "--out",
        dir.path().join("r2").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("problem.random_init") && stderr(&o).contains("task 2"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn replay_prints_the_fitness_and_writes_trajectory_pictures_and_animation() {
    let dir = tempfile::tempdir().unwrap();
    let net_path = damper_file(dir.path());
    let out = dir.path().join("replay");
    let o = psa_esp(&[
        "replay",
        net_path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    // It stops the spin within a few steps and stays in the box (1 point a
    // step; doing nothing scores 0), and earns a little for the heading.
    let fitness = summary["fitness_percent_mean"].as_f64().unwrap();
    assert!(fitness > 25.0 && fitness < 100.0, "{fitness}");
    let csv = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    assert!(csv.starts_with("t,x,y,heading,vx,vy,omega,u0,u1,u2,u3,points"));
    let last: Vec<f64> = csv
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    assert!(last[6].abs() < 0.05, "the spin is stopped: {last:?}");
    let png = std::fs::read(out.join("trial.png")).unwrap();
    assert!(
        png.starts_with(b"\x89PNG\r\n\x1a\n") && png.len() > 20_000,
        "{} bytes",
        png.len()
    );
    for svg in ["trial.svg", "trial-animation.svg"] {
        let text = std::fs::read_to_string(out.join(svg)).unwrap();
        assert!(
            text.contains("<svg") && text.trim_end().ends_with("</svg>") && text.len() > 20_000,
            "{svg}"
        );
    }
    assert!(std::fs::read_to_string(out.join("trial-animation.svg"))
        .unwrap()
        .contains("<animate"));
    // Several trials under noise: mean and sd over the trials.
    let o = psa_esp(&[
        "replay",
        net_path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--trials",
        "4",
        "--input-noise",
        "0.05",
        "--random-init",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(summary["fitness_percent_per_trial"].as_array().unwrap().len(), 4);
    // Bad input: task 2 has no random initialisation; a broken network file.
    let o = psa_esp(&[
        "replay",
        net_path.to_str().unwrap(),
        "--task",
        "2",
        "--random-init",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("task 2"));
    std::fs::write(&net_path, "{").unwrap();
    let o = psa_esp(&["replay", net_path.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("damper.json") && stderr(&o).contains("not valid JSON"),
        "{}",
        stderr(&o)
    );
}
