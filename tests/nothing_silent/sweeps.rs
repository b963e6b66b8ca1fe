//! Sweeps are counted, and checked whole, before their first run is built.

use super::*;

// Sweeps are counted before they are built.

#[test]
fn a_sweep_of_too_many_variants_is_refused_before_any_is_built() {
    let values = |key: &str| {
        let list: Vec<String> = (0..100).map(|i| format!("{}", 0.001 * i as f64)).collect();
        format!("{key}={}", list.join(","))
    };
    let vary = [
        values("problem.noise.input_sd"),
        values("problem.noise.output_sd"),
        values("problem.tasks.task3_speed"),
        values("problem.tasks.task1_spin"),
    ];
    let start = Instant::now();
    let err = sweep_of(
        grid(&["baseline"], &[Task::StopRotation]),
        &vary.iter().map(String::as_str).collect::<Vec<_>>(),
    )
    .unwrap_err();
    let err = format!("{err:#}");
    assert!(err.contains("100000000 variants"), "{err}");
    assert!(start.elapsed() < Duration::from_secs(5), "{:?}", start.elapsed());
    // The command line, likewise: refused at once, nothing written.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sweep");
    let vary: Vec<&str> = vary.iter().map(String::as_str).collect();
    let o = run_within(&tiny_sweep(&out, "1", &vary), Duration::from_secs(30)).expect("refused within 30 s");
    refused(&o, &["100000000 variants"]);
    assert!(!out.exists());
}

// Sweeps are checked whole before the first run.

/// Eight keys of two values each, each read by task 1 (a key only tasks 2
/// and 3 read would be refused in a task-1 grid): 256 variants, whose
/// names would pass a file name's 255 bytes if each named every key and
/// value in full.
const VARIED: [&str; 8] = [
    "problem.noise.output_sd=0.0,0.05",
    "problem.noise.input_sd=0.0,0.05",
    "problem.sensors.angular_velocity_scale=1.0,2.0",
    "problem.sensors.position_scale=10.0,20.0",
    "problem.fitness.heading_window=0.05,0.1",
    "problem.fitness.box_half_width=0.05,0.1",
    "problem.fitness.spin_window=0.05,0.1",
    "problem.tasks.task1_spin=1.0,0.7853981633974483",
];

#[test]
fn variant_names_fit_a_file_system_and_every_variant_is_checked_on_every_task() {
    let spec = sweep_of(grid(&["baseline"], &[Task::StopRotation]), &VARIED).unwrap();
    let variants = spec.variants();
    assert_eq!(variants.len(), 256);
    for v in &variants {
        assert!(v.name.len() <= MAX_VARIANT_NAME, "{} bytes: {}", v.name.len(), v.name);
    }
    let names: std::collections::HashSet<&str> = variants.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(names.len(), variants.len(), "names stay distinct");
    // The command line makes such a variant's folder: the first of the
    // 256 runs (shard 0 of 256), three generations.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sweep");
    let mut args = tiny_sweep(&out, "1", &VARIED);
    args.extend(["--shard", "0/256"]);
    ok(&psa_esp(&args));
    assert_eq!(files_named(&out, RunFiles::CHAMPION).len(), 1);
    // Random starts on task 2, through the command line: refused before
    // any run, nothing written.
    let out = dir.path().join("random");
    refused(
        &psa_esp(&tiny_sweep(&out, "2", &["problem.random_init=true,false"])),
        &["task 2", "random"],
    );
    assert!(files_named(&out, RunFiles::RECORDS).is_empty());
    // Random starts on task 2: refused before any run.
    let err = sweep_of(grid(&["baseline"], &[Task::Turn]), &["problem.random_init=true,false"]).unwrap_err();
    let err = format!("{err:#}");
    assert!(err.contains("task 2") && err.contains("random"), "{err}");
}

#[test]
fn a_huge_vary_list_is_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sweep");
    let list = |key: &str, n: usize| {
        let values: Vec<String> = (1..=n).map(|i| i.to_string()).collect();
        format!("{key}={}", values.join(","))
    };
    let long = list("esp.stagnation", 20_000);
    let mut args = tiny_sweep(&out, "1", &[&long]);
    args.extend(["--mode", "one-at-a-time"]);
    let o = run_within(&args, Duration::from_secs(20)).expect("refused within 20 s");
    refused(&o, &["esp.stagnation", "at most 10000"]);
    // 10^12 variants of four lists of 1000 values: counted, not compared.
    let lists: Vec<String> = [
        "esp.stagnation",
        "esp.burst_scale",
        "problem.steps",
        "esp.lesion_threshold",
    ]
    .iter()
    .map(|k| list(k, 1000))
    .collect();
    let vary: Vec<&str> = lists.iter().map(String::as_str).collect();
    let o = run_within(&tiny_sweep(&out, "1", &vary), Duration::from_secs(20)).expect("refused within 20 s");
    refused(&o, &["1000000000000 variants"]);
    assert!(!out.exists());
}
