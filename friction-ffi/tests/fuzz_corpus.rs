//! The fuzz corpus of the C ABI's object decoding (`fuzz/corpus/objects`,
//! found by `cargo +nightly fuzz run objects` and minimised), replayed on
//! stable through the fuzz target's own harness: a regression test of
//! every input the fuzzer kept.

#![allow(clippy::unwrap_used, clippy::expect_used)]

#[path = "../fuzz/harness.rs"]
mod harness;

#[test]
#[cfg_attr(miri, ignore = "reads files (Miri isolates the file system)")]
fn fuzz_corpus_replays() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/objects");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .expect("the committed corpus")
        .map(|entry| entry.unwrap().path())
        .collect();
    files.sort();
    // a corpus lost or emptied is a failure, not a pass
    assert!(
        files.len() >= 450,
        "{} corpus files in {} (501 committed)",
        files.len(),
        dir.display()
    );
    for file in &files {
        harness::run(&std::fs::read(file).unwrap());
    }
}
