//! A checkpoint is an input file under the rules of docs/limits.md.

use super::*;

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
