//! Hostile input never kills, hangs or exhausts the tool: every
//! row runs the built binary on input a careless user or an attacker might
//! give and expects exit code 2 and a message naming the offending key or
//! argument, within a time limit (a hang is killed and fails the test) and
//! an address-space limit (runaway allocation fails fast instead of
//! swapping the machine).
//!
//! The classes of the issue: (1) values that made ODE abort the process,
//! (2) counts that sized memory without bound, (3) loops that never ended
//! (Cauchy rejection, thread counts, FIFOs and other non-regular input
//! files), (4) counts whose arithmetic overflowed.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use esp_neuroevolution::network::Network;
use psa_sim::psa::{NetworkFile, PsaSettings, SensorSettings, Task};

/// The most one row may take; each takes well under a second.
const TIME_LIMIT: Duration = Duration::from_secs(60);
/// The address space one row may use (ulimit -v, KiB): 4 GiB.
const MEMORY_LIMIT_KIB: u64 = 4 << 20;

/// One row: which class of the issue, the arguments, and what the error
/// message must contain.
struct Case {
    class: u8,
    args: Vec<String>,
    needle: String,
}

/// How a row ended.
struct Outcome {
    code: Option<i32>,
    stderr: String,
    elapsed: Duration,
}

/// Runs the binary with `args` under [`MEMORY_LIMIT_KIB`]; kills it after
/// [`TIME_LIMIT`] and returns `None` then.
fn run_limited(args: &[String]) -> Option<Outcome> {
    run_under(&format!("ulimit -v {MEMORY_LIMIT_KIB}"), args)
}

