//! Nothing silent: every setting a command takes either acts
//! or is refused, old results stay readable, and no output path can
//! clobber the system. One test (or a few) per defect of the issue, each
//! named after what it holds.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use esp_neuroevolution::network::Network;
use psa_experiment::grid::sweep::{parse_vary, SweepMode, SweepSpec, MAX_VARIANT_NAME};
use psa_experiment::grid::{run_dir, GridPreset, GridSpec, RunKey};
use psa_experiment::RunFiles;
use psa_sim::physics::{BackendKind, StartQuaternion};
use psa_sim::psa::settings::defaults::{value_at, Placement, BUILDS, CHANGES};
use psa_sim::psa::{FitnessState, HeadingWrap, NetworkFile, PsaSettings, Scoring, Task};

use common::psa_esp;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn ok(o: &Output) -> String {
    assert!(o.status.success(), "exit {:?}: {}", o.status.code(), stderr(o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Asserts exit code 2 and a message holding every one of `needles`.
fn refused(o: &Output, needles: &[&str]) -> String {
    let text = stderr(o);
    assert_eq!(o.status.code(), Some(2), "expected exit 2: {text}");
    for needle in needles {
        assert!(text.contains(needle), "the message lacks {needle:?}: {text}");
    }
    assert!(!text.contains("panicked"), "{text}");
    text
}

/// Runs the binary with `args`, killed after `limit` (then `None`).
fn run_within(args: &[&str], limit: Duration) -> Option<Output> {
    let mut child = Command::new(common::binary())
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            child.kill().unwrap();
            child.wait().unwrap();
            return None;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    Some(child.wait_with_output().unwrap())
}

fn make_fifo(path: &Path) {
    assert!(Command::new("mkfifo").arg(path).status().unwrap().success());
}

/// The full hash of the parent of `commit` (a prefix), from the history
/// the table of defaults places builds in.
fn parent_of(commit: &str) -> String {
    let line = BUILDS
        .lines()
        .find(|l| l.starts_with(commit))
        .expect("a commit of the history");
    line.split(' ').nth(1).expect("a parent").to_string()
}

/// A process id that no process has now: a child that has ended.
fn dead_pid() -> u32 {
    let mut child = Command::new("true").spawn().unwrap();
    let pid = child.id();
    child.wait().unwrap();
    pid
}

/// A finished tiny grid (baseline, task 1, one seed, 3 generations), made
/// once; each test copies it.
fn finished_grid() -> &'static Path {
    static GRID: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    let (_, path) = GRID.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("grid");
        ok(&psa_esp(&tiny_args(&out)));
        (dir, out)
    });
    path
}

fn tiny_args(out: &Path) -> Vec<&'static str> {
    let out = Box::leak(out.display().to_string().into_boxed_str());
    vec![
        "replicate",
        "--preset",
        "quick",
        "--configs",
        "baseline",
        "--tasks",
        "1",
        "--seeds",
        "1",
        "--generations",
        "3",
        "--robustness-trials",
        "3",
        "--threads",
        "1",
        "--quiet",
        "--out",
        out,
    ]
}

/// A copy of the finished tiny grid in `dir`.
fn copy_of_grid(dir: &Path) -> PathBuf {
    let copy = dir.join("grid");
    let status = Command::new("cp")
        .arg("-a")
        .arg(finished_grid())
        .arg(&copy)
        .status()
        .unwrap();
    assert!(status.success());
    copy
}

fn run_folder(grid: &Path) -> PathBuf {
    run_dir(
        grid,
        &RunKey {
            config: "baseline".parse().unwrap(),
            task: Task::StopRotation,
            seed: 1,
        },
    )
}

fn names_in(dir: &Path) -> Vec<String> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut names: Vec<String> = entries
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

// 1. Output paths.

#[test]
fn an_output_path_that_is_a_link_a_fifo_or_a_device_is_refused_and_left_as_it_was() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("precious.txt");
    std::fs::write(&target, "precious\n").unwrap();
    let link = dir.path().join("link.csv");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let fifo = dir.path().join("fifo.csv");
    make_fifo(&fifo);
    let simulate = |out: &Path| {
        psa_esp(&[
            "simulate",
            "--thrust",
            "1,0,0,0",
            "--steps",
            "3",
            "--out",
            out.to_str().unwrap(),
        ])
    };
    refused(
        &simulate(&link),
        &["link.csv", "a symbolic link", "regular file or a new name"],
    );
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "precious\n");
    refused(&simulate(&fifo), &["fifo.csv", "a FIFO"]);
    assert!(std::os::unix::fs::FileTypeExt::is_fifo(
        &std::fs::symlink_metadata(&fifo).unwrap().file_type()
    ));
    // A regular file is replaced whole, a new name created; nothing else is left.
    ok(&simulate(&target));
    ok(&simulate(&dir.path().join("new.csv")));
    assert_eq!(
        names_in(dir.path()),
        ["fifo.csv", "link.csv", "new.csv", "precious.txt"]
    );
    // Output folders: a file (or a link to one) is not a folder.
    let out = target.display().to_string();
    refused(
        &psa_esp(&["evolve", "--task", "1", "--generations", "1", "--out", &out]),
        &["precious.txt"],
    );
    let grid_link = dir.path().join("grid-link");
    std::os::unix::fs::symlink(&target, &grid_link).unwrap();
    refused(&psa_esp(&tiny_args(&grid_link)), &["grid-link", "not a directory"]);
}

// 2. A file that lacks a setting gets the value of the build that wrote it.

fn network_json(problem: &PsaSettings) -> serde_json::Value {
    let network = Network::from_genes(7, 4, vec![0.25; 2 * 11]).unwrap();
    let file = NetworkFile::new(
        &network,
        Task::StopRotation,
        problem,
        &psa_experiment::build_info(),
        serde_json::Map::new(),
    );
    serde_json::to_value(&file).unwrap()
}

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

fn load_json(dir: &Path, json: &serde_json::Value) -> Result<PsaSettings, String> {
    let path = dir.join("net.json");
    std::fs::write(&path, json.to_string()).unwrap();
    NetworkFile::load(&path)
        .map(|(file, _)| file.problem.unwrap())
        .map_err(|e| e.to_string())
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

/// The model before the refit (`configs/positive-heading.toml`): its build
/// wrote every problem setting and the size of its table of defaults,
/// four rows short of today's (the refit's task-2 spin, the
/// hill-climber's two alpha rows and task 2's clockwise start).
const POSITIVE_HEADING_ROWS: usize = 4;

#[test]
fn a_task_2_champion_of_the_model_before_the_refit_replays_to_its_recorded_fitness_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let (recorded, mut old) = champion_of(dir.path(), "run", "configs/positive-heading.toml", "2");
    assert_eq!(old["problem"]["tasks"]["task2_spin"], 0.75, "the model's own start");
    old["provenance"]["defaults"] = (psa_sim::psa::settings::defaults::rows() - POSITIVE_HEADING_ROWS).into();
    let replayed = replayed(dir.path(), "old", &old);
    assert_eq!(replayed.to_bits(), recorded.to_bits(), "{replayed} against {recorded}");
}

// 3. Settings that do nothing act or are refused.

/// The arguments of a tiny sweep on `tasks` into `out`, varying each of
/// `vary`: the tiny grid's (`tiny_args`) as a sweep.
fn tiny_sweep<'a>(out: &Path, tasks: &'a str, vary: &[&'a str]) -> Vec<&'a str> {
    let mut args = tiny_args(out);
    args[0] = "sweep";
    let at = args.iter().position(|a| *a == "--tasks").unwrap();
    args[at + 1] = tasks;
    for v in vary {
        args.extend(["--vary", v]);
    }
    args
}

/// Every file called `name` under `dir`, sorted.
fn files_named(dir: &Path, name: &str) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).into_iter().flatten() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.file_name().is_some_and(|n| n == name) {
                found.push(path);
            }
        }
    }
    found.sort();
    found
}

