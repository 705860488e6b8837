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
