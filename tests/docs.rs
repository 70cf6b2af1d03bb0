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

/// The commands shown in indented code lines: (page, words after `fluidform`). Lines with
/// placeholders (`[...]`, `a|b`, `<name>`, `N`-style metavariables) are synopses, not commands.
fn commands() -> Vec<(PathBuf, Vec<String>)> {
    let mut out = Vec::new();
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        for line in text.lines().filter(|l| l.starts_with("    ")) {
            let line = line.split("  #").next().unwrap().trim();
            let Some(at) = line
                .find("fluidform ")
                .or(line.ends_with("fluidform").then_some(0))
            else {
                continue;
            };
            let before = &line[..at];
            // `xvfb-run -a fluidform ...` runs it; `FLUIDFORM_BIN=./fluidform scripts/...`
            // names the binary for a script.
            if before.contains('=') || before.contains('/') || !line[at..].starts_with("fluidform")
            {
                continue;
            }
            let cmd = line[at + "fluidform".len()..].trim();
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
    assert!(cmds.len() >= 20, "only {} commands found", cmds.len());
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