/// Runs the binary with `args` after the shell command `limits` (ulimit
/// settings); kills it after [`TIME_LIMIT`] and returns `None` then.
fn run_under(limits: &str, args: &[String]) -> Option<Outcome> {
    let start = Instant::now();
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!("{limits} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_psa-esp"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start psa-esp");
    let mut pipe = child.stderr.take().expect("stderr is piped");
    let reader = std::thread::spawn(move || {
        let mut text = String::new();
        let _ = pipe.read_to_string(&mut text);
        text
    });
    loop {
        if let Some(status) = child.try_wait().expect("wait for psa-esp") {
            let stderr = reader.join().expect("stderr reader");
            return Some(Outcome {
                code: status.code(),
                stderr,
                elapsed: start.elapsed(),
            });
        }
        if start.elapsed() > TIME_LIMIT {
            child.kill().expect("kill psa-esp");
            child.wait().expect("reap psa-esp");
            return None;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// Input files the rows point at.
struct Fixtures {
    dir: tempfile::TempDir,
    network: PathBuf,
    fifo: PathBuf,
    fifo_grid: PathBuf,
    huge_seeds_grid: PathBuf,
    big_file: PathBuf,
    configs: usize,
}

impl Fixtures {
    fn new() -> Fixtures {
        let dir = tempfile::tempdir().unwrap();
        let network = dir.path().join("net.json");
        save_network(&network, SensorSettings::default());
        let fifo = dir.path().join("fifo");
        make_fifo(&fifo);
        // A grid folder whose grid.json is a FIFO, and one whose grid.json
        // asks for 1e18 seeds.
        let fifo_grid = dir.path().join("fifo-grid");
        std::fs::create_dir(&fifo_grid).unwrap();
        make_fifo(&fifo_grid.join("grid.json"));
        let huge_seeds_grid = dir.path().join("huge-grid");
        std::fs::create_dir(&huge_seeds_grid).unwrap();
        let grid = psa_experiment::grid::GridSpec::from_preset(psa_experiment::grid::GridPreset::Quick);
        let mut json = serde_json::to_value(&grid).unwrap();
        json["seeds"] = serde_json::json!(1_000_000_000_000_000_000u64);
        std::fs::write(huge_seeds_grid.join("grid.json"), json.to_string()).unwrap();
        // A configuration file of 100 MiB (sparse: no disk used).
        let big_file = dir.path().join("big.toml");
        std::fs::File::create(&big_file).unwrap().set_len(100 << 20).unwrap();
        Fixtures {
            dir,
            network,
            fifo,
            fifo_grid,
            huge_seeds_grid,
            big_file,
            configs: 0,
        }
    }

    fn path(&self, name: &str) -> String {
        self.dir.path().join(name).display().to_string()
    }

    /// `evolve` with a configuration file holding `toml` (and `extra` arguments).
    fn evolve_config(&mut self, toml: &str, extra: &[&str]) -> Vec<String> {
        self.configs += 1;
        let config = self.dir.path().join(format!("config{}.toml", self.configs));
        std::fs::write(&config, toml).unwrap();
        let mut args = strings(&[
            "evolve",
            "--task",
            "1",
            "--config",
            &config.display().to_string(),
            "--out",
            &self.path(&format!("evolve{}", self.configs)),
        ]);
        args.extend(strings(extra));
        args
    }

    fn replay(&self, extra: &[&str]) -> Vec<String> {
        let mut args = strings(&[
            "replay",
            &self.network.display().to_string(),
            "--out",
            &self.path("replay"),
        ]);
        args.extend(strings(extra));
        args
    }
}

fn strings(args: &[&str]) -> Vec<String> {
    args.iter().map(|s| s.to_string()).collect()
}

fn make_fifo(path: &Path) {
    let status = Command::new("mkfifo").arg(path).status().expect("run mkfifo");
    assert!(status.success(), "mkfifo {}", path.display());
}

fn save_network(path: &Path, scaling: SensorSettings) {
    let network = Network::from_genes(7, 4, vec![0.5; 2 * 11]).unwrap();
    let problem = PsaSettings {
        sensors: scaling,
        ..PsaSettings::default()
    };
    NetworkFile::new(
        &network,
        Task::StopRotation,
        &problem,
        &psa_experiment::build_info(),
        serde_json::Map::new(),
    )
    .save(path)
    .unwrap();
}

/// Every row of the suite.
fn cases(f: &mut Fixtures) -> Vec<Case> {
    let mut cases = Vec::new();
    let mut add = |class: u8, args: Vec<String>, needle: &str| {
        cases.push(Case {
            class,
            args,
            needle: needle.to_string(),
        })
    };
    let sim = |extra: &[&str]| {
        let mut args = strings(&["simulate", "--thrust", "1,1,1,1", "--steps", "5"]);
        args.extend(strings(extra));
        args
    };
    let net = f.network.display().to_string();
    let fifo = f.fifo.display().to_string();
    let out = f.path("grid-out");

    // 1. Values that made ODE abort (and the other backends write inf/NaN).
    for backend in ["ode", "native", "rapier"] {
        add(
            1,
            sim(&["--backend", backend, "--start=0,0,0,0,0,1e160"]),
            "--start omega",
        );
    }
    add(1, sim(&["--start=1e300,0,0,0,0,0"]), "--start x");
    add(1, sim(&["--start=0,0,0,0,1e200,0"]), "--start vy");
    add(1, sim(&["--start=0,0,nan,0,0,0"]), "--start heading");
    add(1, sim(&["--dt", "1e300"]), "--dt");
    add(1, sim(&["--dt", "1e-300"]), "--dt");
    add(1, sim(&["--dt", "inf"]), "--dt");
    add(
        1,
        strings(&["crosscheck", "--dt", "1e300", "--sequences", "2", "--steps", "5"]),
        "--dt",
    );
    add(
        1,
        strings(&["crosscheck", "--dt", "5", "--sequences", "2", "--steps", "5"]),
        "--dt",
    );
    for backend in ["ode", "native", "rapier"] {
        add(
            1,
            f.evolve_config("[problem.body]\nmax_force = 1e308\n", &["--backend", backend]),
            "max_force",
        );
        add(
            1,
            f.evolve_config("[problem.tasks]\ntask1_spin = 1e200\n", &["--backend", backend]),
            "task1_spin",
        );
    }
    for (toml, needle) in [
        ("[problem.physics]\ndt = 1e300\n", "physics.dt"),
        ("[problem.body]\ndensity = 1e300\n", "density"),
        ("[problem.body]\nhull_radius = 1e-300\n", "hull_radius"),
        ("[problem.body]\nthruster_size = [1e200, 0.02, 0.02]\n", "thruster_size"),
        ("[problem.body]\nmount_radius = -inf\n", "mount_radius"),
        ("[problem.tasks]\ntask3_speed = 1e200\n", "task3_speed"),
        ("[problem.tasks]\ntask3_distance = -1e300\n", "task3_distance"),
        (
            "[problem.tasks]\ntask2_target_heading = 1e300\n",
            "task2_target_heading",
        ),
        (
            "[problem.tasks]\ntask3_random_distance = [0.0, 1e300]\n",
            "task3_random_distance",
        ),
        ("[problem.sensors]\nposition_scale = 1e300\n", "position_scale"),
        ("[problem.noise]\ninput_sd = 1e300\n", "input_sd"),
        ("[problem.fitness]\nbox_half_width = inf\n", "box_half_width"),
        (
            "[problem.physics]\nrapier_solver_iterations = 4000000000\n",
            "rapier_solver_iterations",
        ),
        (
            "[problem.physics]\nquick_step_iterations = 4000000000\n",
            "quick_step_iterations",
        ),
    ] {
        add(1, f.evolve_config(toml, &[]), needle);
    }
    add(1, f.replay(&["--input-noise", "1e300"]), "--input-noise");
    add(1, f.replay(&["--output-noise", "-1"]), "--output-noise");
    let scaled = f.dir.path().join("scaled.json");
    save_network(
        &scaled,
        SensorSettings {
            velocity_scale: 1e300,
            ..SensorSettings::default()
        },
    );
    add(
        1,
        strings(&["replay", &scaled.display().to_string(), "--out", &f.path("replay2")]),
        "velocity_scale",
    );

    // 2. Counts that sized memory without bound.
    add(2, sim(&["--steps", "100000000000"]), "--steps");
    add(2, f.replay(&["--trials", "1000000000000"]), "--trials");
    add(
        2,
        strings(&["replicate", "--seeds", "18446744073709551615", "--out", &out]),
        "--seeds",
    );
    add(
        2,
        strings(&["replicate", "--generations", "1000000000000", "--out", &out]),
        "--generations",
    );
    add(
        2,
        strings(&["replicate", "--robustness-trials", "1000000000000", "--out", &out]),
        "--robustness-trials",
    );
    add(
        2,
        strings(&["crosscheck", "--sequences", "1000000000000", "--steps", "5"]),
        "--sequences",
    );
    add(2, strings(&["bench", "--networks", "1000000000000"]), "--networks");
    add(2, strings(&["bench", "--rounds", "1000000000000"]), "--rounds");
    add(2, strings(&["bench", "--steps", "1000000000000000"]), "--steps");
    for (toml, needle) in [
        ("[esp]\nsubpop_size = 1000000\n", "subpop_size"),
        ("[esp]\ninitial_hidden = 1000000\n", "initial_hidden"),
        ("[esp]\ntrials_per_neuron = 1000000\n", "trials_per_neuron"),
        (
            "[esp]\ntrials_per_neuron = 1000\nsubpop_size = 10000\n",
            "networks per generation",
        ),
        ("[esp]\ngenerations = 1000000000000\n", "esp.generations"),
        (
            "algorithm = \"hill_climb\"\n[hill_climb]\ncandidates = 1000000\n",
            "candidates",
        ),
        ("algorithm = \"hill_climb\"\n[hill_climb]\nhidden = 1000000\n", "hidden"),
        ("[problem]\nsteps = 1000000000000\n", "steps"),
        ("[problem]\ntrials = 1000000000000\n", "trials"),
    ] {
        add(2, f.evolve_config(toml, &[]), needle);
    }
    add(
        2,
        strings(&["report", &f.huge_seeds_grid.display().to_string()]),
        "seeds",
    );
    add(
        2,
        strings(&["replicate", "--out", &f.huge_seeds_grid.display().to_string()]),
        "seeds",
    );
    let big = f.big_file.display().to_string();
    add(
        2,
        strings(&["evolve", "--task", "1", "--config", &big, "--out", &f.path("big-out")]),
        "more than",
    );
    add(2, strings(&["simulate", "--thrust-file", &big]), "more than");

    // 3. Loops that never ended.
    for (toml, needle) in [
        ("[esp]\nmutation_scale = 1e308\n", "mutation_scale"),
        ("[esp]\nburst_scale = 1e308\n", "burst_scale"),
        ("[esp]\nburst_scale = 100000.0\n", "cauchy_limit"),
        ("[esp]\ncauchy_limit = 1e-300\n", "cauchy_limit"),
        ("[esp]\ninit_range = 1e300\n", "init_range"),
        ("algorithm = \"hill_climb\"\n[hill_climb]\nalpha = 1e308\n", "alpha"),
        (
            "algorithm = \"hill_climb\"\n[hill_climb]\nalpha = 1000.0\n",
            "cauchy_limit",
        ),
        (
            "algorithm = \"hill_climb\"\n[hill_climb]\nanneal_alpha = 1.1\n",
            "cauchy_limit",
        ),
        (
            "algorithm = \"hill_climb\"\n[hill_climb]\ncauchy_limit = 1e300\n",
            "cauchy_limit",
        ),
    ] {
        add(3, f.evolve_config(toml, &[]), needle);
    }
    add(
        3,
        strings(&["evolve", "--task", "1", "--threads", "1000000", "--out", &f.path("t")]),
        "--threads",
    );
    add(
        3,
        strings(&["replicate", "--threads", "1000000", "--out", &out]),
        "--threads",
    );
    add(
        3,
        strings(&["evolve", "--task", "1", "--config", &fifo, "--out", &f.path("fifo-out")]),
        "FIFO",
    );
    add(3, strings(&["replay", &fifo, "--out", &f.path("fifo-replay")]), "FIFO");
    add(3, strings(&["simulate", "--thrust-file", &fifo]), "FIFO");
    add(3, strings(&["report", &f.fifo_grid.display().to_string()]), "FIFO");
    add(
        3,
        strings(&["replicate", "--out", &f.fifo_grid.display().to_string()]),
        "FIFO",
    );
    add(
        3,
        strings(&["evolve", "--task", "1", "--config", "/dev/zero", "--out", &f.path("z")]),
        "a device",
    );
    add(3, strings(&["replay", "/dev/zero", "--out", &f.path("z2")]), "a device");
    add(3, strings(&["simulate", "--thrust-file", "/dev/zero"]), "a device");
    add(
        3,
        strings(&[
            "evolve",
            "--task",
            "1",
            "--config",
            &f.dir.path().display().to_string(),
            "--out",
            &f.path("d"),
        ]),
        "a directory",
    );
    add(
        3,
        strings(&["replay", &f.dir.path().display().to_string(), "--out", &f.path("d2")]),
        "a directory",
    );

    // 4. Counts whose arithmetic overflowed.
    add(4, sim(&["--steps", "18446744073709551615"]), "--steps");
    add(
        4,
        strings(&["crosscheck", "--steps", "18446744073709551615", "--sequences", "2"]),
        "--steps",
    );
    add(
        4,
        strings(&[
            "evolve",
            "--task",
            "1",
            "--generations",
            "18446744073709551615",
            "--out",
            &f.path("g"),
        ]),
        "--generations",
    );
    add(
        4,
        strings(&[
            "replay",
            &net,
            "--trials",
            "18446744073709551615",
            "--out",
            &f.path("r"),
        ]),
        "--trials",
    );
    add(
        4,
        f.evolve_config("[problem]\nsteps = 9223372036854775807\n", &[]),
        "steps",
    );
    add(4, f.evolve_config("[esp]\nsubpop_size = -1\n", &[]), "subpop_size");
    cases
}

#[test]
fn hostile_input_gets_exit_2_and_a_message_naming_it_in_time() {
    let mut fixtures = Fixtures::new();
    let cases = cases(&mut fixtures);
    assert!(cases.len() >= 60, "{} rows", cases.len());
    for class in 1..=4 {
        assert!(cases.iter().any(|c| c.class == class), "no row of class {class}");
    }
    for command in [
        "simulate",
        "crosscheck",
        "evolve",
        "replicate",
        "report",
        "replay",
        "bench",
    ] {
        assert!(cases.iter().any(|c| c.args[0] == command), "no row for {command}");
    }
    let mut failures = Vec::new();
    let mut slowest = Duration::ZERO;
    for case in &cases {
        let shown = format!("class {}: psa-esp {}", case.class, case.args.join(" "));
        match run_limited(&case.args) {
            None => failures.push(format!("{shown}: still running after {TIME_LIMIT:?}, killed")),
            Some(o) => {
                slowest = slowest.max(o.elapsed);
                let message_ok = o.stderr.contains(&case.needle) && !o.stderr.contains("panicked");
                if o.code != Some(2) || !message_ok {
                    failures.push(format!(
                        "{shown}: exit {:?}, expected 2 and a message naming {:?}; stderr:\n{}",
                        o.code, case.needle, o.stderr
                    ));
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} rows failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
    eprintln!("{} rows, slowest {slowest:?}", cases.len());
}

#[test]
fn refused_runs_leave_results_already_written_intact() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("trajectory.csv");
    std::fs::write(&csv, "earlier results\n").unwrap();
    let o = run_limited(&strings(&[
        "simulate",
        "--thrust",
        "1,0,0,0",
        "--start=0,0,0,0,0,1e160",
        "--out",
        &csv.display().to_string(),
    ]))
    .expect("ends in time");
    assert_eq!(o.code, Some(2), "{}", o.stderr);
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), "earlier results\n");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "no stray files");
}

#[test]
fn a_long_simulation_streams_instead_of_holding_its_trajectory() {
    // 2 million steps held in memory would need about 400 MB (states 96 MB,
    // commands 112 MB, the CSV text 200 MB); the process may have 64 MiB of
    // data (heap), so only a streamed trajectory fits.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("long.csv");
    let o = run_under(
        "ulimit -d 65536",
        &strings(&[
            "simulate",
            "--backend",
            "native",
            "--thrust",
            "0,0,0,0",
            "--steps",
            "2000000",
            "--out",
            &out.display().to_string(),
        ]),
    )
    .expect("ends in time");
    assert_eq!(o.code, Some(0), "{}", o.stderr);
    let lines = std::io::BufRead::lines(std::io::BufReader::new(std::fs::File::open(&out).unwrap())).count();
    assert_eq!(lines, 2_000_002, "header, start and 2,000,000 steps");
}
