//! Output paths.

use super::*;

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
