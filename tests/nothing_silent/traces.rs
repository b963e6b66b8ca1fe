//! The trace tools, `evolve --trace` and `traces`.

use super::*;

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
