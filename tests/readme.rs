//! The README against the program and the repository: each command's
//! synopsis under "Commands" names exactly the options of that command's
//! own `--help` (and, where both list an option's values, the same values),
//! and every relative link in the project's Markdown
//! (README.md, CHANGELOG.md, CONTRIBUTING.md, docs/) reaches a file and,
//! where it names one, a heading of it; every `docs/*.md` a source,
//! manifest or script cites exists; every file, test and test file
//! CONTRIBUTING.md cites exists; the Python stub names the backends and
//! algorithms as the crates do; python/README.md's wheel recipe is CI's
//! and its commands run the project's venv.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository root (the `psa-esp` crate's manifest folder).
fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn help(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_psa-esp"))
        .args(args)
        .arg("--help")
        .output()
        .expect("run psa-esp --help");
    assert!(out.status.success(), "psa-esp {args:?} --help failed");
    String::from_utf8(out.stdout).expect("help is UTF-8")
}

/// The `--long` names in a piece of text.
fn long_options(text: &str) -> BTreeSet<String> {
    let mut names = BTreeSet::new();
    let mut rest = text;
    while let Some(at) = rest.find("--") {
        let after = &rest[at + 2..];
        let len = after
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '-'))
            .unwrap_or(after.len());
        let name = &after[..len];
        if name.starts_with(|c: char| c.is_ascii_lowercase()) {
            names.insert(format!("--{name}"));
        }
        rest = &after[len..];
    }
    names
}

/// The options a `--help` lists: the lines under `Options:` that start
/// (after the indent clap gives an option, at most six spaces) with a dash.
/// `--help` itself is left out: clap adds it to every command.
fn help_options(help: &str) -> BTreeSet<String> {
    let options = help.split_once("\nOptions:\n").map(|(_, o)| o).unwrap_or_default();
    options
        .lines()
        .filter(|line| {
            let indent = line.len() - line.trim_start().len();
            (2..=6).contains(&indent) && line.trim_start().starts_with('-')
        })
        .flat_map(|line| long_options(line.split("  ").find(|s| s.contains("--")).unwrap_or("")))
        .filter(|name| name != "--help")
        .collect()
}

/// The values each option of a `--help` allows, where clap lists them:
/// `[possible values: a, b]`, or a `Possible values:` list of `- a: ...`.
fn help_values(help: &str) -> BTreeMap<String, BTreeSet<String>> {
    let options = help.split_once("\nOptions:\n").map(|(_, o)| o).unwrap_or_default();
    let mut values = BTreeMap::<String, BTreeSet<String>>::new();
    let mut current = String::new();
    for line in options.lines() {
        let trimmed = line.trim_start();
        let indent = line.len() - trimmed.len();
        if (2..=6).contains(&indent) && trimmed.starts_with('-') {
            current = long_options(line.split("  ").find(|s| s.contains("--")).unwrap_or(""))
                .pop_first()
                .unwrap_or_default();
        }
        if let Some((_, listed)) = line.split_once("[possible values: ") {
            let listed = listed.split(']').next().unwrap_or("");
            let set = values.entry(current.clone()).or_default();
            set.extend(listed.split(", ").map(str::to_owned));
        } else if let Some(item) = trimmed.strip_prefix("- ").filter(|_| indent > 6) {
            let value = item.split(':').next().unwrap_or("").to_owned();
            values.entry(current.clone()).or_default().insert(value);
        }
    }
    values
}

/// The values a synopsis lists for an option, as in `--preset quick|paper`.
fn synopsis_values(synopsis: &str) -> BTreeMap<String, BTreeSet<String>> {
    let words: Vec<&str> = synopsis.split_whitespace().collect();
    let mut values = BTreeMap::new();
    for pair in words.windows(2) {
        let option = pair[0].trim_start_matches('[');
        let listed = pair[1].trim_end_matches(']');
        if option.starts_with("--") && !option.contains('|') && listed.contains('|') && !listed.starts_with('-') {
            values.insert(option.to_owned(), listed.split('|').map(str::to_owned).collect());
        }
    }
    values
}

/// The subcommands `psa-esp --help` lists (without clap's `help`).
fn subcommands() -> BTreeSet<String> {
    let top = help(&[]);
    let (_, commands) = top.split_once("\nCommands:\n").expect("a Commands section");
    commands
        .lines()
        .take_while(|line| line.starts_with("  "))
        .filter_map(|line| line.split_whitespace().next())
        .filter(|name| *name != "help")
        .map(str::to_owned)
        .collect()
}

