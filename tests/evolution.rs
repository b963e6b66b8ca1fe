//! The search algorithms end to end: a non-PSA problem, configuration
//! files, determinism across thread counts, and the evolve command.

use std::path::Path;
use std::process::Command;

use esp_neuroevolution::network::Network;
use esp_neuroevolution::{Esp, EspSettings, FnEvaluator, HillClimb, HillClimbSettings};
use psa_experiment::{Preset, RunConfig};
use psa_sim::psa::{NetworkFile, PsaSettings, TrialRunner};

/// XOR with a 3-H-1 network (inputs x1, x2, bias): fitness 4 minus the
/// summed squared error over the four cases, so 4 is perfect.
fn xor() -> impl esp_neuroevolution::Evaluator<Worker = ()> {
    FnEvaluator::new(3, 1, |net: &Network, _: &mut esp_neuroevolution::rng::Stream| {
        let mut out = [0.0];
        let mut error = 0.0;
        for (a, b) in [(0.0, 0.0), (0.0, 1.0), (1.0, 0.0), (1.0, 1.0)] {
            net.activate(&[a, b, 1.0], &mut out);
            let target = if a != b { 1.0 } else { 0.0 };
            error += (out[0] - target) * (out[0] - target);
        }
        Ok(4.0 - error)
    })
}

#[test]
fn esp_solves_xor_within_its_budget() {
    // Stated: with 4 sub-populations of 20, within 200 generations of 200
    // networks (40,000 evaluations), every seed gets each case within 0.1
    // of its target (fitness > 3.96). (Measured: all of seeds 1-10 reach 4.000.)
    let settings = EspSettings {
        subpop_size: 20,
        initial_hidden: 4,
        generations: 200,
        ..EspSettings::hoverstad()
    };
    for seed in 1..=5 {
        let result = Esp::new(settings.clone(), seed).unwrap().run(&xor(), |_| {}).unwrap();
        assert!(
            result.champion.fitness > 3.96,
            "seed {seed}: {}",
            result.champion.fitness
        );
        assert!(result.records.last().unwrap().evaluations >= 40_000);
        // It starts far from solved: a random network scores about 3.
        assert!(result.records[0].mean < 3.5);
    }
}

#[test]
fn hill_climber_improves_on_xor() {
    let settings = HillClimbSettings {
        hidden: 3,
        candidates: 50,
        cycles: 100,
        ..HillClimbSettings::default()
    };
    let result = HillClimb::new(settings, 1).unwrap().run(&xor(), |_| {}).unwrap();
    assert!(result.champion.fitness > 3.5, "{}", result.champion.fitness);
    assert!(result.records[0].max < result.champion.fitness);
}

#[test]
fn presets_differ_from_the_baseline_in_their_one_setting() {
    let base = Preset::Baseline.config();
    let toml = |c: &RunConfig| c.to_toml().unwrap();
    let changed = |p: Preset| {
        let (a, b) = (toml(&base), toml(&p.config()));
        a.lines()
            .zip(b.lines())
            .filter(|(x, y)| x != y)
            .map(|(_, y)| y.to_string())
            .collect::<Vec<_>>()
    };
    assert_eq!(changed(Preset::Systematic), ["sampling = \"systematic\""]);
    assert_eq!(changed(Preset::MaxCredit), ["credit = \"max\""]);
    assert_eq!(changed(Preset::LesionOff), ["topology = \"off\""]);
    assert_eq!(changed(Preset::EraseBest), ["erase_best = true"]);
    assert_eq!(changed(Preset::Gomez), ["burst = \"gomez\""]);
    assert_eq!(changed(Preset::HillClimb), ["algorithm = \"hill_climb\""]);
    assert_eq!(base.esp.generations, 2000);
    assert_eq!(base.esp.networks_per_generation(), 400);
}