fn grid(configs: &[&str], tasks: &[Task]) -> GridSpec {
    GridSpec {
        configs: configs.iter().map(|c| c.parse().unwrap()).collect(),
        tasks: tasks.to_vec(),
        seeds: 1,
        first_seed: 1,
        generations: 3,
        robustness_trials: 3,
        ..GridSpec::from_preset(GridPreset::Quick)
    }
}

fn sweep_of(grid: GridSpec, vary: &[&str]) -> anyhow::Result<SweepSpec> {
    let vary = vary.iter().map(|v| parse_vary(v)).collect::<anyhow::Result<Vec<_>>>()?;
    SweepSpec::new(grid, vary, SweepMode::Combinations)
}

#[test]
fn a_varied_backend_or_generation_count_is_the_variant_grids_own() {
    let spec = sweep_of(
        grid(&["baseline"], &[Task::StopRotation]),
        &["problem.backend=native,rapier"],
    )
    .unwrap();
    let backends: Vec<BackendKind> = spec
        .variants()
        .iter()
        .map(|v| spec.variant_grid(v).unwrap().backend)
        .collect();
    assert_eq!(backends, [BackendKind::Native, BackendKind::Rapier]);
    let spec = sweep_of(grid(&["baseline"], &[Task::StopRotation]), &["esp.generations=3,4"]).unwrap();
    let generations: Vec<usize> = spec
        .variants()
        .iter()
        .map(|v| spec.variant_grid(v).unwrap().generations)
        .collect();
    assert_eq!(generations, [3, 4]);
    // Through the command line: each variant's runs evolve for its own
    // number of generations.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sweep");
    let mut args = tiny_sweep(&out, "1", &["esp.generations=3,4"]);
    let at = args.iter().position(|a| *a == "--generations").unwrap();
    args.drain(at..at + 2);
    ok(&psa_esp(&args));
    let lines: Vec<usize> = files_named(&out, RunFiles::RECORDS)
        .iter()
        .map(|f| std::fs::read_to_string(f).unwrap().lines().count())
        .collect();
    assert_eq!(lines.len(), 2, "{lines:?}");
    assert_eq!(
        lines[1],
        lines[0] + 1,
        "4 generations record one more than 3: {lines:?}"
    );
    // In a grid's own settings they are refused: the grid sets them.
    let mut own = grid(&["baseline"], &[Task::StopRotation]);
    own.overrides = Some("[problem]\nbackend = \"ode\"\n".into());
    let err = format!("{:#}", own.check_new().unwrap_err());
    assert!(err.contains("problem.backend") && err.contains("--backend"), "{err}");
}

#[test]
fn a_varied_setting_that_changes_no_run_is_refused_naming_it() {
    // The input-noise configuration sets the input noise itself.
    let err = sweep_of(
        grid(&["input-noise"], &[Task::StopRotation]),
        &["problem.noise.input_sd=0.0,0.1"],
    )
    .unwrap_err();
    let err = format!("{err:#}");
    assert!(
        err.contains("problem.noise.input_sd") && err.contains("changes nothing"),
        "{err}"
    );
    // 1 and 1.0 are one value.
    let err = format!("{:#}", parse_vary("problem.tasks.task1_spin=1,1.0").unwrap_err());
    assert!(err.contains("same value"), "{err}");
    // A table and a key inside it: one would silently win.
    let err = sweep_of(
        grid(&["baseline"], &[Task::StopRotation]),
        &[
            "problem.fitness.scoring=original,evolution",
            "problem.fitness={ kind = \"original\" },{ kind = \"incremental\" }",
        ],
    )
    .unwrap_err();
    let err = format!("{err:#}");
    assert!(err.contains("problem.fitness") && err.contains("overlap"), "{err}");
    // The command line refuses them before anything is written.
    let dir = tempfile::tempdir().unwrap();
    for (vary, needles) in [
        (
            "problem.tasks.task1_spin=1,1.0",
            ["problem.tasks.task1_spin", "same value"],
        ),
        (
            "problem.noise.input_sd=0.0,0.1",
            ["problem.noise.input_sd", "changes nothing"],
        ),
    ] {
        let out = dir.path().join("sweep");
        let mut args = tiny_sweep(&out, "1", &[vary]);
        if vary.starts_with("problem.noise") {
            let at = args.iter().position(|a| *a == "baseline").unwrap();
            args[at] = "input-noise";
        }
        refused(&psa_esp(&args), &needles);
        assert!(!out.exists(), "{vary}: nothing written");
    }
}

#[test]
fn a_rescoring_setting_that_changes_no_test_is_refused_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let source = copy_of_grid(dir.path());
    for (toml, key) in [
        ("[problem.noise]\ninput_sd = 0.2\n", "problem.noise.input_sd"),
        ("[problem.noise]\noutput_sd = 0.2\n", "problem.noise.output_sd"),
        ("[problem]\nrandom_init = true\n", "problem.random_init"),
        ("[problem.fitness]\nkind = \"original\"\n", "problem.fitness.kind"),
    ] {
        rescore_is_refused_as_changing_nothing(dir.path(), &source, toml, key);
    }
}

// 4. Grids of earlier builds stay readable.

/// Makes the run of the grid in `grid` look written by the build before
/// `changed`: its config.toml without the table's keys, its run.json
/// naming that build.
fn age_run(grid: &Path, changed: &str) {
    age_run_folder(&run_folder(grid), changed);
}

/// [`age_run`] for the run in `folder`.
fn age_run_folder(folder: &Path, changed: &str) {
    let text = std::fs::read_to_string(folder.join("config.toml")).unwrap();
    let mut table: toml::Table = toml::from_str(&text).unwrap();
    for row in CHANGES {
        let mut parts: Vec<&str> = row.key.split('.').collect();
        let last = parts.pop().unwrap();
        let mut at = Some(&mut table);
        for part in parts {
            at = at.and_then(|t| t.get_mut(part)).and_then(|v| v.as_table_mut());
        }
        if let Some(t) = at {
            t.remove(last);
        }
    }
    std::fs::write(folder.join("config.toml"), toml::to_string(&table).unwrap()).unwrap();
    let path = folder.join("run.json");
    let mut run: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let build = run["build"].as_object_mut().unwrap();
    build.remove("defaults");
    build.insert("git_commit".into(), parent_of(changed).into());
    std::fs::write(&path, serde_json::to_string_pretty(&run).unwrap()).unwrap();
}

