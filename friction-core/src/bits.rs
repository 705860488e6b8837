//! Stored forms that every bit pattern is a value of.
//!
//! The C ABI (`friction-ffi`) keeps built models and states in memory that
//! C owns and may have overwritten: a caller's bug, or a random pattern
//! that happens to carry a right tag word. Those bytes are then read as the
//! core's values, and a `bool` holding 2, or an enum discriminant no
//! variant has, is undefined behaviour to read. So the private fields of
//! every stored type are kept in forms for which any byte is a value: a
//! [`Flag`] for a `bool`, a `u8` decoded totally for a fieldless enum (every
//! byte maps to some variant), a tag byte with its data for an enum with
//! data. Valid objects behave as before; a garbage one gives garbage
//! numbers, never a crash.

/// A `bool` stored as a byte: `0` is false, anything else true.
#[derive(Clone, Copy, Default)]
#[repr(transparent)]
pub(crate) struct Flag(u8);

impl Flag {
    /// `true` or `false` as a flag.
    #[inline]
    pub(crate) const fn new(value: bool) -> Self {
        Self(value as u8)
    }

    /// Whether the flag is set (any byte but 0).
    #[inline]
    pub(crate) const fn get(self) -> bool {
        self.0 != 0
    }
}

impl From<bool> for Flag {
    fn from(value: bool) -> Self {
        Self::new(value)
    }
}

// equal as the `bool`s they stand for: valid objects compare as before
impl PartialEq for Flag {
    fn eq(&self, other: &Self) -> bool {
        self.get() == other.get()
    }
}

impl core::fmt::Debug for Flag {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        self.get().fmt(f)
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for Flag {
    fn format(&self, f: defmt::Formatter<'_>) {
        self.get().format(f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn any_nonzero_byte_is_set() {
        assert!(!Flag(0).get());
        for b in 1..=255 {
            assert!(Flag(b).get(), "{b}");
            assert_eq!(Flag(b), Flag::new(true));
        }
        assert_eq!(Flag::new(false), Flag(0));
        assert_eq!(std::format!("{:?}", Flag(7)), "true");
    }
}
