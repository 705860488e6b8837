//! Every `friction` command the README and the guide show runs verbatim
//! from a fresh clone (issue 34): the lines of their `sh` blocks that call
//! the tool through cargo (`cargo run --release -p friction-host --bin
//! friction -- ...`), run with the built binary in a folder that holds the
//! clone's inputs (`params/`, the shipped data) and nothing else, each
//! exiting 0. The synopsis lines (`friction simulate --params ...` with
//! brackets and placeholders) describe the syntax and are not run.

use std::path::{Path, PathBuf};
use std::process::Command;

const PREFIX: &str = "cargo run --release -p friction-host --bin friction --";

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The commands (arguments after `--`) in the `sh` blocks of `text`, with
/// continued lines joined and trailing comments dropped.
fn commands(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut in_sh = false;
    let mut pending = String::new();
    for line in text.lines() {
        let trimmed = line.trim();
        if trimmed.starts_with("```") {
            in_sh = !in_sh && trimmed == "```sh";
            continue;
        }
        if !in_sh {
            continue;
        }
        if let Some(head) = trimmed.strip_suffix('\\') {
            pending.push_str(head);
            pending.push(' ');
            continue;
        }
        pending.push_str(trimmed);
        let whole = std::mem::take(&mut pending);
        let whole = whole.split(" # ").next().unwrap_or("").trim().to_string();
        if let Some(args) = whole.strip_prefix(PREFIX) {
            out.push(args.split_whitespace().collect::<Vec<_>>().join(" "));
        }
    }
    out
}

#[test]
fn documented_commands_run_verbatim() {
    let mut docs = vec![root().join("README.md")];
    let mut guide: Vec<PathBuf> = std::fs::read_dir(root().join("docs/guide"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    guide.sort();
    docs.extend(guide);
    // a fresh clone's inputs, read-only through links; outputs land here
    let dir = tempfile::tempdir().unwrap();
    std::os::unix::fs::symlink(root().join("params"), dir.path().join("params")).unwrap();
    std::fs::create_dir_all(dir.path().join("friction-host/tests")).unwrap();
    std::os::unix::fs::symlink(
        root().join("friction-host/tests/data"),
        dir.path().join("friction-host/tests/data"),
    )
    .unwrap();
    let mut ran = 0;
    for doc in &docs {
        let text = std::fs::read_to_string(doc).unwrap();
        for args in commands(&text) {
            // absolute outputs (/tmp/...) go into this run's folder
            let args: Vec<String> = args
                .split_whitespace()
                .map(|a| match a.strip_prefix("/tmp/") {
                    Some(rest) => dir.path().join("tmp").join(rest).display().to_string(),
                    None => a.to_string(),
                })
                .collect();
            let out = Command::new(env!("CARGO_BIN_EXE_friction"))
                .args(&args)
                .current_dir(dir.path())
                .output()
                .unwrap();
            assert!(
                out.status.success(),
                "{}: `friction {}` exited {:?}: {}",
                doc.display(),
                args.join(" "),
                out.status.code(),
                String::from_utf8_lossy(&out.stderr)
            );
            ran += 1;
        }
    }
    // the README's four and the guide's servo, robustness, actuator and
    // online examples at least
    assert!(ran >= 10, "only {ran} commands found");
}

#[test]
fn the_extraction_joins_continued_lines_and_drops_comments() {
    let text = "```sh\ncargo run --release -p friction-host --bin friction -- servo \\\n  --output x   # a comment\nfriction synopsis [--x]\n```\n```python\ncargo run --release -p friction-host --bin friction -- no\n```\n";
    assert_eq!(commands(text), ["servo --output x"]);
}
