//! Compiles the hand-written C step (lugre.c) with the system C compiler.
fn main() {
    cc::Build::new()
        .file("lugre.c")
        .opt_level(2)
        .warnings(true)
        .extra_warnings(true)
        .compile("lugre_c");
    println!("cargo:rerun-if-changed=lugre.c");
    println!("cargo:rerun-if-changed=lugre.h");
}