#[test]
fn configuration_files_override_settings_and_reject_bad_keys_and_values() {
    let base = Preset::Baseline.config();
    let c = base
        .with_overrides("[esp]\nsubpop_size = 20\n[problem.noise]\ninput_sd = 0.05\n")
        .unwrap();
    assert_eq!((c.esp.subpop_size, c.problem.noise.input_sd), (20, 0.05));
    assert_eq!(
        c.esp.stagnation, base.esp.stagnation,
        "untouched settings keep the preset's values"
    );
    let cases = [
        ("[esp]\nsubpop_sise = 20\n", "subpop_sise"),
        ("colour = 1\n", "colour"),
        ("[esp]\nsubpop_size = -3\n", "subpop_size"),
        ("[esp]\nmutation_rate = 1.5\n", "esp.mutation_rate"),
        ("[hill_climb]\np_flip = -0.1\n", "hill_climb.p_flip"),
        (
            "[esp]\ninit_range = 1e308\n",
            "esp.init_range must be in (0, 1e6], got 1e308",
        ),
        (
            "[hill_climb]\ninit_range = 1e308\n",
            "hill_climb.init_range must be in (0, 1e6]",
        ),
        ("[esp]\ngenerations = 0\n", "esp.generations"),
        ("[esp]\nsubpop_size = 0\n", "esp.subpop_size"),
        ("[problem]\nsteps = 0\n", "steps"),
        ("[problem.physics]\ndt = -0.05\n", "dt"),
        ("[problem]\nbackend = \"bullet\"\n", "bullet"),
        ("[esp\n", "TOML"),
    ];
    for (text, needle) in cases {
        let err = format!("{:#}", base.with_overrides(text).unwrap_err());
        assert!(err.contains(needle), "{text:?}: {err}");
    }
}

fn psa_esp(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_psa-esp")).args(args).output().unwrap()
}

fn small_config(dir: &Path) -> String {
    let path = dir.join("small.toml");
    std::fs::write(&path, "[esp]\nsubpop_size = 8\ntrials_per_neuron = 2\nstagnation = 3\n").unwrap();
    path.to_str().unwrap().to_string()
}

#[test]
fn evolve_is_bit_identical_for_1_2_and_4_threads() {
    let dir = tempfile::tempdir().unwrap();
    let config = small_config(dir.path());
    for backend in ["ode", "native"] {
        let mut outputs = Vec::new();
        for threads in ["1", "2", "4"] {
            let out = dir.path().join(format!("{backend}-{threads}"));
            let o = psa_esp(&[
                "evolve",
                "--task",
                "1",
                "--seed",
                "3",
                "--generations",
                "12",
                "--config",
                &config,
                "--backend",
                backend,
                "--threads",
                threads,
                "--out",
                out.to_str().unwrap(),
            ]);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            outputs.push((
                std::fs::read(out.join("records.csv")).unwrap(),
                std::fs::read(out.join("champion.json")).unwrap(),
            ));
        }
        assert!(
            outputs.iter().all(|o| *o == outputs[0]),
            "{backend}: results depend on the thread count"
        );
        // And the records saw bursts, so the whole machinery ran.
        let records = String::from_utf8(outputs[0].0.clone()).unwrap();
        assert!(records.lines().any(|l| l.contains(",true,")), "{records}");
    }
}

#[test]
fn evolve_writes_a_champion_that_replays_to_its_recorded_fitness() {
    let dir = tempfile::tempdir().unwrap();
    let config = small_config(dir.path());
    for (preset, task) in [("baseline", "2"), ("hill-climb", "3"), ("max-credit", "1")] {
        let out = dir.path().join(preset);
        let o = psa_esp(&[
            "evolve",
            "--task",
            task,
            "--preset",
            preset,
            "--generations",
            "8",
            "--config",
            &config,
            "--out",
            out.to_str().unwrap(),
            "--json",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let summary: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let (file, network) = NetworkFile::load(&out.join("champion.json")).unwrap();
        assert_eq!(file.task.to_string(), task);
        // Replaying the champion without noise gives exactly its recorded fitness.
        let resolved = RunConfig::default()
            .with_overrides(&std::fs::read_to_string(out.join("config.toml")).unwrap())
            .unwrap();
        let mut runner = TrialRunner::new(&resolved.problem, file.task).unwrap();
        let fitness = runner
            .evaluate(&network, &mut esp_neuroevolution::rng::stream(0, &[]))
            .unwrap();
        assert_eq!(fitness, summary["champion_fitness"].as_f64().unwrap(), "{preset}");
        let records = std::fs::read_to_string(out.join("records.csv")).unwrap();
        assert_eq!(records.lines().count(), 9, "header + 8 generations");
        assert_eq!(resolved.problem, PsaSettings::default());
        // The same directory again: refused, nothing overwritten.
        let o = psa_esp(&["evolve", "--task", task, "--out", out.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2));
        assert!(String::from_utf8_lossy(&o.stderr).contains("not empty"));
        assert_eq!(std::fs::read_to_string(out.join("records.csv")).unwrap(), records);
    }
}

#[test]
fn evolve_rejects_bad_arguments_with_a_clear_message() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "[esp]\nlesion_threshold = 2\n").unwrap();
    let cases: [(&[&str], &str); 4] = [
        (&["evolve", "--task", "4"], "task must be 1, 2 or 3"),
        (&["evolve", "--task", "1", "--preset", "best"], "best"),
        (
            &["evolve", "--task", "1", "--config", bad.to_str().unwrap()],
            "esp.lesion_threshold",
        ),
        (&["evolve", "--task", "1", "--generations", "0"], "--generations"),
    ];
    for (args, needle) in cases {
        let o = psa_esp(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(needle), "{args:?}: {err}");
    }
}

