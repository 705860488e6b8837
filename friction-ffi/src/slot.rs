//! Caller-allocated storage: the only `unsafe` code of the crate.
//!
//! C allocates each object (`friction_model_f64`, ...) as a plain array of
//! 64-bit words whose size the header states. A constructor writes a tag
//! (the object type's 32-bit `MAGIC`) followed by a Rust value into it; every
//! later call checks the tag before it views the words as that value. The
//! size and alignment of each value are checked at compile time; every
//! stored value is `Copy` (no destructor, no pointer into itself), so C
//! may copy an initialised object with `memcpy` or assignment.

/// A C-visible object of `WORDS` 64-bit words holding one `Value`.
pub(crate) trait Opaque: Sized {
    /// What the object holds.
    type Value: Copy;
    /// The tag written by the constructor: one per object type, so a
    /// never-initialised object (or one of another type) is refused. It
    /// repeats one byte, `0xB1` to `0xB6`: Thumb-2 encodes such a word as an
    /// instruction's immediate, so the check is one `cmp` and no constant
    /// to build; and the bytes are neither ASCII text nor a usual fill
    /// pattern (`0x00`, `0xFF`, `0xAA`, `0x55`, `0xCD`, `0xDEADBEEF`) that
    /// reused memory could hold. 32 bits, not 64: a 64-bit tag took two
    /// `eor`s and an `orr` more a call on the Cortex-M4F (the servo tick
    /// through the C ABI, 1.10x the Rust tick's instructions, counts them).
    const MAGIC: u32;
}

/// The layout a constructor writes: the tag, then the value.
#[repr(C)]
struct Slot<V> {
    magic: u32,
    value: V,
}

/// Compile-time check that `Slot<O::Value>` fits in `O`.
const fn fits<O: Opaque>() -> bool {
    core::mem::size_of::<Slot<O::Value>>() <= core::mem::size_of::<O>()
        && core::mem::align_of::<Slot<O::Value>>() <= core::mem::align_of::<O>()
}

/// The object's tag (its first 32 bits: `Slot` is `repr(C)` with the tag
/// first). Read through a pointer: the rest of the words may hold a value's
/// padding, which is not data.
fn tag<O: Opaque>(object: &O) -> u32 {
    const { assert!(core::mem::size_of::<O>() >= 8 && core::mem::align_of::<O>() >= 8) };
    // SAFETY: the object is at least one aligned u64 long, and its first
    // 32 bits are either C's bytes or a tag this module wrote.
    unsafe { (object as *const O).cast::<u32>().read() }
}

/// Writes `value` into `out` with its tag.
pub(crate) fn put<O: Opaque>(out: &mut O, value: O::Value) {
    const { assert!(fits::<O>(), "the C object is too small for its value") };
    let slot = (out as *mut O).cast::<Slot<O::Value>>();
    // SAFETY: `fits` checked size and alignment; `out` is a unique
    // reference, so the words are ours to overwrite; `Slot` is `Copy` data.
    unsafe {
        slot.write(Slot {
            magic: O::MAGIC,
            value,
        })
    };
}

/// The value in `object`, or `None` when its tag is not `O::MAGIC`.
pub(crate) fn get<O: Opaque>(object: &mut O) -> Option<&mut O::Value> {
    const { assert!(fits::<O>(), "the C object is too small for its value") };
    if tag(object) != O::MAGIC {
        return None;
    }
    let slot = (object as *mut O).cast::<Slot<O::Value>>();
    // SAFETY: the tag shows a constructor wrote a `Slot<O::Value>` here
    // (or C copied one that it wrote); size and alignment are checked.
    Some(unsafe { &mut (*slot).value })
}

/// The value in `object` read-only, or `None` when its tag is not `O::MAGIC`.
pub(crate) fn get_ref<O: Opaque>(object: &O) -> Option<&O::Value> {
    const { assert!(fits::<O>(), "the C object is too small for its value") };
    if tag(object) != O::MAGIC {
        return None;
    }
    let slot = (object as *const O).cast::<Slot<O::Value>>();
    // SAFETY: as in `get`.
    Some(unsafe { &(*slot).value })
}

/// Implements [`Opaque`] for a C object type (declared by hand, so that
/// cbindgen sees it) holding `$value`.
macro_rules! opaque {
    ($name:ident, $value:ty, $magic:expr) => {
        impl crate::slot::Opaque for $name {
            type Value = $value;
            const MAGIC: u32 = $magic;
        }
    };
}
pub(crate) use opaque;
