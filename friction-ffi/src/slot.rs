//! Caller-allocated storage: where C's bytes become Rust values.
//!
//! C allocates each object (`friction_model_f64`, ...) as a plain array of
//! 64-bit words whose size the header states. A constructor writes a tag
//! (the object type's 32-bit `MAGIC`) followed by a Rust value into it; every
//! later call checks the words before it views them as that value, because
//! C may hand over anything: an object no constructor wrote (stack garbage,
//! a `memset`), one of another type, or a corrupted one. The size and
//! alignment of each value are checked at compile time; every stored value
//! is `Copy` (no destructor, no pointer into itself), so C may copy an
//! initialised object with `memcpy` or assignment.
//!
//! The check, before any byte is viewed as a Rust value: the tag and the
//! value's variant (a `#[repr(u32)]` enum's discriminant, stored next to
//! the tag), read as two `u32`s, must be `MAGIC` and one of the enum's
//! variants. Every field of every variant is then of a type every bit
//! pattern is a value of (floats, integers, the `u32` kinds and unions of
//! `crate::any`, whose dispatch never reads a union field for a kind no
//! constructor writes), apart from the core's private fields:
//!
//! What this cannot check: the private fields of the core's built models
//! and states. `friction_core` keeps a few `bool`s and enums inside them
//! (the Stribeck curve's shape, the observer's damping flag, the GMS slip
//! modes, ...) and counts (the bristle model's re-bond budget). Bytes that
//! carry the right tag and variant but were changed inside a core value by
//! C are read as that value; an uninitialised or `memset` object, or a
//! random pattern but with a chance of 6 in 2^64, does not get that far. Checking
//! them needs the core to store them in a form every bit pattern is a
//! value of (or to check them itself).

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

/// A value stored in an object: a `#[repr(u32)]` enum (so that its
/// discriminant, the variant, is its first 32 bits: RFC 2195) whose fields
/// are all of types every bit pattern is a value of (floats, integers, the
/// `u32` kinds and unions of `crate::any`), apart from the core's private
/// fields (see the module's note).
pub(crate) trait Checked: Copy {
    /// The enum's variant count: its discriminants are `0..VARIANTS`
    /// (implicit, in declaration order).
    const VARIANTS: u32;
    /// Whether every model kind inside is one a constructor writes (the
    /// dispatch is sound without it: an unknown kind steps as no model).
    fn is_valid(&self) -> bool;
}

/// The layout a constructor writes: a free word (zero), the tag, then the
/// value. The tag sits next to the value's variant, so that one 64-bit
/// load (`ldrd` on a Cortex-M) reads both for the check.
#[repr(C)]
struct Slot<V> {
    free: u32,
    magic: u32,
    value: V,
}

/// Compile-time check that `Slot<O::Value>` fits in `O`, with the tag and
/// the variant next to each other.
const fn fits<O: Opaque>() -> bool {
    core::mem::size_of::<Slot<O::Value>>() <= core::mem::size_of::<O>()
        && core::mem::align_of::<Slot<O::Value>>() <= core::mem::align_of::<O>()
        && core::mem::offset_of!(Slot<O::Value>, magic) == 4
        && core::mem::offset_of!(Slot<O::Value>, value) == 8
}

/// The object's tag and its value's variant (bytes 4 to 11), read as two
/// `u32`s: no enum is formed from them before they are checked.
fn header<O: Opaque>(object: &O) -> [u32; 2] {
    const { assert!(fits::<O>(), "the C object is too small for its value") };
    // SAFETY: `fits` keeps bytes 4 to 11 inside the object (4-aligned, as
    // the object is 8-aligned); they hold C's bytes, or the tag and the
    // discriminant of a `#[repr(u32)]` enum this module wrote (never
    // padding), and every bit pattern is a `u32`.
    unsafe {
        (object as *const O)
            .cast::<u8>()
            .add(4)
            .cast::<[u32; 2]>()
            .read()
    }
}

