//! Caller-allocated storage: where C's bytes become Rust values.
//!
//! C allocates each object (`friction_model_f64`, ...) as a plain array of
//! 64-bit words whose size the header states. A constructor writes a tag
//! word and a value into it: the value is a `union` (of the models, the
//! observers or the compensators), and the tag word is the object type's
//! 32-bit `MAGIC` plus the kind (from 1) of the union field written. Every
//! later call reads the tag word as a `u32`, subtracts `MAGIC` and matches
//! the kind; a kind no constructor writes (C's garbage, a `memset`, an
//! object of another type, or a bare `MAGIC`: kind 0) is refused before any
//! union field is read. A union of `Copy` types is a value for any bytes,
//! so nothing is formed from C's bytes that could be invalid before the
//! check. The size and alignment of each value are checked at compile
//! time; every stored value is `Copy` (no destructor, no pointer into
//! itself), so C may copy an initialised object with `memcpy` or
//! assignment.
//!
//! The model kinds inside (LuGre, Dahl, ...) are a `u32` and a union too
//! (`crate::any`), whose dispatch never reads a union field for a kind no
//! constructor writes.
//!
//! Behind a right tag word, C's bytes are read as the core's values: a
//! tag-correct object whose other bytes C changed (or a random pattern
//! with a chance of a few in 2^32) is viewed as the model, observer or
//! compensator it claims to be. So `friction_core` stores every private
//! field in a form that any bytes are a value of (its `bits` module:
//! flags as bytes read `!= 0`, choices as bytes decoded totally, an
//! optional curve as a curve and a flag) and bounds the integers where it
//! uses them (the bristle model's re-bond budget, the elasto-plastic
//! sub-step count, the adaptive observer's scale exponent, counters); the
//! one public field that is an enum, GMS's slip modes, is made valid by
//! `crate::any` (`Repair`) before the state is viewed. Such an object gives
//! garbage numbers and a documented status, never undefined behaviour, a
//! panic or a long loop (`tests/garbage.rs`, under Miri too).

/// A C-visible object of `WORDS` 64-bit words holding one `Value`.
pub(crate) trait Opaque: Sized {
    /// What the object holds: a union, its field named by the kind in the
    /// tag word.
    type Value: Union;
    /// The object type's tag: one per object type, so that a
    /// never-initialised object (or one of another type) is refused. It
    /// repeats one byte, `0xB1` to `0xB6`, neither ASCII text nor a usual
    /// fill pattern (`0x00`, `0xFF`, `0xAA`, `0x55`, `0xCD`, `0xDEADBEEF`)
    /// that reused memory could hold; and Thumb-2 encodes `-(MAGIC + 1)` as
    /// an instruction's immediate, so the check of the tag word is one
    /// `add`, one `cmp` and the jump table of the kinds (the servo tick
    /// through the C ABI, budgeted at 1.10x the Rust tick's instructions on
    /// the Cortex-M4F, counts them). 32 bits, not 64: a 64-bit tag took two
    /// `eor`s and an `orr` more a call.
    const MAGIC: u32;
}

/// A value that is a `union` of `Copy` types, so that every bit pattern is
/// a value of it; which field holds data is the kind in the tag word.
///
/// # Safety
///
/// Only for `union`s of `Copy` types.
pub(crate) unsafe trait Union: Copy {}

/// What a constructor builds (a Rust `enum`), with its stored form.
pub(crate) trait Built {
    /// The union an object stores.
    type Stored: Union;
    /// The kind (from 1) and the union with the field it names written.
    fn stored(self) -> (u32, Self::Stored);
}

/// The layout a constructor writes: the tag word (the object's first 32
/// bits), then the value.
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

/// Writes `value` into `out` with the tag word `O::MAGIC + kind`.
pub(crate) fn put_kind<O: Opaque>(out: &mut O, kind: u32, value: O::Value) {
    const { assert!(fits::<O>(), "the C object is too small for its value") };
    let slot = (out as *mut O).cast::<Slot<O::Value>>();
    // SAFETY: `fits` checked size and alignment; `out` is a unique
    // reference, so the words are ours to overwrite; `Slot` is `Copy` data.
    unsafe {
        slot.write(Slot {
            magic: O::MAGIC.wrapping_add(kind),
            value,
        })
    };
}

/// The kind in the tag word (`tag - O::MAGIC`: a constructor's kind, 0 for
/// the type's bare tag, anything for garbage), read as a `u32`.
#[inline]
fn kind<O: Opaque>(object: &O) -> u32 {
    const { assert!(fits::<O>(), "the C object is too small for its value") };
    // SAFETY: the object's first 32 bits are inside it and aligned (`fits`;
    // objects are arrays of `u64`); they hold C's bytes or a tag word this
    // module wrote (never padding, which may follow them), and every bit
    // pattern is a `u32`.
    let magic = unsafe { (object as *const O).cast::<u32>().read() };
    magic.wrapping_sub(O::MAGIC)
}

/// The kind in `object`'s tag word and its value, a union: any bytes are
/// one, so it is viewed before the caller's `match` on the kind refuses
/// what no constructor writes.
#[inline]
pub(crate) fn get_kind<O: Opaque>(object: &mut O) -> (u32, &mut O::Value) {
    let kind = kind(object);
    let slot = (object as *mut O).cast::<Slot<O::Value>>();
    // SAFETY: size and alignment are checked (`fits`); every bit pattern
    // is a value of a `Union`.
    (kind, unsafe { &mut (*slot).value })
}

/// [`get_kind`] read-only.
pub(crate) fn get_kind_ref<O: Opaque>(object: &O) -> (u32, &O::Value) {
    let kind = kind(object);
    let slot = (object as *const O).cast::<Slot<O::Value>>();
    // SAFETY: as in `get_kind`.
    (kind, unsafe { &(*slot).value })
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