#[test]
fn a_traced_evolve_is_the_untraced_run_and_traces_every_generation() {
    let dir = tempfile::tempdir().unwrap();
    let config = small_config(dir.path());
    let run = |name: &str, trace: Option<&Path>| {
        let out = dir.path().join(name);
        let mut args = vec![
            "evolve".to_string(),
            "--task".into(),
            "2".into(),
            "--seed".into(),
            "7".into(),
            "--generations".into(),
            "80".into(),
            "--config".into(),
            config.clone(),
            "--out".into(),
            out.display().to_string(),
        ];
        if let Some(trace) = trace {
            args.extend(["--trace".into(), trace.display().to_string()]);
        }
        let o = psa_esp(&args.iter().map(String::as_str).collect::<Vec<_>>());
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        (
            std::fs::read(out.join("records.csv")).unwrap(),
            std::fs::read(out.join("champion.json")).unwrap(),
        )
    };
    let trace = dir.path().join("trace.csv");
    let traced = run("traced", Some(&trace));
    assert!(traced == run("plain", None), "tracing changed the run");
    let text = std::fs::read_to_string(&trace).unwrap();
    // The header names the run (docs/file-formats.md), then the CSV.
    let header: Vec<&str> = text.lines().take_while(|l| l.starts_with('#')).collect();
    assert_eq!(header.len(), 8, "{text}");
    for line in [
        "# task: 2",
        "# configuration: baseline",
        "# seed: 7",
        "# generations: 80",
    ] {
        assert!(header.contains(&line), "{line}: {text}");
    }
    let lines: Vec<&str> = text.lines().skip(header.len()).collect();
    assert_eq!(lines.len(), 81, "{text}");
    assert!(lines[0].starts_with("generation,max,champion,subpops,burst,topology,top_first_pass"));
    // The trace's max and champion are the records' own, and bursts and
    // topology changes show (stagnation 3 in 80 generations: 19 bursts, 16
    // topology changes).
    let records = String::from_utf8(traced.0).unwrap();
    for (t, r) in lines[1..].iter().zip(records.lines().skip(1)) {
        let (t, r): (Vec<&str>, Vec<&str>) = (t.split(',').collect(), r.split(',').collect());
        assert_eq!(t[0], r[0]);
        let fitness = |s: &str| s.parse::<f64>().unwrap();
        assert!(
            r.iter().any(|v| v.parse::<f64>().is_ok_and(|v| v == fitness(t[1]))),
            "{t:?} {r:?}"
        );
        for rank in &t[11..13] {
            assert!((0.0..=1.0).contains(&fitness(rank)), "{t:?}");
        }
    }
    assert!(lines[1..].iter().any(|l| l.split(',').nth(4) == Some("1")), "{text}");
    assert!(lines[1..].iter().any(|l| l.split(',').nth(5) != Some("")), "{text}");

    // An existing trace is never overwritten; the hill-climber has no sub-populations.
    let again = dir.path().join("again");
    let o = psa_esp(&[
        "evolve",
        "--task",
        "2",
        "--generations",
        "2",
        "--config",
        &config,
        "--out",
        again.to_str().unwrap(),
        "--trace",
        trace.to_str().unwrap(),
    ]);
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("trace file"));
    let o = psa_esp(&[
        "evolve",
        "--task",
        "2",
        "--preset",
        "hill-climb",
        "--generations",
        "2",
        "--out",
        again.to_str().unwrap(),
        "--trace",
        dir.path().join("hc.csv").to_str().unwrap(),
    ]);
    assert!(
        !o.status.success() && String::from_utf8_lossy(&o.stderr).contains("hill-climber"),
        "{o:?}"
    );
}

