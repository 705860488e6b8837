//! The host's modules form layers, with no import circle (issue 18): a
//! module may use only modules of a lower layer (and itself). Doc comments
//! are not imports.
#![allow(clippy::unwrap_used, clippy::panic)]

use std::path::Path;

const LAYERS: &[&[&str]] = &[
    &["checks", "signals", "reference", "control"],
    &["io"],
    &["plot"],
    &["models"],
    &["params"],
    &["sim"],
    &["experiments", "servo", "identify"],
    &["validate", "fuzzing", "online", "commission"],
];

/// The crate's exported macros (`crate::outln!`) and the module defining each.
const MACROS: &[(&str, &str)] = &[("out", "io"), ("outln", "io")];

fn layer(module: &str) -> usize {
    LAYERS
        .iter()
        .position(|l| l.contains(&module))
        .unwrap_or_else(|| panic!("module `{module}` is in no layer: add it to LAYERS"))
}

fn files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

#[test]
fn host_modules_import_only_lower_layers() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut all = Vec::new();
    files(&src, &mut all);
    let mut violations = Vec::new();
    for path in &all {
        let rel = path.strip_prefix(&src).unwrap();
        let first = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_str()
            .unwrap();
        let module = first.trim_end_matches(".rs");
        if module == "lib" || module == "main" {
            continue;
        }
        let own = layer(module);
        let text = std::fs::read_to_string(path).unwrap();
        for line in text.lines() {
            let code = line.trim_start();
            if code.starts_with("//") {
                continue;
            }
            for (i, _) in code.match_indices("crate::") {
                let name: String = code[i + 7..]
                    .chars()
                    .take_while(|c| c.is_ascii_lowercase() || *c == '_')
                    .collect();
                // an exported macro sits at the crate's root: count it as
                // the module that defines it
                let name = match MACROS.iter().find(|(m, _)| *m == name) {
                    Some((_, defined_in)) => defined_in.to_string(),
                    None => name,
                };
                if name.is_empty() || name == module {
                    continue;
                }
                if layer(&name) >= own {
                    violations.push(format!("{}: uses crate::{name}", rel.display()));
                }
            }
        }
    }
    assert!(violations.is_empty(), "{violations:#?}");
}
