//! `include/friction.h` is what cbindgen generates from the sources now:
//! the test fails when the committed header is stale. Regenerate with
//! `FRICTION_BLESS=1 cargo test -p friction-ffi --test header`.

#![allow(clippy::expect_used)]

use std::path::Path;

#[test]
#[cfg_attr(
    miri,
    ignore = "reads and writes files; no unsafe code of the crate runs"
)]
fn header_is_current() {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config =
        cbindgen::Config::from_file(crate_dir.join("cbindgen.toml")).expect("cbindgen.toml parses");
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_crate(crate_dir)
        .with_config(config)
        .generate()
        .expect("cbindgen generates the header")
        .write(&mut generated);
    let generated = String::from_utf8(generated).expect("the header is UTF-8");
    let path = crate_dir.join("include/friction.h");
    if std::env::var_os("FRICTION_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("write include/friction.h");
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "include/friction.h is stale: run `FRICTION_BLESS=1 cargo test -p friction-ffi --test header`"
    );
}
