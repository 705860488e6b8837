//! Puts memory.x where the linker (cortex-m-rt's link.x) finds it, and
//! tells the cost benchmark its target.
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::copy("memory.x", out.join("memory.x")).expect("memory.x is next to Cargo.toml");
    println!("cargo:rustc-link-search={}", out.display());
    // the cost benchmark names the core it was built for
    let target = env::var("TARGET").expect("cargo sets TARGET");
    println!("cargo:rustc-env=COST_TARGET={target}");
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");
}