#[test]
fn a_report_says_above_its_tables_when_its_runs_flew_different_models() {
    let dir = tempfile::tempdir().unwrap();
    let grid = dir.path().join("grid");
    let mut args = tiny_args(&grid);
    let at = args.iter().position(|a| *a == "--seeds").unwrap();
    args[at + 1] = "2";
    ok(&psa_esp(&args));
    // Seed 2 as a build before the positive heading wrap wrote it: counted
    // (this grid under its build's defaults), but another model.
    age_run_folder(&grid.join("runs/baseline/task1/seed2"), "a70d696");
    let o = psa_esp(&["report", grid.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("mixed models"), "{}", stderr(&o));
    let md = std::fs::read_to_string(grid.join("report.md")).unwrap();
    let banner = md.lines().find(|l| l.starts_with("**MIXED MODELS")).expect("a banner");
    assert!(
        banner.contains("baseline task 1: `problem.sensors.position_scale` = 10.0 in 1 (seeds 2), 5.0 in 1 (seeds 1)"),
        "{banner}"
    );
    assert!(md.find("**MIXED MODELS").unwrap() < md.find("## Grid").unwrap());
    // One model: no banner.
    std::fs::remove_dir_all(grid.join("runs/baseline/task1/seed2")).unwrap();
    ok(&psa_esp(&args));
    let o = psa_esp(&["report", grid.to_str().unwrap()]);
    assert!(!stderr(&o).contains("mixed models"));
}

#[test]
fn a_grid_of_an_earlier_build_is_reported_and_resuming_it_names_the_setting_and_the_build() {
    let dir = tempfile::tempdir().unwrap();
    let grid = copy_of_grid(dir.path());
    age_run(&grid, "a70d696");
    let report = psa_esp(&["report", grid.to_str().unwrap(), "--format", "json"]);
    ok(&report);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(grid.join("report.json")).unwrap()).unwrap();
    assert_eq!(json["runs_counted"], 1, "{}", stderr(&report));
    let readings = json["readings"].to_string();
    assert!(
        readings.contains("(-pi, pi]"),
        "the run's own heading range: {readings}"
    );
    // Resuming with this build's defaults: refused, naming the settings
    // (one its build did not have yet, read from the table) and the build.
    refused(
        &psa_esp(&tiny_args(&grid)),
        &[
            "esp.stagnation = 40 there",
            "position_scale = 10.0 there",
            &parent_of("a70d696"),
        ],
    );
    // Re-scoring reads it too, under its own model.
    let config = dir.path().join("rescore.toml");
    std::fs::write(&config, "[problem.fitness]\nscoring = \"incremental\"\n").unwrap();
    let out = dir.path().join("rescored");
    ok(&psa_esp(&[
        "rescore",
        grid.to_str().unwrap(),
        "--config",
        config.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]));
    ok(&psa_esp(&["report", out.to_str().unwrap()]));
}

// 5. Sweeps are counted before they are built.

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

// 6. One run counted once.

#[test]
fn a_configuration_or_task_listed_twice_is_refused_and_an_old_grid_counts_each_run_once() {
    let dir = tempfile::tempdir().unwrap();
    for (flag, list, needle) in [
        (
            "--configs",
            "baseline,baseline",
            "configuration baseline is listed twice",
        ),
        ("--tasks", "1,1", "task 1 is listed twice"),
    ] {
        let out = dir.path().join(flag.trim_start_matches('-'));
        let mut args = tiny_args(&out);
        let at = args.iter().position(|a| *a == flag).unwrap();
        args[at + 1] = list;
        refused(&psa_esp(&args), &[needle]);
    }
    // A grid.json that lists a configuration twice (an earlier build wrote them).
    let grid = copy_of_grid(dir.path());
    let path = grid.join("grid.json");
    let mut spec: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    spec["configs"] = serde_json::json!(["baseline", "baseline"]);
    spec["tasks"] = serde_json::json!([1, 1]);
    std::fs::write(&path, spec.to_string()).unwrap();
    let loaded = GridSpec::load(&grid).unwrap();
    assert_eq!(loaded.runs().len(), 1);
    ok(&psa_esp(&["report", grid.to_str().unwrap(), "--format", "json"]));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(grid.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["runs_counted"], 1);
    assert_eq!(report["runs_expected"], 1);
}

// 7. A checkpoint is an input file under the rules of docs/limits.md.

#[test]
fn a_checkpoint_that_is_not_a_bounded_regular_file_is_refused_before_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let grid = copy_of_grid(dir.path());
    let folder = run_folder(&grid);
    std::fs::remove_file(folder.join("robustness.json")).unwrap();
    let checkpoint = folder.join("checkpoint.json");
    let mut args = tiny_args(&grid);
    args.push("--lockstep");
    type Make = fn(&Path);
    let cases: [(&str, Make, &str); 4] = [
        ("FIFO", make_fifo, "a FIFO"),
        (
            "link to /dev/zero",
            |p| std::os::unix::fs::symlink("/dev/zero", p).unwrap(),
            "symbolic link",
        ),
        (
            "70 MB",
            |p| std::fs::File::create(p).unwrap().set_len(70 << 20).unwrap(),
            "more than",
        ),
        ("directory", |p| std::fs::create_dir(p).unwrap(), "a directory"),
    ];
    for (what, make, needle) in cases {
        make(&checkpoint);
        let o = run_within(&args, Duration::from_secs(60)).unwrap_or_else(|| panic!("{what}: hangs"));
        refused(&o, &["checkpoint.json", needle]);
        assert!(!folder.join("robustness.json").exists(), "{what}: the run was not run");
        if checkpoint.is_dir() {
            std::fs::remove_dir(&checkpoint).unwrap();
        } else {
            std::fs::remove_file(&checkpoint).unwrap();
        }
    }
    // Without --lockstep too (it could be neither read nor removed).
    std::fs::create_dir(&checkpoint).unwrap();
    refused(&psa_esp(&tiny_args(&grid)), &["checkpoint.json"]);
}

#[test]
fn a_run_claimed_by_a_process_that_has_exited_but_is_not_reaped_is_run() {
    let dir = tempfile::tempdir().unwrap();
    let grid = copy_of_grid(dir.path());
    let folder = run_folder(&grid);
    std::fs::remove_file(folder.join("robustness.json")).unwrap();
    // A claimant that has exited and that its parent (this test) has not
    // reaped: /proc still lists it, as a zombie.
    let mut child = Command::new("true").spawn().unwrap();
    let pid = child.id();
    let stat = (0..500)
        .find_map(|_| {
            std::thread::sleep(Duration::from_millis(10));
            std::fs::read_to_string(format!("/proc/{pid}/stat"))
                .ok()
                .filter(|s| s.contains(") Z "))
        })
        .expect("the child shows as a zombie");
    let start: u64 = stat[stat.rfind(')').unwrap() + 1..]
        .split_whitespace()
        .nth(19)
        .unwrap()
        .parse()
        .unwrap();
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .as_secs();
    let claim = serde_json::json!({
        "host": psa_sim::provenance::host_name(),
        "pid": pid,
        "process_start": start,
        "started": "2026-12-02T00:00:00Z",
        "started_unix": now,
    });
    std::fs::write(folder.join("claim.json"), claim.to_string()).unwrap();
    let o = psa_esp(&tiny_args(&grid));
    child.wait().unwrap();
    ok(&o);
    assert!(
        folder.join("robustness.json").exists(),
        "the run was run: {}",
        stderr(&o)
    );
    assert!(!stderr(&o).contains("left to another process"), "{}", stderr(&o));
}

// 8. A finished grid holds only its documented files.

