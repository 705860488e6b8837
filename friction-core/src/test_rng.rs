//! The unit tests' pseudo-random numbers (tests only).

/// Marsaglia's 64-bit xorshift (13, 7, 17) from `state` (not 0): the next
/// state on each call.
pub(crate) fn xorshift64(mut state: u64) -> impl FnMut() -> u64 {
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    }
}

/// Finite values of every size up to `max` (the scalar's largest), from
/// `seed`: `±max`, 0, and uniform values within 1e-3, 1e3 and `max`, as
/// the hostile-input tests draw them.
pub(crate) fn hostile(seed: u64, max: f64) -> impl FnMut() -> f64 {
    let mut rng = xorshift64(seed);
    move || {
        let r = rng();
        let unit = (r >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0;
        match r % 6 {
            0 => max,
            1 => -max,
            2 => 0.0,
            3 => unit * 1e-3,
            4 => unit * 1e3,
            _ => unit * max,
        }
    }
}