/// Phrases a synopsis may use for a set of another command's options: the
/// phrase, the command whose synopsis it stands for, and the options of that
/// synopsis it leaves out.
const STANDS_FOR: &[(&str, &str, &[&str])] = &[("[replicate's grid options]", "replicate", &["--out"])];

/// The README's synopses: the fenced block under "## Commands", one entry
/// per `psa-esp NAME` line with its indented continuation lines; the
/// program's own line (`psa-esp --version`) is under the name "".
fn readme_synopses() -> BTreeMap<String, String> {
    let readme = std::fs::read_to_string(root().join("README.md")).expect("read README.md");
    let (_, section) = readme
        .split_once("\n## Commands\n")
        .expect("a Commands section in README.md");
    let (_, block) = section.split_once("```text\n").expect("a text block under Commands");
    let (block, _) = block.split_once("```").expect("the block's end");
    let mut synopses = BTreeMap::<String, String>::new();
    let mut current = None;
    for line in block.lines() {
        if let Some(rest) = line.strip_prefix("psa-esp ") {
            let first = rest.split_whitespace().next().unwrap_or("");
            let (name, options) = if first.starts_with('-') {
                ("", rest)
            } else {
                (first, &rest[first.len()..])
            };
            let name = name.to_owned();
            assert!(!synopses.contains_key(&name), "README.md gives `psa-esp {name}` twice");
            synopses.insert(name.clone(), options.to_owned());
            current = Some(name);
        } else if line.starts_with(' ') {
            let name = current.as_ref().expect("a continuation line after a command's line");
            let text = synopses.get_mut(name).expect("the command's entry");
            text.push(' ');
            text.push_str(line.trim());
        }
    }
    synopses
}

/// The options a synopsis names, with its stand-in phrases expanded.
fn synopsis_options(synopses: &BTreeMap<String, String>, name: &str) -> BTreeSet<String> {
    let mut text = synopses[name].clone();
    let mut names = BTreeSet::new();
    for (phrase, command, left_out) in STANDS_FOR {
        if text.contains(phrase) {
            text = text.replace(phrase, "");
            names.extend(
                synopsis_options(synopses, command)
                    .into_iter()
                    .filter(|o| !left_out.contains(&o.as_str())),
            );
        }
    }
    names.extend(long_options(&text));
    names
}

#[test]
fn each_readme_synopsis_names_exactly_the_options_of_its_commands_help() {
    let synopses = readme_synopses();
    let commands = subcommands();
    let documented: BTreeSet<String> = synopses.keys().filter(|n| !n.is_empty()).cloned().collect();
    assert_eq!(
        documented, commands,
        "README.md's synopses (left) and `psa-esp --help`'s commands (right) differ"
    );
    let mut problems = Vec::new();
    for name in synopses.keys() {
        let args: Vec<&str> = if name.is_empty() { vec![] } else { vec![name.as_str()] };
        let text = help(&args);
        let in_help = help_options(&text);
        let in_readme = synopsis_options(&synopses, name);
        let allowed = help_values(&text);
        for (option, listed) in synopsis_values(&synopses[name]) {
            match allowed.get(&option) {
                Some(values) if *values != listed => problems.push(format!(
                    "psa-esp {name} {option}: the README lists {listed:?}, --help {values:?}"
                )),
                _ => {}
            }
        }
        let missing: Vec<_> = in_help.difference(&in_readme).collect();
        let extra: Vec<_> = in_readme.difference(&in_help).collect();
        if !missing.is_empty() || !extra.is_empty() {
            problems.push(format!(
                "psa-esp {name}: in --help but not in the README: {missing:?}; in the README but not in --help: {extra:?}"
            ));
        }
    }
    assert!(
        problems.is_empty(),
        "README.md's synopses drift:\n{}",
        problems.join("\n")
    );
}