#[test]
fn what_killed_processes_left_is_cleared_when_the_grid_is_resumed_or_reported() {
    let dir = tempfile::tempdir().unwrap();
    let grid = copy_of_grid(dir.path());
    let folder = run_folder(&grid);
    let expected = names_in(&folder);
    let host = psa_sim::provenance::host_name();
    let dead = dead_pid();
    // A killed lockstep grid's claim on a finished run.
    let claim = serde_json::json!({
        "host": host,
        "pid": dead,
        "started": "2026-11-27T00:00:00Z",
        "started_unix": 1_700_000_000u64,
    });
    std::fs::write(folder.join("claim.json"), claim.to_string()).unwrap();
    // A checkpoint a lockstep process left.
    std::fs::write(folder.join("checkpoint.json"), "{}").unwrap();
    // Temporary files of killed processes, and one of a live process.
    std::fs::write(folder.join(format!(".run.json.tmp-{host}-{dead}-0")), "x").unwrap();
    std::fs::write(grid.join(format!(".report.md.tmp-{host}-{dead}-1")), "x").unwrap();
    let live = format!(".grid.json.tmp-{host}-{}-2", std::process::id());
    std::fs::write(grid.join(&live), "x").unwrap();
    ok(&psa_esp(&tiny_args(&grid)));
    assert_eq!(names_in(&folder), expected);
    assert!(grid.join(&live).exists(), "a live process's file is left");
    std::fs::write(grid.join(format!(".report.md.tmp-{host}-{dead}-3")), "x").unwrap();
    std::fs::create_dir_all(grid.join("figures")).unwrap();
    std::fs::write(
        grid.join("figures").join(format!(".f.png.tmp-{host}-{dead}-4.png")),
        "x",
    )
    .unwrap();
    ok(&psa_esp(&["report", grid.to_str().unwrap()]));
    let leftovers: Vec<String> = names_in(&grid)
        .into_iter()
        .chain(names_in(&grid.join("figures")))
        .filter(|n| n.contains(&format!("-{dead}-")))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn a_run_resumed_without_lockstep_leaves_no_checkpoint() {
    let dir = tempfile::tempdir().unwrap();
    let grid = copy_of_grid(dir.path());
    let folder = run_folder(&grid);
    let expected = names_in(&folder);
    std::fs::remove_file(folder.join("robustness.json")).unwrap();
    // A saved run that reads (of another search: another seed), as a
    // lockstep process leaves: the ordinary executor runs the run from its
    // start and removes it.
    let saved: esp_neuroevolution::AnyRun = esp_neuroevolution::Esp::new(psa_experiment::paper_esp_settings(), 99)
        .unwrap()
        .start(7, 4)
        .unwrap()
        .into();
    std::fs::write(folder.join("checkpoint.json"), serde_json::to_string(&saved).unwrap()).unwrap();
    ok(&psa_esp(&tiny_args(&grid)));
    assert_eq!(names_in(&folder), expected);
}

// 9. Sweeps are checked whole before the first run.

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

// 10. Errors for the settings of network files name the key.

#[test]
fn a_bad_value_in_a_network_file_is_named_by_its_key() {
    let dir = tempfile::tempdir().unwrap();
    for (section, key, value) in [
        ("sensors", "heading_wrap", serde_json::json!("both")),
        ("sensors", "heading_input", serde_json::json!("relative")),
        ("fitness", "scoring", serde_json::json!("best")),
        ("fitness", "state", serde_json::json!("imagined")),
        ("physics", "start_quaternion", serde_json::json!(7)),
    ] {
        let mut json = network_json(&PsaSettings::default());
        json["problem"][section][key] = value;
        let err = load_json(dir.path(), &json).unwrap_err();
        assert!(err.contains(&format!("problem.{section}.{key}")), "{err}");
    }
    let mut json = network_json(&PsaSettings::default());
    json["problem"]["exponential"] = "slow".into();
    let err = load_json(dir.path(), &json).unwrap_err();
    assert!(err.contains("problem.exponential"), "{err}");
    // Replayed from the command line, the error names the key too.
    let mut json = network_json(&PsaSettings::default());
    json["problem"]["sensors"]["heading_wrap"] = "both".into();
    let file = dir.path().join("bad.json");
    std::fs::write(&file, json.to_string()).unwrap();
    let o = psa_esp(&["replay", file.to_str().unwrap(), "--backend", "native"]);
    assert!(!o.status.success());
    let text = stderr(&o);
    assert!(
        text.contains("problem.sensors.heading_wrap") && !text.contains("panicked"),
        "{text}"
    );
}

// The rules of docs/limits.md for output paths and checkpoints.

#[test]
fn docs_limits_states_the_rules_for_output_paths_and_checkpoints() {
    let doc = std::fs::read_to_string(repo("docs/limits.md")).unwrap();
    for needle in [
        "## Output paths",
        "## Checkpoints",
        "a regular file or a new name",
        "not a directory",
        "checkpoint.json",
        "remove it to start the run afresh",
        "io::check_output_file",
        "io::create_output_dir",
        "io::remove_stale_temporaries",
        "## Settings a task does not read",
        "Task::reads_setting",
        "damaged, not a saved run",
    ] {
        assert!(doc.contains(needle), "docs/limits.md lacks {needle:?}");
    }
    // The message the page quotes is the one the tool gives.
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("x.csv");
    make_fifo(&fifo);
    let o = psa_esp(&[
        "simulate",
        "--thrust",
        "1,0,0,0",
        "--steps",
        "2",
        "--out",
        fifo.to_str().unwrap(),
    ]);
    let text = refused(&o, &[]);
    let quoted = text
        .trim()
        .trim_start_matches("error: ")
        .replace(fifo.to_str().unwrap(), "/tmp/x.csv");
    assert!(doc.contains(&quoted), "docs/limits.md should quote {quoted:?}");
}

// A run is judged on the settings its own task
// reads (`Task::reads_setting`), in every command.

/// A finished tiny grid of task 2 alone in `dir/name`.
fn task_2_grid(dir: &Path, name: &str) -> PathBuf {
    let out = dir.join(name);
    let mut args = tiny_args(&out);
    let at = args.iter().position(|a| *a == "--tasks").unwrap();
    args[at + 1] = "2";
    ok(&psa_esp(&args));
    out
}

/// Sets the `overrides` of the grid in `grid` (its grid.json) to `toml`.
fn set_grid_overrides(grid: &Path, toml: &str) {
    let path = grid.join("grid.json");
    let mut spec: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    spec["overrides"] = toml.into();
    std::fs::write(&path, serde_json::to_string_pretty(&spec).unwrap()).unwrap();
}

/// `report --format json` of `grid` (exit 1 when a run is not counted),
/// and its report.json.
fn report_json(grid: &Path) -> serde_json::Value {
    let o = psa_esp(&["report", grid.to_str().unwrap(), "--format", "json"]);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr(&o));
    serde_json::from_str(&std::fs::read_to_string(grid.join("report.json")).unwrap()).unwrap()
}

#[test]
fn a_rescoring_setting_no_task_of_the_grid_reads_is_refused_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let source = copy_of_grid(dir.path());
    for (toml, key) in [
        ("[problem.tasks]\ntask2_spin = 1.0\n", "problem.tasks.task2_spin"),
        (
            "[problem.tasks]\ntask2_velocity = [0.1, 0.0]\n",
            "problem.tasks.task2_velocity",
        ),
        ("[problem.task2]\nsteps = 100\n", "problem.task2.steps"),
    ] {
        rescore_is_refused_as_changing_nothing(dir.path(), &source, toml, key);
    }
}

#[test]
fn a_sweep_of_a_setting_no_task_of_the_grid_reads_is_refused_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    for (vary, key) in [
        ("problem.tasks.task2_spin=1.0,-1.5", "problem.tasks.task2_spin"),
        ("problem.task2.steps=100,200", "problem.task2.steps"),
    ] {
        let out = dir.path().join("sweep");
        refused(&psa_esp(&tiny_sweep(&out, "1", &[vary])), &[key, "changes nothing"]);
        assert!(!out.exists(), "{vary}: nothing written");
    }
}

#[test]
fn a_sweep_one_at_a_time_or_of_the_other_algorithms_settings_is_refused_when_its_variants_run_the_same_runs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sweep");
    let one_at_a_time = |vary: &'static [&'static str]| {
        let mut args = tiny_sweep(&out, "1", vary);
        args.extend(["--mode", "one-at-a-time"]);
        args
    };
    // Task 1 reads no task-2 start: each value runs the base's runs.
    for vary in [
        &["problem.tasks.task2_spin=1.0,-1.5"][..],
        &["problem.tasks.task2_spin=1.0"],
    ] {
        refused(
            &psa_esp(&one_at_a_time(vary)),
            &["problem.tasks.task2_spin", "changes nothing"],
        );
        assert!(!out.exists(), "{vary:?}: nothing written");
    }
    // ESP reads no hill-climber setting, the hill-climber no ESP one.
    for (vary, config, key) in [
        ("hill_climb.alpha=0.3,1.0", "baseline", "hill_climb.alpha"),
        ("esp.stagnation=20,30", "hill-climb", "esp.stagnation"),
    ] {
        let mut args = tiny_sweep(&out, "1", &[vary]);
        let at = args.iter().position(|a| *a == "--configs").unwrap();
        args[at + 1] = config;
        refused(&psa_esp(&args), &[key, "changes nothing"]);
        assert!(!out.exists(), "{vary}: nothing written");
    }
    // The base's own value, named, is a row of its own; a value that
    // changes a run is not refused.
    let ok = psa_esp(&one_at_a_time(&["problem.tasks.task1_spin=1.0,2.0"]));
    assert!(ok.status.success(), "{}", stderr(&ok));
}

