//! The readers the fuzz targets drive (`friction-host/fuzz`, `cargo +nightly
//! fuzz run params|csv`), here so that `cargo test` replays their committed
//! corpora through exactly the same code on stable (`tests/fuzz_corpus.rs`).
//! Each takes arbitrary bytes and must return, never panic: a refusal is
//! an ordinary error.

/// The parameter-file reader: TOML text as `friction` reads `--params`,
/// then the `[servo]` table resolved as `friction servo` does.
pub fn params(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(file) = crate::params::ParamFile::parse(text, "fuzz.toml") {
        let _ = file.servo.resolve("fuzz.toml");
    }
}

/// The CSV readers: the streamed `t,v` rows of `friction simulate` and the
/// delimited columns of `friction identify`.
pub fn csv(data: &[u8]) {
    if let Ok(rows) = crate::io::TvRows::new(data, "fuzz.csv") {
        for row in rows {
            let _ = row;
        }
    }
    if let Ok(text) = std::str::from_utf8(data) {
        if let Ok(columns) =
            crate::identify::data::parse_columns(text, "fuzz.csv", &["t", "x", "f"])
        {
            let _ = crate::identify::data::check_time(&columns.data[0], "fuzz.csv", "t");
        }
    }
}
