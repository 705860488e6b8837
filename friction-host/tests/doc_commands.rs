//! Every `friction` command the README and the guide show runs verbatim
//! from a fresh clone (issue 34): the lines of their `sh` blocks that call
//! the tool through cargo (`cargo run --release -p friction-host --bin
//! friction -- ...` or `cargo run --release -p friction-host -- ...`, the
//! same binary), run with the built binary in a folder that holds the
//! clone's inputs (`params/`, the shipped data) and nothing else, each
//! exiting 0 or with the code its trailing comment documents (`# exits
//! 1`). Arguments are split as the shell splits them (double and single
//! quotes). The synopsis lines (`friction simulate --params ...` with
//! brackets and placeholders) describe the syntax and are not run.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The ways the docs call the tool through cargo (`friction` is the
/// package's only binary).
const PREFIXES: [&str; 2] = [
    "cargo run --release -p friction-host --bin friction --",
    "cargo run --release -p friction-host --",
];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// One documented command: its arguments and the exit code the docs give.
#[derive(Debug, PartialEq)]
struct Documented {
    args: Vec<String>,
    exit: i32,
}

/// `line` split into words as a POSIX shell does for quotes (no variables,
/// no escapes inside quotes).
fn words(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut word = String::new();
    let mut in_word = false;
    let mut quote: Option<char> = None;
    for c in line.chars() {
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), c) => word.push(c),
            (None, '"' | '\'') => {
                quote = Some(c);
                in_word = true;
            }
            (None, c) if c.is_whitespace() => {
                if in_word {
                    out.push(std::mem::take(&mut word));
                    in_word = false;
                }
            }
            (None, c) => {
                word.push(c);
                in_word = true;
            }
        }
    }
    assert!(quote.is_none(), "unclosed quote in `{line}`");
    if in_word {
        out.push(word);
    }
    out
}

/// The commands in the `sh` blocks of `text`, with continued lines joined
/// and trailing comments dropped (a comment `exits N` gives the code).
fn commands(text: &str) -> Vec<Documented> {
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
        let (command, comment) = whole.split_once(" # ").unwrap_or((&whole, ""));
        let command = command.trim();
        let Some(args) = PREFIXES.iter().find_map(|p| command.strip_prefix(p)) else {
            continue;
        };
        let exit = match comment.trim().strip_prefix("exits ") {
            Some(code) => code.trim().parse().unwrap(),
            None => 0,
        };
        out.push(Documented {
            args: words(args),
            exit,
        });
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
        for Documented { args, exit } in commands(&text) {
            // absolute outputs (/tmp/...) go into this run's folder
            let args: Vec<String> = args
                .iter()
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
            assert_eq!(
                out.status.code(),
                Some(exit),
                "{}: `friction {}` exited {:?}, documented {exit}: {}",
                doc.display(),
                args.join(" "),
                out.status.code(),
                String::from_utf8_lossy(&out.stderr)
            );
            ran += 1;
        }
    }
    // the README's four, the guide's servo, robustness, actuator and
    // online examples and the identification guide's five at least
    assert!(ran >= 15, "only {ran} commands found");
}

#[test]
fn the_extraction_joins_continued_lines_and_drops_comments() {
    let text = "```sh\ncargo run --release -p friction-host --bin friction -- servo \\\n  --output x   # a comment\nfriction synopsis [--x]\ncargo run --release -p friction-host -- identify --time \"Time [s]\" \\\n  --output 'a b'  # exits 1\n```\n```python\ncargo run --release -p friction-host --bin friction -- no\n```\n";
    assert_eq!(
        commands(text),
        [
            Documented {
                args: vec!["servo".into(), "--output".into(), "x".into()],
                exit: 0
            },
            Documented {
                args: ["identify", "--time", "Time [s]", "--output", "a b"]
                    .map(String::from)
                    .to_vec(),
                exit: 1
            },
        ]
    );
}
