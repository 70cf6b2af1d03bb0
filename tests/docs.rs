//! The README and docs/ hold what they point at: every relative link names a file of the
//! checkout, every script they tell a reader to run exists, and every fluidform command
//! they show parses (run with `--help` appended, so the parser checks each switch and value
//! it meets and nothing runs).
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// README.md and every chapter under docs/.
fn pages() -> Vec<PathBuf> {
    let mut v = vec![root().join("README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root().join("docs"))
        .expect("docs/")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    assert!(
        docs.len() >= 7,
        "the README's chapters are in docs/: {docs:?}"
    );
    v.extend(docs);
    v
}

/// The targets of markdown links `](target)` in `text`.
fn links(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find("](") {
        rest = &rest[i + 2..];
        if let Some(j) = rest.find(')') {
            out.push(rest[..j].to_string());
        }
    }
    out
}

#[test]
fn every_relative_link_names_a_file() {
    let mut checked = 0;
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        for link in links(&text) {
            if link.starts_with("http://") || link.starts_with("https://") {
                continue;
            }
            let path = link.split('#').next().unwrap();
            let target = page.parent().unwrap().join(path);
            assert!(
                target.exists(),
                "{}: link to {link}: no file {}",
                page.display(),
                target.display()
            );
            checked += 1;
        }
    }
    assert!(checked >= 15, "only {checked} links checked");
}

#[test]
fn the_readme_is_short_and_links_every_chapter() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let lines = readme.lines().count();
    assert!(lines <= 300, "README.md has {lines} lines (at most 300)");
    for page in pages().iter().skip(1) {
        let name = page.file_name().unwrap().to_str().unwrap();
        assert!(
            readme.contains(&format!("](docs/{name})")),
            "README.md does not link docs/{name}"
        );
    }
}

/// Inline code spans: the text between pairs of backticks.
fn spans(text: &str) -> Vec<&str> {
    text.split('`').skip(1).step_by(2).collect()
}

/// The commands shown in indented code lines and inline code: (page, words after
/// `fluidform`). Those with placeholders (`[...]`, `a|b`, `<name>`, `...`, `FILE`-style
/// metavariables) are synopses, not commands.
fn commands() -> Vec<(PathBuf, Vec<String>)> {
    let mut out = Vec::new();
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        let indented = text.lines().filter(|l| l.starts_with("    "));
        let inline = spans(&text)
            .into_iter()
            .filter(|s| s.starts_with("fluidform"));
        for line in indented.chain(inline) {
            let line = line.split("  #").next().unwrap().trim();
            let Some(at) = line
                .find("fluidform ")
                .or(line.ends_with("fluidform").then_some(0))
            else {
                continue;
            };
            // Run as is, or under Xvfb; not a word inside prose or a path.
            let before = line[..at].trim();
            if !(before.is_empty() || before == "xvfb-run -a") {
                continue;
            }
            let cmd = line[at + "fluidform".len()..].trim();
            let commands = [
                "devices", "run", "view", "bench", "plot", "scene", "inspect",
            ];
            let first = cmd.split_whitespace().next().unwrap_or("");
            let named = commands.contains(&first) || ["experiment", "compare"].contains(&first);
            if !(first.is_empty() || first.starts_with("--") || named) {
                continue; // prose or a diagram naming the crate
            }
            let synopsis = cmd.contains('[')
                || cmd.contains('|')
                || cmd.contains('<')
                || cmd.contains("..")
                || cmd
                    .split_whitespace()
                    .any(|w| w.len() > 1 && w.chars().all(|c| c.is_ascii_uppercase() || c == '_'))
                || cmd.contains('>')
                || cmd.contains('=') && !cmd.contains("--");
            if synopsis || line.contains("fluidform.") || line.contains("fluidform-") {
                continue;
            }
            out.push((
                page.clone(),
                cmd.split_whitespace().map(String::from).collect(),
            ));
        }
    }
    out
}

#[test]
fn every_command_shown_parses() {
    let cmds = commands();
    assert!(cmds.len() >= 12, "only {} commands found", cmds.len());
    for (page, args) in &cmds {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_fluidform"))
            .args(args)
            .arg("--help")
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{}: `fluidform {}` does not parse: {}",
            page.display(),
            args.join(" "),
            String::from_utf8_lossy(&o.stderr)
        );
    }
}

#[test]
fn every_script_named_exists() {
    let mut checked = 0;
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        for word in text.split(|c: char| c.is_whitespace() || "`()[],;:".contains(c)) {
            let Some(i) = word.find("scripts/") else {
                continue;
            };
            let name = word[i..].trim_end_matches('.');
            if !(name.ends_with(".sh") || name.ends_with(".py")) {
                continue;
            }
            assert!(
                Path::new(&root().join(name)).exists(),
                "{}: names {name}, which does not exist",
                page.display()
            );
            checked += 1;
        }
    }
    assert!(checked >= 5, "only {checked} script names checked");
}

/// Every long option of every command: the words `--name` in each command's --help.
fn cli_options() -> std::collections::BTreeSet<String> {
    let help = |args: &[&str]| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_fluidform"))
            .args(args)
            .arg("--help")
            .output()
            .unwrap();
        assert!(o.status.success(), "fluidform {} --help", args.join(" "));
        String::from_utf8_lossy(&o.stdout).to_string()
    };
    let mut text = help(&[]);
    for cmd in [
        "devices",
        "run",
        "view",
        "plot",
        "inspect",
        "experiment",
        "compare",
        "scene",
    ] {
        text.push_str(&help(&[cmd]));
    }
    for b in fluidform::bench::Bench::all() {
        text.push_str(&help(&["bench", &b.as_str()]));
    }
    options_in(&text)
}

/// The `--name` words of `text`.
fn options_in(text: &str) -> std::collections::BTreeSet<String> {
    text.split(|c: char| !(c.is_ascii_alphanumeric() || c == '-'))
        .filter(|w| w.starts_with("--") && w.len() > 2 && w.as_bytes()[2].is_ascii_lowercase())
        .map(|w| w.trim_end_matches('-').to_string())
        .collect()
}

#[test]
fn every_switch_named_exists() {
    let known = cli_options();
    // Options of the scripts and of other tools the pages show (cargo, xvfb-run, apt).
    let mut others = String::new();
    for e in std::fs::read_dir(root().join("scripts")).unwrap() {
        others.push_str(&std::fs::read_to_string(e.unwrap().path()).unwrap_or_default());
    }
    let others = options_in(&others);
    let tools = [
        "--release",
        "--test-threads",
        "--all-targets",
        "--no-deps",
        "--features",
    ];
    let mut checked = 0;
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        let code: Vec<&str> = text
            .lines()
            .filter(|l| l.starts_with("    "))
            .chain(spans(&text))
            .collect();
        for opt in options_in(&code.join("\n")) {
            if others.contains(&opt) || tools.contains(&opt.as_str()) {
                continue;
            }
            assert!(
                known.contains(&opt),
                "{}: `{opt}` is no switch of any fluidform command",
                page.display()
            );
            checked += 1;
        }
    }
    assert!(checked >= 60, "only {checked} switches checked");
}
