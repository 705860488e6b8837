//! Arbitrary bytes as each object type of the C ABI, through every call
//! that reads one (`harness.rs`, which the stable corpus test shares).

#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "../harness.rs"]
mod harness;

fuzz_target!(|data: &[u8]| harness::run(data));
