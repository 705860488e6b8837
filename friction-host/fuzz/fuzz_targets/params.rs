//! The parameter-file (TOML) reader on arbitrary bytes.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| friction_host::fuzzing::params(data));