/// Every Markdown file whose links the project keeps: README.md,
/// CHANGELOG.md, CONTRIBUTING.md and everything under docs/.
fn markdown_files() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = ["README.md", "CHANGELOG.md", "CONTRIBUTING.md"]
        .iter()
        .map(|f| root().join(f))
        .filter(|p| p.exists())
        .collect();
    let mut dirs = vec![root().join("docs")];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).expect("read docs/") {
            let path = entry.expect("a docs/ entry").path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "md") {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

/// GitHub's anchor of a heading: lower case, spaces to hyphens, every
/// character but letters, digits, hyphens and underscores dropped.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

/// The lines of a Markdown text outside its fenced code blocks.
fn outside_code(markdown: &str) -> impl Iterator<Item = &str> {
    let mut in_code = false;
    markdown.lines().filter(move |line| {
        if line.starts_with("```") {
            in_code = !in_code;
            return false;
        }
        !in_code
    })
}

fn anchors(markdown: &str) -> BTreeSet<String> {
    outside_code(markdown)
        .filter(|line| line.starts_with('#'))
        .map(|line| anchor(line.trim_start_matches('#')))
        .collect()
}

/// The relative targets of `](target)` links outside code blocks.
fn relative_links(markdown: &str) -> Vec<String> {
    let mut links = Vec::new();
    for line in outside_code(markdown) {
        let mut rest = line;
        while let Some(at) = rest.find("](") {
            let after = &rest[at + 2..];
            let end = after.find(')').unwrap_or(after.len());
            let target = &after[..end];
            if !target.contains("://") && !target.starts_with("mailto:") {
                links.push(target.to_owned());
            }
            rest = &after[end..];
        }
    }
    links
}

#[test]
fn every_relative_link_in_the_markdown_reaches_its_file_and_heading() {
    let mut broken = Vec::new();
    for file in markdown_files() {
        let text = std::fs::read_to_string(&file).expect("read a Markdown file");
        for link in relative_links(&text) {
            let (path, fragment) = link.split_once('#').unwrap_or((&link, ""));
            let target = if path.is_empty() {
                file.clone()
            } else {
                file.parent().expect("a folder").join(path)
            };
            let shown = file.strip_prefix(root()).unwrap_or(&file).display().to_string();
            if !target.exists() {
                broken.push(format!("{shown}: {link} (no such file)"));
            } else if !fragment.is_empty() {
                let heads = anchors(&std::fs::read_to_string(&target).unwrap_or_default());
                if !heads.contains(fragment) {
                    broken.push(format!("{shown}: {link} (no such heading)"));
                }
            }
        }
    }
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

/// Every file of the repository whose text may cite a doc: sources,
/// manifests, configuration files and scripts (not `target/` or hidden
/// folders).
fn citing_files() -> Vec<PathBuf> {
    let mut files = Vec::new();
    let mut dirs = vec![root().to_path_buf()];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).expect("read a folder") {
            let path = entry.expect("a folder entry").path();
            let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
            if path.is_dir() {
                if !name.starts_with('.') && name != "target" {
                    dirs.push(path);
                }
            } else if ["rs", "toml", "py", "sh", "cff"]
                .iter()
                .any(|e| path.extension().is_some_and(|x| x == *e))
            {
                files.push(path);
            }
        }
    }
    files
}

#[test]
fn every_doc_a_source_file_cites_exists() {
    let mut missing = Vec::new();
    for file in citing_files() {
        let Ok(text) = std::fs::read_to_string(&file) else {
            continue;
        };
        let mut rest = text.as_str();
        while let Some(at) = rest.find("docs/") {
            let after = &rest[at..];
            let len = after
                .find(|c: char| !(c.is_ascii_alphanumeric() || "_-./".contains(c)))
                .unwrap_or(after.len());
            let cited = after[..len].trim_end_matches('.');
            // A path that only ends in docs/ (another folder's) is not the repository's.
            let inside_a_path = rest[..at].ends_with(|c: char| c == '/' || c.is_ascii_alphanumeric());
            if cited.ends_with(".md") && !inside_a_path && !root().join(cited).exists() {
                let shown = file.strip_prefix(root()).unwrap_or(&file).display().to_string();
                missing.push(format!("{shown}: {cited}"));
            }
            rest = &after[len.max(5)..];
        }
    }
    assert!(missing.is_empty(), "docs cited but missing:\n{}", missing.join("\n"));
}

/// The names inside each `Literal[...]` that follows `marker` in the
/// Python stub, `python/psa_esp/_native.pyi`.
fn stub_literals(marker: &str) -> Vec<Vec<String>> {
    let stub = std::fs::read_to_string(root().join("python/psa_esp/_native.pyi")).unwrap();
    stub.match_indices(marker)
        .map(|(at, _)| {
            let rest = &stub[at + marker.len()..];
            let inside = rest
                .strip_prefix("Literal[")
                .unwrap_or_else(|| panic!("the stub's {marker:?} at byte {at} is not a Literal of names"));
            let inside = &inside[..inside.find(']').unwrap()];
            inside
                .split(',')
                .map(|name| name.trim().trim_matches('"').to_string())
                .collect()
        })
        .collect()
}

