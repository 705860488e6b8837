//! Steps the Rust and the C LuGre step over the same sweep, `ROUNDS` x 1024
//! steps each, for an instruction count under callgrind (`run.sh`): the
//! inclusive counts of `rust_step` and `c_step` divided by the step count.
use friction_bench_c::{
    c_ie_step, c_step, rust_fixed_step, rust_step, velocities, CLuGre, H, PARAMS,
};
use friction_core::{LuGreFixedStepState, LuGreState};
use std::hint::black_box;

/// Rounds over the 1024-step sweep.
const ROUNDS: usize = 100;

/// With the argument `fixed`, steps the fixed-step form and the minimal C
/// implicit-Euler step (whose `exp` is glibc's, so that callgrind
/// attributes the libm crate's `exp` calls to the fixed-step form alone).
fn main() {
    if std::env::args().nth(1).as_deref() == Some("fixed") {
        let fixed = PARAMS
            .build_fixed_step::<f64>(H)
            .expect("canudas1995 builds");
        let (mut w, mut ff) = (LuGreFixedStepState::default(), 0.0);
        let vs = velocities();
        for _ in 0..ROUNDS {
            for &v in &vs {
                ff += rust_fixed_step(black_box(&fixed), &mut w, black_box(v));
            }
        }
        // the minimal C implicit-Euler step over the same sweep
        let c = CLuGre::new(&PARAMS).expect("exponent 2");
        let (mut z, mut fi) = (0.0, 0.0);
        for _ in 0..ROUNDS {
            for &v in &vs {
                fi += c_ie_step(black_box(&c), &mut z, black_box(v), black_box(H));
            }
        }
        println!(
            "steps {} fixed-step, force sums {ff:.9e}, implicit Euler {fi:.9e}",
            ROUNDS * vs.len()
        );
        return;
    }
    let rust = PARAMS.build::<f64>().expect("canudas1995 builds");
    let c = CLuGre::new(&PARAMS).expect("exponent 2");
    let vs = velocities();
    let (mut s, mut z) = (LuGreState::default(), 0.0);
    let (mut fr, mut fc) = (0.0, 0.0);
    for _ in 0..ROUNDS {
        for &v in &vs {
            fr += rust_step(black_box(&rust), &mut s, black_box(v), black_box(H));
        }
    }
    for _ in 0..ROUNDS {
        for &v in &vs {
            fc += c_step(black_box(&c), &mut z, black_box(v), black_box(H));
        }
    }
    println!("steps {} (each)", ROUNDS * vs.len());
    println!("force sums: rust {fr:.9e}, c {fc:.9e}");
}
