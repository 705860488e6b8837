//! Status codes: every function of the C ABI returns one.

use friction_core::ParamError;

/// What a call did: `FRICTION_OK` (0) or why it refused. Values are stable;
/// [`friction_status_name`] names each one. In C the type is an
/// `int32_t` (the enum names the values), the same size on every target.
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum friction_status {
    /// Success.
    FRICTION_OK = 0,
    /// A required pointer was NULL.
    FRICTION_NULL_POINTER = 1,
    /// The object was never initialised by its constructor (or belongs to
    /// another type).
    FRICTION_NOT_INITIALISED = 2,
    /// A parameter is NaN or infinite (the error names it).
    FRICTION_NOT_FINITE = 3,
    /// A parameter must be > 0.
    FRICTION_NOT_POSITIVE = 4,
    /// A parameter must be >= 0.
    FRICTION_NEGATIVE = 5,
    /// `fs` is below `fc`.
    FRICTION_STATIC_BELOW_COULOMB = 6,
    /// A parameter overflows the scalar type (f32).
    FRICTION_NOT_REPRESENTABLE = 7,
    /// A parameter, or a ratio built from it, underflows the scalar type.
    FRICTION_UNDERFLOW = 8,
    /// A force term overflows the scalar type at the velocity limit.
    FRICTION_FORCE_OVERFLOW = 9,
    /// A parameter lies outside 1e-20 ..= 1e20 in magnitude.
    FRICTION_OUT_OF_RANGE = 10,
    /// A parameter must be >= 1.
    FRICTION_BELOW_ONE = 11,
    /// Element weights do not sum to 1.
    FRICTION_WEIGHTS_NOT_ONE = 12,
    /// The period `h` differs from the one a fixed-step model was built for.
    FRICTION_PERIOD_MISMATCH = 13,
    /// A parameter must lie below another (the error names the first).
    FRICTION_NOT_BELOW = 14,
    /// The model has no observer (a static map), or no fixed-step form for
    /// `h > 0`.
    FRICTION_NOT_SUPPORTED = 15,
    /// A step input (`v`, `h`, `e`, `x` or a setpoint) was NaN or infinite,
    /// or `h < 0`: the state is unchanged, the output is the held force
    /// (or the servo's safe zero command).
    FRICTION_INPUT_REJECTED = 16,
    /// A commissioning routine has not finished: no result yet.
    FRICTION_NOT_FINISHED = 17,
    /// A commissioning routine stopped early (the error names the limit).
    FRICTION_ABORTED = 18,
    /// A commissioning run had fewer than three steady plateaus in a
    /// direction.
    FRICTION_TOO_FEW_PLATEAUS = 19,
    /// A commissioning fit missed its plateaus by more than 10 % of `fc`
    /// RMS.
    FRICTION_POOR_FIT = 20,
    /// A commissioning fit found no positive Coulomb level.
    FRICTION_NO_FRICTION = 21,
}

impl friction_status {
    /// The status for a core parameter error.
    pub(crate) fn from_param(error: ParamError) -> Self {
        match error {
            ParamError::NotFinite(_) => Self::FRICTION_NOT_FINITE,
            ParamError::NotPositive(_) => Self::FRICTION_NOT_POSITIVE,
            ParamError::Negative(_) => Self::FRICTION_NEGATIVE,
            ParamError::StaticBelowCoulomb => Self::FRICTION_STATIC_BELOW_COULOMB,
            ParamError::NotRepresentable(_) => Self::FRICTION_NOT_REPRESENTABLE,
            ParamError::Underflow(_) => Self::FRICTION_UNDERFLOW,
            ParamError::ForceOverflow(_) => Self::FRICTION_FORCE_OVERFLOW,
            ParamError::OutOfRange(_) => Self::FRICTION_OUT_OF_RANGE,
            ParamError::BelowOne(_) => Self::FRICTION_BELOW_ONE,
            ParamError::WeightsNotOne(_) => Self::FRICTION_WEIGHTS_NOT_ONE,
            ParamError::PeriodMismatch => Self::FRICTION_PERIOD_MISMATCH,
            ParamError::NotBelow { .. } => Self::FRICTION_NOT_BELOW,
        }
    }
}