#[test]
fn a_task_2_run_of_another_start_whose_build_cannot_be_placed_is_not_counted() {
    let dir = tempfile::tempdir().unwrap();
    let grid = task_2_grid(dir.path(), "grid");
    let folder = run_dir(
        &grid,
        &RunKey {
            config: "baseline".parse().unwrap(),
            task: Task::Turn,
            seed: 1,
        },
    );
    let config = folder.join("config.toml");
    let mut table: toml::Table = toml::from_str(&std::fs::read_to_string(&config).unwrap()).unwrap();
    table["problem"]["tasks"]["task2_spin"] = toml::Value::Float(1.0);
    std::fs::write(&config, toml::to_string(&table).unwrap()).unwrap();
    let path = folder.join("run.json");
    let mut run: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let build = run["build"].as_object_mut().unwrap();
    build.remove("defaults");
    build.insert("git_commit".into(), "0123456789abcdef0123456789abcdef01234567".into());
    std::fs::write(&path, serde_json::to_string_pretty(&run).unwrap()).unwrap();
    let report = report_json(&grid);
    assert_eq!(report["runs_counted"], 0, "{report}");
    let problems = report["problems"].to_string();
    assert!(problems.contains("problem.tasks.task2_spin"), "{problems}");
}

#[test]
fn a_task_1_run_is_judged_without_the_problem_task2_table() {
    let dir = tempfile::tempdir().unwrap();
    let grid = copy_of_grid(dir.path());
    let toml = "[problem.task2]\nsteps = 100\n";
    set_grid_overrides(&grid, toml);
    let report = report_json(&grid);
    assert_eq!(report["runs_counted"], 1, "{report}");
    assert_eq!(report["problems"], serde_json::json!([]), "{report}");
    // Resumed with that table: the task-1 run is finished, not refused.
    let config = dir.path().join("task2.toml");
    std::fs::write(&config, toml).unwrap();
    let mut args = tiny_args(&grid);
    args.extend(["--config", config.to_str().unwrap()]);
    ok(&psa_esp(&args));
}

#[test]
fn report_md_lists_every_setting_a_grid_changes_from_the_defaults_that_its_runs_read() {
    let dir = tempfile::tempdir().unwrap();
    let grid = copy_of_grid(dir.path());
    ok(&psa_esp(&["report", grid.to_str().unwrap()]));
    let plain = std::fs::read_to_string(grid.join("report.md")).unwrap();
    assert!(!plain.contains("changed from the defaults"), "{plain}");
    let readings = plain.lines().find(|l| l.starts_with("| readings |")).unwrap();
    assert!(
        readings.contains("task 1:") && !readings.contains("task 2") && !readings.contains("task 3"),
        "a task-1 grid's readings name task 1 only: {readings}"
    );
    // Settings the grid's task-1 run does not read: its runs are the
    // default grid's, and the label says so by naming nothing.
    set_grid_overrides(
        &grid,
        "[problem.tasks]\ntask2_spin = 1.0\ntask3_speed = 0.3\n[hill_climb]\nalpha = 1.0\n",
    );
    ok(&psa_esp(&["report", grid.to_str().unwrap()]));
    let md = std::fs::read_to_string(grid.join("report.md")).unwrap();
    assert!(!md.contains("changed from the defaults"), "{md}");
    // A setting task 1 reads is named (its run, flown without it, is then not counted).
    set_grid_overrides(&grid, "[problem.tasks]\ntask1_spin = 2.0\ntask2_spin = 1.0\n");
    let o = psa_esp(&["report", grid.to_str().unwrap()]);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr(&o));
    let md = std::fs::read_to_string(grid.join("report.md")).unwrap();
    assert!(md.contains("`problem.tasks.task1_spin = 2.0` (default 1.0)"), "{md}");
    assert!(!md.contains("task2_spin"), "{md}");
}

#[test]
fn replicate_refuses_a_configuration_setting_no_task_of_its_grid_reads() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("task2.toml");
    for (toml, key) in [
        ("[problem.tasks]\ntask2_spin = 1.0\n", "problem.tasks.task2_spin"),
        ("[problem.task2]\nsteps = 100\n", "problem.task2.steps"),
    ] {
        std::fs::write(&config, toml).unwrap();
        let out = dir.path().join("grid");
        let mut args = tiny_args(&out);
        args.extend(["--config", Box::leak(config.display().to_string().into_boxed_str())]);
        refused(&psa_esp(&args), &[key, "changes nothing", "no task of this grid (1)"]);
        assert!(!out.exists(), "{key}: nothing written");
    }
    // The setting a task of the grid reads is taken, as is the default's value.
    std::fs::write(&config, "[problem.tasks]\ntask1_spin = 2.0\ntask2_spin = -0.75\n").unwrap();
    let mut args = tiny_args(&dir.path().join("ok"));
    args.extend(["--config", Box::leak(config.display().to_string().into_boxed_str())]);
    ok(&psa_esp(&args));
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

#[test]
fn every_damaged_checkpoint_is_refused_by_one_rule() {
    let dir = tempfile::tempdir().unwrap();
    let grid = copy_of_grid(dir.path());
    let folder = run_folder(&grid);
    std::fs::remove_file(folder.join("robustness.json")).unwrap();
    let checkpoint = folder.join("checkpoint.json");
    let plain = tiny_args(&grid);
    let mut lockstep = plain.clone();
    lockstep.push("--lockstep");
    // The lockstep executor, which resumes from a checkpoint, and the
    // ordinary one, which runs a run from its start: one rule for both.
    for args in [&lockstep, &plain] {
        for (what, bytes) in [
            ("zeroed", vec![0u8; 4096]),
            ("truncated", b"{\"Esp\":{\"records\":[".to_vec()),
            ("empty", Vec::new()),
            ("garbage", vec![0xff, 0xfe, 0x00, 0x41]),
        ] {
            std::fs::write(&checkpoint, &bytes).unwrap();
            let o = run_within(args, Duration::from_secs(60)).unwrap_or_else(|| panic!("{what}: hangs"));
            refused(&o, &["checkpoint.json", "remove it to start the run afresh"]);
            assert!(!folder.join("robustness.json").exists(), "{what}: the run was not run");
            assert!(checkpoint.exists(), "{what}: the file is left for the user");
            std::fs::remove_file(&checkpoint).unwrap();
        }
    }
}