/// A trace with the given generations' best networks landing (1-based),
/// a burst ending generation 3, mean-credit ranks 0.2 (landing) and 0.6.
fn handmade_trace(generations: usize, landing: &[usize]) -> String {
    let mut text = String::from(
        "generation,max,champion,subpops,burst,topology,top_first_pass,top_entries,top_steps_in,top_first_in,\
         champion_first_pass,mean_credit_rank,max_credit_rank,mean_credit_gap\n",
    );
    let first = landing.iter().min().copied().unwrap_or(usize::MAX);
    for g in 1..=generations {
        let lands = landing.contains(&g);
        text.push_str(&format!(
            "{g},50,50,5,{},,{},1,10,490,{},{},0,0.1\n",
            u8::from(g == 3),
            u8::from(lands),
            u8::from(g >= first),
            if lands { "0.2000" } else { "0.6000" },
        ));
    }
    text
}

#[test]
fn traces_summarises_each_folder_of_traces_as_a_group() {
    let dir = tempfile::tempdir().unwrap();
    let config = small_config(dir.path());
    // Group "real": one trace written by evolve; group "made": two of known content.
    let real = dir.path().join("real");
    let made = dir.path().join("made");
    std::fs::create_dir_all(&real).unwrap();
    std::fs::create_dir_all(&made).unwrap();
    let o = psa_esp(&[
        "evolve",
        "--task",
        "2",
        "--generations",
        "20",
        "--config",
        &config,
        "--out",
        dir.path().join("run").to_str().unwrap(),
        "--trace",
        real.join("seed-1.trace.csv").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Lands at 3 (lost at the burst), 5-6 (lost otherwise) and 8 (the last).
    std::fs::write(made.join("a.trace.csv"), handmade_trace(8, &[3, 5, 6, 8])).unwrap();
    std::fs::write(made.join("b.trace.csv"), handmade_trace(8, &[])).unwrap();
    std::fs::write(made.join("notes.txt"), "not a trace").unwrap();
    let out = dir.path().join("summary");
    let o = psa_esp(&[
        "traces",
        real.to_str().unwrap(),
        made.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let table = String::from_utf8(o.stdout).unwrap();
    assert!(
        table.contains("| made | 2 | 1 | 3 | 4 | 1 / 0 / 1 | 1 | 0.20 / 0.60 |"),
        "{table}"
    );
    assert!(table.lines().any(|l| l.starts_with("| real | 1 |")), "{table}");
    // The made traces have no header (as an earlier build wrote them): the
    // table says so; the real one's names its run.
    assert!(table.contains("- made: 2 of 2 traces of an earlier build"), "{table}");
    assert!(
        table.contains("- real: task 2; configuration baseline (config "),
        "{table}"
    );
    assert_eq!(std::fs::read_to_string(out.join("traces.md")).unwrap(), table);
    let csv = std::fs::read_to_string(out.join("traces.csv")).unwrap();
    assert!(csv.contains("\nmade,a,8,3,4,1,0,1,1,0.2000,0.6000,,,,,,\n"), "{csv}");
    assert!(csv.contains("\nmade,b,8,,0,0,0,0,0,,0.6000,,,,,,\n"), "{csv}");
    assert_eq!(
        csv.lines()
            .filter(|l| l.starts_with("real,seed-1,20,")
                && l.contains(",2,baseline,")
                && l.ends_with(&format!(",1,20,{}", psa_sim::psa::settings::defaults::rows())))
            .count(),
        1,
        "{csv}"
    );
    let landing = std::fs::read_to_string(out.join("traces-landing.csv")).unwrap();
    assert!(
        landing.starts_with("group,generation,runs,found_by,landing\nreal,1,1,"),
        "{landing}"
    );
    assert!(landing.contains("\nmade,3,2,1,1\nmade,4,2,1,0\n"), "{landing}");
    for figure in ["traces-landing.svg", "traces-landing.png"] {
        assert!(std::fs::metadata(out.join(figure)).unwrap().len() > 1000, "{figure}");
    }

    // A folder without traces, and a damaged trace, are refused by name.
    let out = dir.path().join("summary-2");
    let empty = dir.path().join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let o = psa_esp(&["traces", empty.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && stderr.contains("empty") && stderr.contains("no *.trace.csv"),
        "{stderr}"
    );
    std::fs::write(
        made.join("c.trace.csv"),
        handmade_trace(3, &[]).replace("\n2,50,50,5,0,,0,", "\n2,50,50,5,0,,2,"),
    )
    .unwrap();
    let o = psa_esp(&["traces", made.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && stderr.contains("c.trace.csv line 3") && stderr.contains("top_first_pass"),
        "{stderr}"
    );
}