/// Writes `value` into `out` with its tag.
pub(crate) fn put<O: Opaque>(out: &mut O, value: O::Value) {
    const { assert!(fits::<O>(), "the C object is too small for its value") };
    let slot = (out as *mut O).cast::<Slot<O::Value>>();
    // SAFETY: `fits` checked size and alignment; `out` is a unique
    // reference, so the words are ours to overwrite; `Slot` is `Copy` data.
    unsafe {
        slot.write(Slot {
            free: 0,
            magic: O::MAGIC,
            value,
        })
    };
}

/// Whether the tag is `O::MAGIC` and the variant one of the value's.
#[inline]
fn accepted<O: Opaque>(object: &O) -> bool
where
    O::Value: Checked,
{
    let [magic, variant] = header(object);
    magic == O::MAGIC && variant < <O::Value as Checked>::VARIANTS
}

/// The value in `object`, or `None` when the object is not one a
/// constructor wrote (its tag or its variant wrong).
#[inline]
pub(crate) fn get<O: Opaque>(object: &mut O) -> Option<&mut O::Value>
where
    O::Value: Checked,
{
    if !accepted(object) {
        return None;
    }
    let slot = (object as *mut O).cast::<Slot<O::Value>>();
    // SAFETY: size and alignment are checked (`fits`); the discriminant is
    // one of the enum's, and each of its fields is of a type every bit
    // pattern is a value of (`Checked`), so the bytes are a value of
    // `O::Value` (see the module's note on the core's private fields).
    Some(unsafe { &mut (*slot).value })
}

/// The value in `object` read-only, as [`get`], and only when every model
/// kind inside is one a constructor writes (for the constructors that
/// copy a model: a new object is never built from an unknown kind).
pub(crate) fn get_valid<O: Opaque>(object: &O) -> Option<&O::Value>
where
    O::Value: Checked,
{
    if !accepted(object) {
        return None;
    }
    let slot = (object as *const O).cast::<Slot<O::Value>>();
    // SAFETY: as in `get`.
    let value = unsafe { &(*slot).value };
    value.is_valid().then_some(value)
}

/// A value that is a `union` of `Copy` types, so that every bit pattern is
/// a value of it; which field holds data is a kind kept elsewhere.
///
/// # Safety
///
/// Only for `union`s (or types every bit pattern is a value of).
pub(crate) unsafe trait Union: Copy {}

/// Writes `value` into `out` with the tag word `O::MAGIC + kind`: the
/// kind (from 1) of the union field written rides in the tag (added, not
/// xor-ed: the check is then one `add` of an immediate Thumb-2 encodes,
/// `-(MAGIC + 1)` repeating one byte, before the jump table's bound).
pub(crate) fn put_kind<O: Opaque>(out: &mut O, kind: u32, value: O::Value)
where
    O::Value: Union,
{
    const { assert!(fits::<O>(), "the C object is too small for its value") };
    let slot = (out as *mut O).cast::<Slot<O::Value>>();
    // SAFETY: as in `put`.
    unsafe {
        slot.write(Slot {
            free: 0,
            magic: O::MAGIC.wrapping_add(kind),
            value,
        })
    };
}

/// The kind in `object`'s tag word (`tag - O::MAGIC`: a constructor's kind,
/// 0 for the type's bare tag, anything for garbage; the caller's `match`
/// refuses what no constructor writes) and the value, which is a union:
/// any bytes are one, so it is viewed before the kind is checked.
#[inline]
pub(crate) fn get_kind<O: Opaque>(object: &mut O) -> (u32, &mut O::Value)
where
    O::Value: Union,
{
    const { assert!(fits::<O>(), "the C object is too small for its value") };
    // SAFETY: as in `header`, bytes 4 to 7 alone (8 to 11 are the union's,
    // possibly padding).
    let magic = unsafe {
        (object as *const O)
            .cast::<u8>()
            .add(4)
            .cast::<u32>()
            .read()
    };
    let slot = (object as *mut O).cast::<Slot<O::Value>>();
    // SAFETY: size and alignment are checked (`fits`); every bit pattern
    // is a value of a `Union`.
    (magic.wrapping_sub(O::MAGIC), unsafe { &mut (*slot).value })
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