#[test]
fn a_speedup_floor_over_too_few_networks_to_batch_is_refused() {
    let o = psa_esp(&["bench", "--speedup-floor", "4", "--networks", "1"]);
    refused(&o, &["--networks 1", "nothing to batch"]);
    // The portable build flies blocks of 8: 8 networks are enough there,
    // 7 are not (the message gives the level's own width).
    let portable = [
        "bench",
        "--speedup-level",
        "portable",
        "--speedup-floor",
        "0.001",
        "--rounds",
        "1",
    ];
    let o = psa_esp(&[&portable[..], &["--networks", "7"]].concat());
    refused(&o, &["--networks 7", "blocks of 8", "portable"]);
    let o = psa_esp(&[&portable[..], &["--networks", "8"]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn a_run_json_that_does_not_parse_is_named_not_config_toml() {
    let dir = tempfile::tempdir().unwrap();
    let grid = copy_of_grid(dir.path());
    // A run of an earlier build: its config.toml needs run.json's build.
    age_run(&grid, "a70d696");
    let path = run_folder(&grid).join("run.json");
    let mut run: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    run["champion_fitness"] = "HUGE".into();
    let text = serde_json::to_string_pretty(&run).unwrap().replace("\"HUGE\"", "1e999");
    std::fs::write(&path, text).unwrap();
    let report = report_json(&grid);
    assert_eq!(report["runs_counted"], 0, "{report}");
    let problems = report["problems"].to_string();
    assert!(
        problems.contains("run.json: damaged") && !problems.contains("config.toml"),
        "{problems}"
    );
    // Resuming names run.json, not config.toml.
    let text = refused(&psa_esp(&tiny_args(&grid)), &["run.json", "damaged"]);
    assert!(!text.contains("config.toml") && !text.contains("not written"), "{text}");
}

#[test]
fn a_network_file_without_provenance_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let grid = copy_of_grid(dir.path());
    let champion = run_folder(&grid).join("champion.json");
    let mut json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&champion).unwrap()).unwrap();
    json.as_object_mut().unwrap().remove("provenance");
    json["problem"]["sensors"]
        .as_object_mut()
        .unwrap()
        .remove("heading_wrap");
    let file = dir.path().join("bare.json");
    std::fs::write(&file, json.to_string()).unwrap();
    refused(
        &psa_esp(&["replay", file.to_str().unwrap()]),
        &["heading_wrap", "no \"provenance\""],
    );
}