/// Longest parameter name [`friction_error`] holds, NUL included.
pub const FRICTION_NAME_LEN: usize = 32;

/// What a constructor refused, for the caller to print: the status and the
/// offending parameter's name (NUL-terminated, empty when none applies).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_error {
    /// The status the constructor returned (a `friction_status` value; an
    /// `int32_t`, so that any bits C leaves here are valid).
    pub status: i32,
    /// The parameter's name as in the parameter files (`fs`, `sigma0`, ...).
    pub parameter: [u8; FRICTION_NAME_LEN],
}

impl friction_error {
    /// The error for `status`, naming `parameter` (cut to fit, NUL-terminated).
    pub(crate) fn new(status: friction_status, parameter: &str) -> Self {
        let mut name = [0u8; FRICTION_NAME_LEN];
        for (slot, byte) in name
            .iter_mut()
            .take(FRICTION_NAME_LEN - 1)
            .zip(parameter.bytes())
        {
            *slot = byte;
        }
        Self {
            status: status as i32,
            parameter: name,
        }
    }
}

/// Why a call refused, inside the crate: the status and the parameter it
/// names (empty when none applies).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Refusal {
    pub(crate) status: friction_status,
    pub(crate) parameter: &'static str,
}

impl Refusal {
    /// `status`, naming `parameter`.
    pub(crate) fn new(status: friction_status, parameter: &'static str) -> Self {
        Self { status, parameter }
    }

    /// Success.
    pub(crate) const OK: Self = Self {
        status: friction_status::FRICTION_OK,
        parameter: "",
    };

    /// The refusal of a core parameter check.
    pub(crate) fn param(error: ParamError) -> Self {
        let parameter = match error {
            ParamError::NotFinite(n)
            | ParamError::NotPositive(n)
            | ParamError::Negative(n)
            | ParamError::NotRepresentable(n)
            | ParamError::Underflow(n)
            | ParamError::ForceOverflow(n)
            | ParamError::OutOfRange(n)
            | ParamError::BelowOne(n)
            | ParamError::WeightsNotOne(n) => n,
            ParamError::StaticBelowCoulomb => "fs",
            ParamError::PeriodMismatch => "h",
            ParamError::NotBelow { name, .. } => name,
        };
        Self::new(friction_status::from_param(error), parameter)
    }
}

/// Returns the refusal's status and, when `error` is not NULL, fills it in.
pub(crate) fn report(error: Option<&mut friction_error>, r: Refusal) -> friction_status {
    if let Some(out) = error {
        *out = friction_error::new(r.status, r.parameter);
    }
    r.status
}

/// A short English description of `status` (a static NUL-terminated
/// string; "unknown status" for a value outside the enum).
#[no_mangle]
pub extern "C" fn friction_status_name(status: i32) -> *const core::ffi::c_char {
    let text: &'static core::ffi::CStr = match status {
        0 => c"ok",
        1 => c"a required pointer is NULL",
        2 => c"the object was not initialised by its constructor",
        3 => c"a parameter is not finite",
        4 => c"a parameter must be > 0",
        5 => c"a parameter must be >= 0",
        6 => c"fs must be >= fc (static friction below Coulomb)",
        7 => c"a parameter overflows the scalar type",
        8 => c"a parameter (or a ratio built from it) underflows the scalar type",
        9 => c"a force term overflows the scalar type at the velocity limit",
        10 => c"a parameter must lie within 1e-20 ..= 1e20 in magnitude",
        11 => c"a parameter must be >= 1",
        12 => c"the element weights must sum to 1",
        13 => c"h differs from the period the fixed-step model was built for",
        14 => c"a parameter must be below another",
        15 => c"not supported by this model",
        16 => c"an input was NaN or infinite (or h < 0): state unchanged",
        17 => c"the commissioning routine has not finished",
        18 => c"the commissioning routine was aborted by a limit or a fault",
        19 => c"too few steady plateaus to fit",
        20 => c"the friction curve fits the plateaus poorly (residual above 10 %)",
        21 => c"no positive Coulomb friction was measured",
        _ => c"unknown status",
    };
    text.as_ptr()
}
