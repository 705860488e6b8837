//! Replays the fuzz targets' committed corpora (`fuzz/corpus/*`, minimised
//! by `cargo fuzz cmin`) through the same readers the targets drive
//! ([`friction_host::fuzzing`]), so that CI checks every input the fuzzer
//! found interesting without nightly: a panic fails the test.

use std::path::Path;

fn replay(target: &str, read: fn(&[u8])) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz/corpus")
        .join(target);
    let mut count = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let data = std::fs::read(&path).unwrap();
        // the file named if the reader panics
        eprintln!("{}", path.display());
        read(&data);
        count += 1;
    }
    assert!(count > 0, "no corpus in {}", dir.display());
}

#[test]
fn the_parameter_file_corpus_is_read_without_a_panic() {
    replay("params", friction_host::fuzzing::params);
}

#[test]
fn the_csv_corpus_is_read_without_a_panic() {
    replay("csv", friction_host::fuzzing::csv);
}