#[test]
fn evolve_refuses_a_folder_name_that_is_not_utf8() {
    use std::os::unix::ffi::OsStrExt;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join(std::ffi::OsStr::from_bytes(b"run-\xff"));
    let o = Command::new(common::binary())
        .args([
            "evolve",
            "--task",
            "1",
            "--generations",
            "2",
            "--backend",
            "native",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    refused(&o, &["not UTF-8"]);
    assert!(!out.exists());
}

#[test]
fn every_command_that_writes_a_folder_refuses_a_name_that_is_not_utf8() {
    use std::os::unix::ffi::OsStrExt;
    let dir = tempfile::tempdir().unwrap();
    let grid = copy_of_grid(dir.path());
    let out = dir.path().join(std::ffi::OsStr::from_bytes(b"out-\xff"));
    let tiny: Vec<String> = tiny_args(&dir.path().join("unused"))
        .iter()
        .map(|a| a.to_string())
        .take_while(|a| a != "--out")
        .collect();
    let mut sweep = tiny.clone();
    sweep[0] = "sweep".into();
    sweep.extend(["--vary".into(), "esp.stagnation=20,30".into()]);
    let grid_arg = grid.display().to_string();
    let truth = dir.path().join("truth.toml");
    std::fs::write(&truth, "[problem.fitness]\nstate = \"truth\"\n").unwrap();
    for command in [
        tiny,
        sweep,
        vec![
            "rescore".into(),
            grid_arg.clone(),
            "--config".into(),
            truth.display().to_string(),
        ],
        vec!["traces".into(), grid_arg],
    ] {
        let o = Command::new(common::binary())
            .args(&command)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        refused(&o, &["--out", "not UTF-8"]);
        assert!(!out.exists(), "{command:?}: nothing written");
    }
}

/// Rescores the grid `source` with the settings `toml` into a folder in
/// `dir`: refused, naming `key` as changing nothing, and nothing written.
fn rescore_is_refused_as_changing_nothing(dir: &Path, source: &Path, toml: &str, key: &str) {
    let config = dir.join("rescore.toml");
    std::fs::write(&config, toml).unwrap();
    let out = dir.join("rescored");
    refused(
        &psa_esp(&[
            "rescore",
            source.to_str().unwrap(),
            "--config",
            config.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]),
        &[key, "changes nothing"],
    );
    assert!(!out.exists(), "{key}: nothing written");
}

// The trace tools, `evolve --trace` and `traces`.

/// The CSV header of a trace.
const TRACE_COLUMNS: &str = "generation,max,champion,subpops,burst,topology,top_first_pass,top_entries,\
                             top_steps_in,top_first_in,champion_first_pass,mean_credit_rank,max_credit_rank,\
                             mean_credit_gap";

/// A trace's header as `evolve --trace` writes it, of `task`, `seed` and
/// `generations` (the budget).
fn trace_header(task: u8, seed: u64, generations: usize) -> String {
    format!(
        "# psa-esp evolve --trace, format 1\n# task: {task}\n# configuration: baseline\n\
         # config: 0123456789abcdef\n# seed: {seed}\n# generations: {generations}\n# model: 12\n\
         # build: 0.1.0 commit 0000000 libode 0.16.2\n"
    )
}

/// A trace's lines (CSV header and rows): `rows` generations, the best
/// network landing in those of `landing` (1-based).
fn trace_rows(rows: usize, landing: &[usize]) -> String {
    let mut text = format!("{TRACE_COLUMNS}\n");
    for g in 1..=rows {
        let lands = u8::from(landing.contains(&g));
        text.push_str(&format!("{g},50,50,5,0,,{lands},1,10,490,{lands},0.2500,0.5000,0.1\n"));
    }
    text
}

/// `traces DIRS... --out OUT EXTRA...`.
fn traces(dirs: &[&Path], out: &Path, extra: &[&str]) -> Output {
    let mut command = Command::new(common::binary());
    command.arg("traces").args(dirs).arg("--out").arg(out).args(extra);
    command.output().unwrap()
}

/// A folder `dir/name` holding the traces `files` (name, contents).
fn trace_folder(dir: &Path, name: &str, files: &[(&str, String)]) -> PathBuf {
    let folder = dir.join(name);
    std::fs::create_dir_all(&folder).unwrap();
    for (file, text) in files {
        std::fs::write(folder.join(file), text).unwrap();
    }
    folder
}

/// `evolve` of task 2 on a small ESP (8 a sub-population, 2 trials a
/// neuron) for `generations`, into `out`, with `extra` arguments.
fn small_evolve(dir: &Path, out: &Path, generations: &str, extra: &[&std::ffi::OsStr]) -> Output {
    let config = dir.join("small.toml");
    std::fs::write(
        &config,
        "[esp]\nsubpop_size = 8\ntrials_per_neuron = 2\nstagnation = 3\n",
    )
    .unwrap();
    Command::new(common::binary())
        .args([
            "evolve",
            "--task",
            "2",
            "--threads",
            "1",
            "--generations",
            generations,
            "--config",
        ])
        .arg(&config)
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

#[test]
fn a_trace_of_a_huge_generation_is_refused_not_an_abort() {
    let dir = tempfile::tempdir().unwrap();
    for generation in ["1000000000000", "18446744073709551615", "99999999999999999999999"] {
        let row = trace_rows(1, &[1]).replace("\n1,50,", &format!("\n{generation},50,"));
        for (name, text) in [("old", row.clone()), ("new", trace_header(2, 1, 80) + &row)] {
            let folder = trace_folder(dir.path(), &format!("{name}-{generation}"), &[("a.trace.csv", text)]);
            let out = dir.path().join(format!("out-{name}-{generation}"));
            let o = traces(&[&folder], &out, &[]);
            let line = if name == "old" { "line 2" } else { "line 10" };
            refused(&o, &["a.trace.csv", line, generation, "where 1 is due"]);
            assert!(!out.exists());
        }
    }
}

#[test]
fn a_trace_named_like_a_file_of_its_run_is_refused_before_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    for name in RunFiles::NAMES {
        for trace in [out.join(name), dir.path().join(format!("./o/../o/{name}"))] {
            let o = small_evolve(dir.path(), &out, "1", &["--trace".as_ref(), trace.as_os_str()]);
            refused(&o, &[&format!("the run's own {name}")]);
            assert!(!out.exists(), "{name}: nothing written");
        }
    }
    // A trace of another name inside --out is the run's neighbour.
    let trace = out.join("seed-1.trace.csv");
    ok(&small_evolve(
        dir.path(),
        &out,
        "1",
        &["--trace".as_ref(), trace.as_os_str()],
    ));
    assert!(std::fs::read_to_string(&trace)
        .unwrap()
        .starts_with("# psa-esp evolve --trace"));
    assert!(std::fs::read_to_string(out.join("config.toml"))
        .unwrap()
        .contains("[esp]"));
    assert!(std::fs::read_to_string(out.join("records.csv"))
        .unwrap()
        .starts_with("generation,min,"));
}

#[test]
fn an_unwritable_trace_is_refused_before_the_first_generation() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    let read_only = dir.path().join("read-only");
    std::fs::create_dir(&read_only).unwrap();
    let mut permissions = std::fs::metadata(&read_only).unwrap().permissions();
    std::os::unix::fs::PermissionsExt::set_mode(&mut permissions, 0o555);
    std::fs::set_permissions(&read_only, permissions).unwrap();
    // As root a read-only folder takes files all the same: not a case then.
    let root = std::fs::write(read_only.join("probe"), "").is_ok();
    let mut cases = vec![
        (dir.path().join("missing/t.trace.csv"), "missing"),
        (PathBuf::from("/proc/t.trace.csv"), "/proc"),
        (out.clone(), "the --out folder itself"),
        (out.join("sub/t.trace.csv"), "inside the new run folder"),
        (dir.path().join("t.trace.csv/x"), "t.trace.csv"),
    ];
    if !root {
        cases.push((read_only.join("t.trace.csv"), "read-only"));
    }
    for (trace, needle) in &cases {
        let o = small_evolve(dir.path(), &out, "1", &["--trace".as_ref(), trace.as_os_str()]);
        refused(&o, &["--trace", needle]);
        assert!(!out.exists(), "{}: nothing of the run written", trace.display());
    }
    // Then the same --out with a good --trace runs.
    let trace = dir.path().join("t.trace.csv");
    ok(&small_evolve(
        dir.path(),
        &out,
        "1",
        &["--trace".as_ref(), trace.as_os_str()],
    ));
    assert!(out.join("champion.json").exists() && trace.exists());
    // And an --out that lies inside the --trace path is refused too.
    let o = small_evolve(
        dir.path(),
        &dir.path().join("u/run"),
        "1",
        &["--trace".as_ref(), dir.path().join("u").as_os_str()],
    );
    refused(&o, &["lies inside --trace"]);
}

#[test]
fn traces_reads_a_trace_by_the_rules_of_every_input_and_keeps_an_existing_summary() {
    let dir = tempfile::tempdir().unwrap();
    let rows = trace_rows(8, &[3]);
    // Each case in a trace of an earlier build (no header) and of this
    // one (8 lines of header): the line of the fault in the first.
    let cases: Vec<(&str, String, usize, &str)> = vec![
        (
            "nan",
            rows.replace("0.2500,0.5000", "NaN,0.5000"),
            2,
            "mean_credit_rank \"NaN\"",
        ),
        (
            "above",
            rows.replace("0.2500,0.5000", "1.5,0.5000"),
            2,
            "mean_credit_rank \"1.5\"",
        ),
        (
            "below",
            rows.replace("0.2500,0.5000", "-0.1,0.5000"),
            2,
            "mean_credit_rank \"-0.1\"",
        ),
        ("max", rows.replace(",0.5000,", ",inf,"), 2, "max_credit_rank \"inf\""),
        (
            "order",
            rows.replace("\n2,50,", "\n3,50,")
                .replace("\n3,50,50,5,0,,1", "\n2,50,50,5,0,,1"),
            3,
            "generation \"3\" where 2 is due",
        ),
        (
            "repeated",
            rows.replace("\n2,50,", "\n1,50,"),
            3,
            "generation \"1\" where 2 is due",
        ),
        (
            "short",
            rows.replace("\n4,50,50,5,0,,0,1,10,490,0,", "\n4,50,50,5,0,,0,1,10,490,"),
            5,
            "13 fields, where the header has 14",
        ),
    ];
    for (name, text, line, needle) in cases {
        for (kind, text, line) in [
            ("old", text.clone(), line),
            ("new", trace_header(2, 1, 8) + &text, line + 8),
        ] {
            let folder = trace_folder(dir.path(), &format!("{name}-{kind}"), &[("a.trace.csv", text)]);
            let out = dir.path().join(format!("{name}-{kind}-out"));
            refused(
                &traces(&[&folder], &out, &[]),
                &["a.trace.csv", &format!("line {line}:"), needle],
            );
            assert!(!out.exists(), "{name}, {kind}: nothing written");
        }
    }
    // A trace longer than its header's budget.
    let folder = trace_folder(dir.path(), "past", &[("a.trace.csv", trace_header(2, 1, 4) + &rows)]);
    refused(
        &traces(&[&folder], &dir.path().join("past-out"), &[]),
        &["line 14", "generation 5 of a run of 4"],
    );
    let good = trace_header(2, 1, 8) + &rows;
    // A trace over 64 MiB is refused before it is read.
    let big = trace_folder(dir.path(), "big", &[]);
    let file = std::fs::File::create(big.join("a.trace.csv")).unwrap();
    file.set_len(1 << 30).unwrap();
    let o = run_within(
        &[
            "traces",
            big.to_str().unwrap(),
            "--out",
            dir.path().join("big-out").to_str().unwrap(),
        ],
        Duration::from_secs(20),
    )
    .expect("refused at once");
    refused(&o, &["a.trace.csv", "1073741824 bytes, more than the 67108864"]);
    // So is anything but a regular file so named: never skipped.
    let fifo = trace_folder(dir.path(), "fifo", &[("a.trace.csv", good.clone())]);
    make_fifo(&fifo.join("b.trace.csv"));
    refused(
        &traces(&[&fifo], &dir.path().join("fifo-out"), &[]),
        &["b.trace.csv", "FIFO"],
    );
    // An existing summary is never replaced: --out must be new or empty.
    let folder = trace_folder(dir.path(), "good", &[("a.trace.csv", good)]);
    let out = dir.path().join("summary");
    std::fs::create_dir(&out).unwrap();
    ok(&traces(&[&folder], &out, &[]));
    let before = std::fs::read(out.join("traces.md")).unwrap();
    let o = traces(&[&folder], &out, &[]);
    refused(&o, &["output folder", "is not empty", "choose another --out"]);
    assert_eq!(std::fs::read(out.join("traces.md")).unwrap(), before);
    let file = dir.path().join("file");
    std::fs::write(&file, "x").unwrap();
    refused(&traces(&[&folder], &file, &[]), &["output folder", "not a directory"]);
}

#[test]
fn traces_refuses_unreadable_names_and_labels_every_folder_apart() {
    use std::os::unix::ffi::OsStrExt;
    let dir = tempfile::tempdir().unwrap();
    let good = trace_header(2, 1, 8) + &trace_rows(8, &[3]);
    // `evolve` refuses a trace it could not name, as it refuses such an --out.
    let bad_name = dir.path().join(std::ffi::OsStr::from_bytes(b"seed-\xff.trace.csv"));
    let out = dir.path().join("o");
    let o = small_evolve(dir.path(), &out, "1", &["--trace".as_ref(), bad_name.as_os_str()]);
    refused(&o, &["--trace", "not UTF-8"]);
    assert!(!out.exists() && !bad_name.exists());
    // `traces` names such a file (one written by an earlier build) instead of skipping it.
    let folder = trace_folder(dir.path(), "named", &[("a.trace.csv", good.clone())]);
    std::fs::write(folder.join(std::ffi::OsStr::from_bytes(b"b-\xff.trace.csv")), &good).unwrap();
    refused(
        &traces(&[&folder], &dir.path().join("named-out"), &[]),
        &["b-", "not UTF-8"],
    );
    // `traces .` labels the group by the folder's own name.
    let here = trace_folder(dir.path(), "here", &[("a.trace.csv", good.clone())]);
    let o = Command::new(common::binary())
        .current_dir(&here)
        .args(["traces", ".", "--out"])
        .arg(dir.path().join("here-out"))
        .output()
        .unwrap();
    assert!(ok(&o).contains("| here | 1 |"), "{}", stderr(&o));
    // The same folder twice is refused, by any of its names.
    for again in [here.clone(), dir.path().join("here/../here/.")] {
        let out = dir.path().join("twice-out");
        refused(&traces(&[&here, &again], &out, &[]), &["named twice", "count twice"]);
        assert!(!out.exists());
    }
    // Two folders of one name are labelled by their paths.
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    let at = trace_folder(&a, "t", &[("x.trace.csv", good.clone())]);
    let bt = trace_folder(&b, "t", &[("x.trace.csv", good)]);
    let out = dir.path().join("two-out");
    let table = ok(&traces(&[&at, &bt], &out, &[]));
    let (la, lb) = (at.display().to_string(), bt.display().to_string());
    assert!(
        table.contains(&format!("| {la} | 1 |")) && table.contains(&format!("| {lb} | 1 |")),
        "{table}"
    );
    let csv = std::fs::read_to_string(out.join("traces.csv")).unwrap();
    assert!(
        csv.contains(&format!("\n{la},x,")) && csv.contains(&format!("\n{lb},x,")),
        "{csv}"
    );
}

#[test]
fn a_trace_names_its_run_and_traces_pools_only_runs_of_one_kind() {
    let dir = tempfile::tempdir().unwrap();
    // The header `evolve --trace` writes names task, configuration (and
    // its hash), seed, budget, model and build.
    let traced = dir.path().join("traced");
    std::fs::create_dir(&traced).unwrap();
    let trace = traced.join("seed-4.trace.csv");
    let out = dir.path().join("run");
    let extra: [&std::ffi::OsStr; 4] = ["--seed".as_ref(), "4".as_ref(), "--trace".as_ref(), trace.as_os_str()];
    ok(&small_evolve(dir.path(), &out, "3", &extra));
    let text = std::fs::read_to_string(&trace).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let model = psa_sim::psa::settings::defaults::rows();
    assert_eq!(lines[0], "# psa-esp evolve --trace, format 1", "{text}");
    for (i, prefix) in [
        "# task: 2",
        "# configuration: baseline",
        "# config: ",
        "# seed: 4",
        "# generations: 3",
        &format!("# model: {model}"),
        "# build: 0.1.0 commit ",
    ]
    .iter()
    .enumerate()
    {
        assert!(lines[i + 1].starts_with(prefix), "line {}: {text}", i + 2);
    }
    assert!(
        lines[8].starts_with("generation,max,champion,") && lines.len() == 12,
        "{text}"
    );

    // Traces of different tasks, budgets or configurations are not summed
    // without --pool; with it, the table says what it pooled, and a run
    // that ended is not counted past its last generation.
    let cases = [
        (
            "tasks",
            trace_header(1, 1, 5) + &trace_rows(5, &[1]),
            "task 1 against 2",
        ),
        (
            "budgets",
            trace_header(2, 1, 5) + &trace_rows(5, &[1]),
            "generations 5 against 12",
        ),
        (
            "configs",
            (trace_header(2, 1, 12) + &trace_rows(12, &[1])).replace("0123456789abcdef", "fedcba9876543210"),
            "configuration baseline (config fedcba9876543210) against baseline (config 0123456789abcdef)",
        ),
    ];
    for (name, text, needle) in cases {
        let later = trace_header(2, 2, 12) + &trace_rows(12, &[1, 12]);
        let folder = trace_folder(dir.path(), name, &[("a.trace.csv", text), ("b.trace.csv", later)]);
        let out = dir.path().join(format!("{name}-out"));
        refused(&traces(&[&folder], &out, &[]), &["differ in", needle, "--pool"]);
        assert!(!out.exists());
        let table = ok(&traces(&[&folder], &out, &["--pool"]));
        assert!(table.contains("pooled (`--pool`)"), "{table}");
    }
    let landing = std::fs::read_to_string(dir.path().join("budgets-out/traces-landing.csv")).unwrap();
    assert!(landing.contains("\nbudgets,5,2,2,0\nbudgets,6,1,1,0\n"), "{landing}");
    assert!(landing.ends_with("\nbudgets,12,1,1,1\n"), "{landing}");

    // Runs of one kind are summed and named; the same run twice is refused.
    let one = trace_folder(
        dir.path(),
        "one",
        &[
            ("a.trace.csv", trace_header(2, 1, 8) + &trace_rows(8, &[3])),
            ("b.trace.csv", trace_header(2, 2, 8) + &trace_rows(8, &[])),
        ],
    );
    let table = ok(&traces(&[&one], &dir.path().join("one-out"), &[]));
    assert!(table.contains("| one | 2 | 1 | 3 |"), "{table}");
    assert!(
        table.contains(
            "- one: task 2; configuration baseline (config 0123456789abcdef); 8 generations; model 12; seeds 1, 2"
        ),
        "{table}"
    );
    std::fs::copy(one.join("a.trace.csv"), one.join("c.trace.csv")).unwrap();
    refused(
        &traces(&[&one], &dir.path().join("twice-out"), &[]),
        &["a.trace.csv and c.trace.csv", "one run"],
    );

    // A trace of an earlier build (no header) reads as it was written, and
    // the summary says it is grouped by its folder alone.
    let old = trace_folder(
        dir.path(),
        "old",
        &[
            ("a.trace.csv", trace_rows(8, &[3])),
            ("b.trace.csv", trace_rows(8, &[])),
        ],
    );
    let table = ok(&traces(&[&old], &dir.path().join("old-out"), &[]));
    assert!(table.contains("| old | 2 | 1 | 3 |"), "{table}");
    assert!(
        table.contains("2 of 2 traces of an earlier build, without a header"),
        "{table}"
    );
    assert!(table.contains("grouped by its folder alone"), "{table}");
    let csv = std::fs::read_to_string(dir.path().join("old-out/traces.csv")).unwrap();
    assert!(csv.contains("\nold,a,8,3,1,0,0,1,0,0.2500,0.2500,,,,,,\n"), "{csv}");
}

#[test]
fn docs_state_the_trace_header_and_the_rules_of_traces() {
    let formats = std::fs::read_to_string(repo("docs/file-formats.md")).unwrap();
    assert!(formats.contains(psa_experiment::trace::TRACE_FORMAT_LINE));
    for key in psa_experiment::trace::HEADER_KEYS {
        assert!(
            formats.contains(&format!("| `{key}` |")),
            "docs/file-formats.md lacks the header key {key}"
        );
        assert!(
            formats.contains(&format!("\n# {key}: ")),
            "the example header lacks {key}"
        );
    }
    let limits = std::fs::read_to_string(repo("docs/limits.md")).unwrap();
    for needle in [
        "## Traces",
        "`--pool`",
        "before the first\ngeneration",
        "where 1 is due",
        "would be the run's own config.toml",
        "new or\nempty folder",
        "grouped by their folder alone",
    ] {
        assert!(limits.contains(needle), "docs/limits.md lacks {needle:?}");
    }
}