#[test]
fn the_python_stubs_names_are_the_crates() {
    use psa_experiment::Algorithm;
    use psa_sim::named::Named;
    use psa_sim::physics::BackendKind;
    let backends = stub_literals("backend: ");
    for names in backends {
        assert_eq!(names, BackendKind::names(), "a backend argument of the stub");
    }
    let mut read = Algorithm::names();
    read.push("hill-climb");
    assert_eq!(stub_literals("algorithm: "), [read], "Run's algorithm argument");
    assert_eq!(
        stub_literals("def algorithm(self) -> "),
        [Algorithm::names()],
        "Run.algorithm"
    );
}

/// The code spans (`...`) of `markdown` on one line each.
fn code_spans(markdown: &str) -> Vec<&str> {
    markdown
        .split('`')
        .skip(1)
        .step_by(2)
        .filter(|span| !span.is_empty() && !span.contains('\n'))
        .collect()
}

#[test]
fn every_file_test_and_test_file_contributing_cites_exists() {
    let guide = std::fs::read_to_string(root().join("CONTRIBUTING.md")).unwrap();
    let rust: String = citing_files()
        .iter()
        .filter(|file| file.extension().is_some_and(|e| e == "rs"))
        .map(|file| std::fs::read_to_string(file).unwrap_or_default())
        .collect();
    // A folder inside a crate is cited from its `src/` ("psa/settings/").
    let sources = ["", "sim/src", "experiment/src", "esp/src", "src", "python/src"];
    let mut missing = Vec::new();
    for span in code_spans(&guide) {
        let path_like = span.contains('/')
            && !span.starts_with('-')
            && span.chars().all(|c| c.is_ascii_alphanumeric() || "_-./".contains(c));
        if path_like && !sources.iter().any(|src| root().join(src).join(span).exists()) {
            missing.push(format!("file {span}"));
        }
        let test_like = span.split('_').count() >= 4
            && span
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
        if test_like && !rust.contains(&format!("fn {span}(")) {
            missing.push(format!("test {span}"));
        }
        for word in span.split(" --test ").skip(1) {
            let name = word.split_whitespace().next().unwrap_or("");
            let tests = root().join("tests");
            let target = tests.join(format!("{name}.rs")).exists() || tests.join(name).join("main.rs").exists();
            if name != "NAME" && !target {
                missing.push(format!("test file tests/{name}.rs"));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "CONTRIBUTING.md cites what is not there:\n{}",
        missing.join("\n")
    );
}

/// The lines of the fenced `sh` blocks of `markdown`.
fn shell_lines(markdown: &str) -> Vec<String> {
    let mut lines = Vec::new();
    let mut inside = false;
    for line in markdown.lines() {
        if line.starts_with("```") {
            inside = !inside && line.trim() == "```sh";
            continue;
        }
        if inside && !line.trim().is_empty() {
            lines.push(line.trim().to_string());
        }
    }
    lines
}

#[test]
fn the_python_readmes_commands_are_cis_and_use_the_projects_venv() {
    let readme = std::fs::read_to_string(root().join("python/README.md")).unwrap();
    let ci = std::fs::read_to_string(root().join(".ci/run")).unwrap();
    let commands = shell_lines(&readme);
    let mut wrong = Vec::new();
    for line in &commands {
        // The portable wheel's build: a line CI runs (which may filter its
        // output).
        let in_ci = ci.lines().any(|l| {
            l.trim().strip_prefix(line.as_str()).is_some_and(|rest| {
                let rest = rest.trim_start();
                rest.is_empty() || rest.starts_with("2>") || rest.starts_with('|')
            })
        });
        if line.contains("build-wheel") && !in_ci {
            wrong.push(format!("not a line of .ci/run: {line}"));
        }
        // Python runs as the project's venv's (a bare python3 cannot import
        // the package), but where it makes the venv.
        for command in line.split("&&") {
            let command = command.trim();
            if command.starts_with("python3 ") && !command.starts_with("python3 -m venv ") {
                wrong.push(format!("not the venv's python: {command}"));
            }
        }
    }
    assert!(
        commands.iter().any(|l| l == "python/build-wheel"),
        "python/README.md gives the wheel's build"
    );
    assert!(wrong.is_empty(), "python/README.md:\n{}", wrong.join("\n"));
}
