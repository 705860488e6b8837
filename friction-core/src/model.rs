//! The shape every model follows, and the error its parameters can raise: see
//! [`FrictionModel`].

use crate::scalar::ScalarConversion;
use crate::Scalar;
use core::fmt;

/// Why a parameter set was rejected. Each variant names the parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ParamError {
    /// The parameter is NaN or infinite.
    NotFinite(&'static str),
    /// The parameter must be strictly positive.
    NotPositive(&'static str),
    /// The parameter must not be negative.
    Negative(&'static str),
    /// The static (breakaway) friction `fs` is below the Coulomb level `fc`.
    StaticBelowCoulomb,
    /// The parameter is finite in `f64` but overflows the chosen scalar type.
    NotRepresentable(&'static str),
    /// The parameter (or a quantity derived from it, such as `Fc / sigma0`)
    /// is non-zero but underflows (to zero or a subnormal), or loses more
    /// than 0.1 % to rounding, in the chosen scalar type.
    Underflow(&'static str),
    /// A force term carrying this parameter overflows the chosen scalar type
    /// for some `|v| <= VELOCITY_LIMIT` (e.g. `sigma2 * 1e6`).
    ForceOverflow(&'static str),
    /// The parameter's magnitude lies outside [`PARAM_RANGE`] (it may be 0
    /// where 0 is allowed): beyond it a product or ratio of parameters
    /// could leave the scalar's range inside a step.
    OutOfRange(&'static str),
    /// The parameter (an exponent) must be `>= 1`.
    BelowOne(&'static str),
    /// The weights named by the parameter (one per element) must sum to 1
    /// within 1e-9.
    WeightsNotOne(&'static str),
    /// The compensator's sample period `h` differs (by more than 1e-9
    /// relative) from the period its fixed-step model was built for.
    PeriodMismatch,
    /// The parameter must lie strictly below a limit set by other parameters.
    NotBelow {
        /// The offending parameter.
        name: &'static str,
        /// The limit, as an expression of other parameters.
        limit: &'static str,
    },
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotFinite(name) => write!(f, "parameter `{name}` is not finite"),
            Self::NotPositive(name) => write!(f, "parameter `{name}` must be > 0"),
            Self::Negative(name) => write!(f, "parameter `{name}` must be >= 0"),
            Self::StaticBelowCoulomb => {
                write!(
                    f,
                    "parameter `fs` must be >= `fc` (static friction below Coulomb)"
                )
            }
            Self::NotRepresentable(name) => {
                write!(f, "parameter `{name}` overflows the chosen scalar type")
            }
            Self::Underflow(name) => write!(
                f,
                "parameter `{name}` (or a ratio built from it) underflows the chosen scalar type"
            ),
            Self::ForceOverflow(name) => write!(
                f,
                "a force term with parameter `{name}` overflows the chosen scalar type at the velocity limit"
            ),
            Self::OutOfRange(name) => write!(
                f,
                "parameter `{name}` must lie within 1e-20 ..= 1e20 in magnitude"
            ),
            Self::BelowOne(name) => write!(f, "parameter `{name}` must be >= 1"),
            Self::WeightsNotOne(name) => write!(
                f,
                "the element weights `{name}` must sum to 1 (within 1e-9)"
            ),
            Self::PeriodMismatch => write!(
                f,
                "parameter `h` differs from the period the fixed-step model was built for"
            ),
            Self::NotBelow { name, limit } => {
                write!(f, "parameter `{name}` must be below `{limit}`")
            }
        }
    }
}

impl core::error::Error for ParamError {}

/// Checks that `value` is finite and `> 0`.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64, ParamError> {
    if !value.is_finite() {
        Err(ParamError::NotFinite(name))
    } else if value <= 0.0 {
        Err(ParamError::NotPositive(name))
    } else {
        Ok(value)
    }
}

/// The magnitudes a model parameter may take, whatever its unit: 1e-20 to
/// 1e20, far beyond any mechanism (stiffnesses to 1e9 N/m, deflections and
/// Stribeck velocities to 1e-9) and narrow enough that a product or ratio
/// of a few parameters, a velocity up to [`VELOCITY_LIMIT`] and a period
/// stays finite and normal in `f64` (the whole-range property test,
/// `tests/whole_range.rs`, draws parameters over all of `f64`).
pub const PARAM_RANGE: (f64, f64) = (1e-20, 1e20);

/// A model parameter: finite, `> 0`, within [`PARAM_RANGE`].
pub(crate) fn magnitude(name: &'static str, value: f64) -> Result<f64, ParamError> {
    let value = positive(name, value)?;
    if (PARAM_RANGE.0..=PARAM_RANGE.1).contains(&value) {
        Ok(value)
    } else {
        Err(ParamError::OutOfRange(name))
    }
}

/// A model parameter that may be 0: finite, `>= 0`, 0 or within [`PARAM_RANGE`].
pub(crate) fn magnitude_or_zero(name: &'static str, value: f64) -> Result<f64, ParamError> {
    if non_negative(name, value)? == 0.0 {
        Ok(0.0)
    } else {
        magnitude(name, value)
    }
}

/// Checks that `value` is finite and `>= 0`.
pub(crate) fn non_negative(name: &'static str, value: f64) -> Result<f64, ParamError> {
    if !value.is_finite() {
        Err(ParamError::NotFinite(name))
    } else if value < 0.0 {
        Err(ParamError::Negative(name))
    } else {
        Ok(value)
    }
}

/// Converts a validated `f64` into the run-time scalar with
/// [`Scalar::try_from_f64`]: overflow is [`ParamError::NotRepresentable`];
/// a non-zero value that underflows or loses more than 0.1 % to rounding is
/// [`ParamError::Underflow`].
pub(crate) fn convert<S: Scalar>(name: &'static str, value: f64) -> Result<S, ParamError> {
    // `+ 0.0`: a parameter of -0 (which validation lets through as 0) is
    // carried as +0, so that no product with it flips the sign of a zero
    S::try_from_f64(value + 0.0).map_err(|e| match e {
        ScalarConversion::Overflow => ParamError::NotRepresentable(name),
        ScalarConversion::Underflow | ScalarConversion::Rounding => ParamError::Underflow(name),
    })
}

/// Converts a quantity derived in `f64` from validated non-zero parameters
/// (a ratio such as `Fc / sigma0`, a product such as `sigma0 h`): besides
/// [`convert`]'s checks, a result that already underflowed in `f64` (to zero
/// or a subnormal) is [`ParamError::Underflow`], not a silent zero.
pub(crate) fn convert_derived<S: Scalar>(name: &'static str, value: f64) -> Result<S, ParamError> {
    if value.is_finite() && !value.is_normal() {
        return Err(ParamError::Underflow(name));
    }
    convert(name, value)
}

/// Checks that a force magnitude (computed in `f64` from the parameters at
/// the velocity limit) fits the scalar type with a margin of 4 for
/// intermediate sums; the error names the parameter that carries it.
pub(crate) fn check_force<S: Scalar>(name: &'static str, magnitude: f64) -> Result<(), ParamError> {
    match S::try_from_f64(4.0 * magnitude) {
        Err(ScalarConversion::Overflow) => Err(ParamError::ForceOverflow(name)),
        _ => Ok(()),
    }
}

/// Magnitude above which input velocities are clamped, in the model's units
/// (m/s or rad/s). Far beyond any mechanism, it keeps every intermediate
/// product finite in `f32`.
pub const VELOCITY_LIMIT: f64 = 1e6;

/// A friction model driven by the sliding velocity.
///
/// The shape every model follows, and the error its parameters can raise.
///
/// A model comes in three parts (after quartiq/idsp):
///
/// - `XxxParams`: design-time parameters in `f64`, checked by `validate()`;
/// - `Xxx<S>`: the built run-time form (`XxxParams::build::<S>()`), immutable,
///   with reciprocals precomputed, shared by any number of states;
/// - `XxxState<S>`: the mutable internal state (`Default` is at rest);
/// - and, with a fixed-step form, `XxxFixedStep<S>`
///   (`XxxParams::build_fixed_step::<S>(h)`, a
///   [`FixedStepModel`](crate::FixedStepModel)) and its state
///   `XxxFixedStepState<S>`. Where a form reuses another's state, its
///   state name is an alias of that state (`ElastoPlasticState<S> =
///   LuGreState<S>`, `DahlFixedStepState<S> = DahlState<S>`).
///
/// The hot path, [`FrictionModel::step`], never fails and never panics.
///
/// `step` advances the state over a sample period `h` with the velocity `v`
/// held, and returns the friction force at the end of the step. `F` opposes
/// motion: in steady sliding `sign(F) = sign(v)`.
///
/// Contract, for every model:
/// - `h = 0` is valid: the state is bitwise unchanged and the force at the
///   current state and velocity is returned;
/// - a non-finite `v` or `h`, or a negative `h`, leaves the state untouched and
///   returns the model's [`FrictionModel::hold_force`], which is finite;
/// - `|v|` is clamped to [`VELOCITY_LIMIT`];
/// - it never panics, never allocates, and returns a finite force: `build()`
///   rejects any parameter set whose forces could overflow the scalar type
///   for `|v| <= VELOCITY_LIMIT`, or whose parameters underflow in it.
pub trait FrictionModel<S: Scalar> {
    /// The internal state; `Default` is the contact at rest, unstrained.
    type State: Copy + Default + fmt::Debug;

    /// Advances `state` by `h` seconds with velocity `v` held; returns the force.
    fn step(&self, state: &mut Self::State, v: S, h: S) -> S;

    /// The force the state alone holds, returned when an input is invalid
    /// (for state models the elastic force `sigma0 z` at `v = 0`).
    fn hold_force(&self, state: &Self::State) -> S;
}

/// Returns `Some(v clamped to the velocity limit)` when `v` and `h` are usable inputs.
#[inline]
pub(crate) fn checked_inputs<S: Scalar>(v: S, h: S) -> Option<S> {
    if v.is_finite() && h.is_finite() && h >= S::ZERO {
        Some(v.sat(S::VELOCITY_LIMIT))
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checks_name_the_parameter() {
        assert_eq!(positive("vs", 0.0), Err(ParamError::NotPositive("vs")));
        assert_eq!(positive("vs", f64::NAN), Err(ParamError::NotFinite("vs")));
        assert_eq!(
            non_negative("sigma2", -1.0),
            Err(ParamError::Negative("sigma2"))
        );
        assert_eq!(non_negative("sigma2", 0.0), Ok(0.0));
        assert_eq!(
            convert::<f32>("sigma0", 1e300),
            Err(ParamError::NotRepresentable("sigma0"))
        );
    }

    /// Every state model: NaN, infinite or negative inputs leave the state
    /// untouched and return the (finite) hold force.
    fn check_invalid_inputs<M: FrictionModel<f32>>(model: &M)
    where
        M::State: PartialEq,
    {
        let mut state = M::State::default();
        for k in 0..50 {
            model.step(&mut state, 1e-3 * (k as f32 * 0.3).sin(), 1e-3);
        }
        let before = state;
        for (v, h) in [
            (f32::NAN, 1e-3),
            (f32::INFINITY, 1e-3),
            (0.1, f32::NAN),
            (0.1, -1e-3),
            (0.1, f32::INFINITY),
        ] {
            let f = model.step(&mut state, v, h);
            assert!(state == before, "state changed for v {v}, h {h}");
            assert_eq!(f, model.hold_force(&state));
            assert!(f.is_finite());
        }
    }

    #[test]
    fn invalid_inputs_never_poison_any_model() {
        use crate::*;
        let lugre = LuGreParams::CANUDAS_1995;
        check_invalid_inputs(&lugre.build::<f32>().unwrap());
        check_invalid_inputs(
            &ElastoPlasticParams { lugre, z_ba: 5e-6 }
                .build::<f32>()
                .unwrap(),
        );
        check_invalid_inputs(
            &DahlParams {
                sigma: 1e5,
                fc: 1.0,
                delta: 1.5,
                sigma2: 0.4,
            }
            .build::<f32>()
            .unwrap(),
        );
        let reset = ResetIntegratorParams {
            sigma0: 1e5,
            sigma1: 300.0,
            z0: 1e-5,
            stiction: 0.5,
            curve: None,
        };
        check_invalid_inputs(&reset.build::<f32>().unwrap());
        check_invalid_inputs(
            &BristleParams {
                sigma0: 1e3,
                delta_s: 1e-6,
                seed: 3,
            }
            .build::<f32, 8>()
            .unwrap(),
        );
    }

    #[test]
    fn invalid_inputs_are_detected() {
        assert_eq!(checked_inputs(1.0f64, 0.0), Some(1.0));
        assert_eq!(checked_inputs(f64::NAN, 1e-3), None);
        assert_eq!(checked_inputs(1.0f64, f64::INFINITY), None);
        assert_eq!(checked_inputs(1.0f64, -1e-3), None);
        assert_eq!(checked_inputs(1e9f32, 1e-3), Some(1e6));
    }
}
