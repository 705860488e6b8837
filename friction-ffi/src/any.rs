//! The core's models behind one type per family, so that the core's
//! generic observer and compensator run on whichever model C built: each
//! family implements the core traits by dispatching on its kind.
//!
//! C hands these back as bytes, so each family is stored in a form every
//! bit pattern is a value of: a `u32` kind and a `union` of the models
//! (a Rust `enum` here would make every kind word but a few undefined
//! behaviour to read). A dispatch that meets a kind no constructor writes
//! does nothing (force 0) and never reads the union; [`Variable::is_valid`]
//! and friends let the observer and servo constructors refuse such a model.
//!
//! A state starts as `REST` (its `Default`, which the core's generic code
//! asks for); the first step turns it into the model's own state at rest,
//! so that a state can never step with another model's union field.

// the capacities the model list's core types are named with
use crate::params::{
    FRICTION_BRISTLES as BRISTLES, FRICTION_ELEMENTS as ELEMENTS, FRICTION_LEUVEN_MEMORY as MEMORY,
};
use friction_core::{
    BristleState, DahlState, FixedStepModel, FixedStepObservable, FrictionModel, GmsSlipMode,
    GmsState, LeuvenState, LuGreFixedStepState, LuGreState, Observable, ResetIntegratorState,
    Scalar, XiongFixedStepState, XiongState,
};

/// The kind of a state before its first step (no union field written).
/// Models count their kinds from 0 (a `match` on them needs no offset
/// before its jump table), so a state at rest takes the last `u32`.
const REST: u32 = u32::MAX;

/// Declares a family: the model (kind and union), its state (kind and
/// union, `REST` until the first step), the kinds, a constructor per kind
/// and the checks.
macro_rules! family {
    (
        $(#[$doc:meta])* $model:ident, $union:ident, $state:ident, $state_union:ident, $tr:ident,
        $kinds:ident, [$($field:ident: $ty:ty),* $(,)?]
    ) => {
        /// The kind of each union field (named as the field: the dispatch
        /// matches a kind by the field's name, so the two cannot disagree),
        /// counted from 0 in the list's order.
        #[allow(non_upper_case_globals)]
        mod $kinds {
            #[allow(non_camel_case_types, dead_code)]
            #[repr(u32)]
            enum Order {
                $($field,)*
            }
            $(pub(super) const $field: u32 = Order::$field as u32;)*
        }

        $(#[$doc])*
        #[derive(Clone, Copy)]
        #[repr(C)]
        pub(crate) struct $model<S: Scalar> {
            kind: u32,
            u: $union<S>,
        }

        /// The models of the family; the field read is the one `kind` names.
        #[derive(Clone, Copy)]
        #[repr(C)]
        #[allow(non_snake_case)]
        union $union<S: Scalar> {
            $($field: $ty,)*
        }

        /// The state of the model of the same kind; `REST` until the first step.
        #[derive(Clone, Copy)]
        #[allow(dead_code)] // a static map's state is `()`
        #[repr(C)]
        pub(crate) struct $state<S: Scalar> {
            kind: u32,
            u: $state_union<S>,
        }

        /// The states of the family; `rest` (nothing) for `REST`.
        #[derive(Clone, Copy)]
        #[repr(C)]
        union $state_union<S: Scalar> {
            rest: (),
            $($field: <$ty as $tr<S>>::State,)*
        }

        #[allow(dead_code)]
        impl<S: Scalar> $model<S> {
            $(
                /// The model of this kind.
                pub(crate) fn $field(model: $ty) -> Self {
                    Self { kind: $kinds::$field, u: $union { $field: model } }
                }
            )*

            /// Whether the kind is one a constructor writes (so the union
            /// field it names was written, by a constructor or C's copy of it).
            #[inline]
            pub(crate) fn is_valid(&self) -> bool {
                matches!(self.kind, $($kinds::$field)|*)
            }

            /// Makes `state` this model's state at rest (a state of another
            /// kind, or `REST`, before the first step).
            #[cold]
            #[inline(never)]
            fn own<'a>(&self, state: &'a mut $state<S>) -> &'a mut $state<S> {
                *state = match self.kind {
                    $($kinds::$field => $state {
                        kind: $kinds::$field,
                        u: $state_union { $field: Default::default() },
                    },)*
                    _ => $state::default(),
                };
                state
            }
        }

        impl<S: Scalar> Default for $state<S> {
            fn default() -> Self {
                Self { kind: REST, u: $state_union { rest: () } }
            }
        }

        // the union's bytes are not printed: only the kind says which they are
        impl<S: Scalar> core::fmt::Debug for $model<S> {
            fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                f.debug_struct(stringify!($model)).field("kind", &self.kind).finish_non_exhaustive()
            }
        }

        impl<S: Scalar> core::fmt::Debug for $state<S> {
            fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                f.debug_struct(stringify!($state)).field("kind", &self.kind).finish_non_exhaustive()
            }
        }
    };
}

/// A state whose bytes may need making valid before they are read as it:
/// the core stores its private fields in forms every bit pattern is a value
/// of, but a public field may hold an enum (GMS's slip modes), which C's
/// bytes may not be a value of.
trait Repair {
    /// Makes the bytes at `state` a value of `Self` where they are not
    /// (a public enum field's byte outside its discriminants becomes one of
    /// them); nothing for a state of numbers.
    ///
    /// # Safety
    ///
    /// `state` is aligned and valid for reads and writes of a `Self`; its
    /// bytes may be any (they are read as bytes only).
    #[inline(always)]
    unsafe fn repair(state: *mut Self) {
        let _ = state;
    }
}

impl Repair for () {}
impl<S: Scalar, const N: usize> Repair for BristleState<S, N> {}
impl<S: Scalar> Repair for ResetIntegratorState<S> {}
impl<S: Scalar> Repair for DahlState<S> {}
impl<S: Scalar> Repair for LuGreState<S> {}
impl<S: Scalar> Repair for LuGreFixedStepState<S> {}
impl<S: Scalar, const M: usize> Repair for LeuvenState<S, M> {}
impl<S: Scalar, const N: usize> Repair for XiongState<S, N> {}
impl<S: Scalar, const N: usize> Repair for XiongFixedStepState<S, N> {}

/// GMS's public `mode` field: each byte read as a byte and written back as
/// the mode `GmsSlipMode::from_byte` reads it as (a `repr(u8)` enum: one byte
/// each), so that a byte no mode has becomes `Stick` before the array is
/// read as `GmsSlipMode`s.
impl<S: Scalar, const N: usize> Repair for GmsState<S, N> {
    #[inline]
    unsafe fn repair(state: *mut Self) {
        const { assert!(core::mem::size_of::<GmsSlipMode>() == 1) };
        // SAFETY: `state` is valid (the caller); the field's N modes are
        // N bytes (`repr(u8)`), each read and written as a `u8`.
        unsafe {
            let modes = core::ptr::addr_of_mut!((*state).mode).cast::<u8>();
            for i in 0..N {
                let byte = modes.add(i);
                byte.write(GmsSlipMode::from_byte(byte.read()) as u8);
            }
        }
    }
}

/// `$body` with `$m` and `$s` bound to the model and its state, for the
/// model's kind; an unknown kind gives `S::ZERO` (never reached: the calls
/// check the kind first). A state of another kind (or `REST`) is first
/// made the model's own at rest (`own`, off the hot path).
macro_rules! each {
    ($kinds:ident, $self:expr, $st:expr, |$m:ident, $s:ident| $body:expr, [$($field:ident: $ty:ty),* $(,)?]) => {{
        let model = $self;
        let state = $st;
        let state = if state.kind == model.kind { state } else { model.own(state) };
        match model.kind {
            $(
                // SAFETY: the model's kind is this arm's, and a kind is only
                // ever written together with the union field it names (by
                // the constructors and `own`; C may copy them), C's bytes
                // in that field being read as it (any bytes are a value of
                // the core's stored forms: see slot.rs); the state's kind is
                // the model's (`own` made it so when it was not).
                $kinds::$field => {
                    // SAFETY: the state's union field is inside `state`, a
                    // unique reference, and aligned; `repair` reads its
                    // bytes as bytes only.
                    unsafe { Repair::repair(core::ptr::addr_of_mut!(state.u.$field)) };
                    let ($m, $s) = unsafe { (&model.u.$field, &mut state.u.$field) };
                    $body
                }
            )*
            _ => S::ZERO,
        }
    }};
}

/// `$body` with `$m`, `$o` and `$s` bound to the model, the old model
/// (`$old`, another model of the family) and the state, when the two models
/// and the state are of one kind; otherwise the state is put back to
/// `REST` (a change of model starts the new one at rest, as its first step
/// would).
macro_rules! each_pair {
    ($kinds:ident, $self:expr, $old:expr, $st:expr, |$m:ident, $o:ident, $s:ident| $body:expr, [$($field:ident: $ty:ty),* $(,)?]) => {{
        let (model, old, state) = ($self, $old, $st);
        if old.kind != model.kind || state.kind != model.kind {
            *state = Default::default();
        } else {
            match model.kind {
                $(
                    $kinds::$field => {
                        // SAFETY: as in `each`: the three kinds are this
                        // arm's, each written with the union field it names
                        // (C's bytes in it read as it); `repair` reads the
                        // state's bytes as bytes only.
                        unsafe { Repair::repair(core::ptr::addr_of_mut!(state.u.$field)) };
                        let ($m, $o, $s) =
                            unsafe { (&model.u.$field, &old.u.$field, &mut state.u.$field) };
                        $body
                    }
                )*
                _ => *state = Default::default(),
            }
        }
    }};
}

/// `$body` with `$m` bound to the model, for the model's kind (no state).
macro_rules! each_model {
    ($kinds:ident, $self:expr, |$m:ident| $body:expr, $default:expr, [$($field:ident: $ty:ty),* $(,)?]) => {{
        let model = $self;
        match model.kind {
            // SAFETY: as in `each`: the kind names the union field written.
            $($kinds::$field => {
                let $m = unsafe { &model.u.$field };
                $body
            })*
            _ => $default,
        }
    }};
}

/// The C ABI's reading of the core's model list
/// (`friction_core::model_list!`): each form's models, passed on to
/// `families!` as one list per family.
macro_rules! dispatch {
    ($(
        $(#[$doc:meta])* $variant:ident = $name:literal {
            params: $params:ty,
            field: $field:ident,
            $(map: $map:ty,)?
            $(variable: $variable:ty,)?
            $(fixed: $fixed:ty,)?
            sets: [$($set:literal),* $(,)?],
        }
    )*) => {
        families! {
            statics: [$($($field: $map,)?)*],
            variables: [$($($field: $variable,)?)*],
            fixeds: [$($($field: $fixed,)?)*],
        }

        /// The snake-case names of the models the C ABI builds
        /// (`friction_<name>_init_f32/_f64`), for the test that each has its
        /// constructors.
        #[cfg(test)]
        pub(crate) const C_MODELS: &[&str] = &[
            $($(named!($field, $map),)? $(named!($field, $variable),)?)*
        ];
    };
}

/// `$field` as a string (a helper of `dispatch!`: a repetition that `$form`
/// drives yields the name of each model that has the form).
#[cfg(test)]
macro_rules! named {
    ($field:ident, $($form:tt)*) => {
        stringify!($field)
    };
}

/// The three families and their dispatch, each from its list of
/// `field: type` (the union field and the core type of its form).
macro_rules! families {
    (statics: $statics:tt, variables: $variables:tt, fixeds: $fixeds:tt,) => {
        family!(
            /// A static map: no state.
            StaticMap, StaticMapUnion, StaticMapState, StaticMapStateUnion, FrictionModel,
            static_kind, $statics
        );

        family!(
            /// A variable-step state model (stepped with its `h` each call).
            Variable, VariableUnion, VariableState, VariableStateUnion, FrictionModel,
            variable_kind, $variables
        );

        family!(
            /// A fixed-step state model (built for one period).
            Fixed, FixedUnion, FixedState, FixedStateUnion, FixedStepModel, fixed_kind, $fixeds
        );

        impl<S: Scalar> FrictionModel<S> for StaticMap<S> {
            type State = ();

            fn step(&self, state: &mut (), v: S, h: S) -> S {
                each_model!(static_kind, self, |m| m.step(state, v, h), S::ZERO, $statics)
            }

            fn hold_force(&self, state: &()) -> S {
                each_model!(static_kind, self, |m| m.hold_force(state), S::ZERO, $statics)
            }
        }

        impl<S: Scalar> FrictionModel<S> for Variable<S> {
            type State = VariableState<S>;

            fn step(&self, state: &mut Self::State, v: S, h: S) -> S {
                each!(variable_kind, self, state, |m, s| m.step(s, v, h), $variables)
            }

            fn hold_force(&self, state: &Self::State) -> S {
                let mut copy = *state;
                each!(variable_kind, self, &mut copy, |m, s| m.hold_force(s), $variables)
            }
        }

        impl<S: Scalar> Observable<S> for Variable<S> {
            fn step_corrected(
                &self,
                state: &mut Self::State,
                v: S,
                correction: S,
                h: S,
                damping: bool,
            ) -> S {
                each!(
                    variable_kind,
                    self,
                    state,
                    |m, s| m.step_corrected(s, v, correction, h, damping),
                    $variables
                )
            }

            fn force_bound(&self, v: S) -> S {
                each_model!(variable_kind, self, |m| m.force_bound(v), S::ZERO, $variables)
            }

            fn carry_over(&self, old: &Self, state: &mut Self::State) {
                each_pair!(variable_kind, self, old, state, |m, o, s| m.carry_over(o, s), $variables)
            }
        }

        impl<S: Scalar> FixedStepModel<S> for Fixed<S> {
            type State = FixedState<S>;

            fn period(&self) -> f64 {
                // an unknown kind (never reached: the calls check it) has no period
                each_model!(fixed_kind, self, |m| m.period(), 0.0, $fixeds)
            }

            #[inline]
            fn step(&self, state: &mut Self::State, v: S) -> S {
                each!(fixed_kind, self, state, |m, s| m.step(s, v), $fixeds)
            }

            fn hold_force(&self, state: &Self::State) -> S {
                let mut copy = *state;
                each!(fixed_kind, self, &mut copy, |m, s| m.hold_force(s), $fixeds)
            }
        }

        impl<S: Scalar> FixedStepObservable<S> for Fixed<S> {
            #[inline]
            fn step_corrected(
                &self,
                state: &mut Self::State,
                v: S,
                correction: S,
                damping: bool,
            ) -> S {
                each!(
                    fixed_kind,
                    self,
                    state,
                    |m, s| m.step_corrected(s, v, correction, damping),
                    $fixeds
                )
            }

            fn force_bound(&self, v: S) -> S {
                each_model!(fixed_kind, self, |m| m.force_bound(v), S::ZERO, $fixeds)
            }

            fn carry_over(&self, old: &Self, state: &mut Self::State) {
                each_pair!(fixed_kind, self, old, state, |m, o, s| m.carry_over(o, s), $fixeds)
            }
        }
    };
}

friction_core::model_list!(dispatch);

#[cfg(test)]
mod tests {
    /// Each model of the list that the C ABI builds has its two
    /// constructors in the header (written by hand: cbindgen reads no macro
    /// output), so a model added to the list without them fails here.
    #[test]
    fn every_listed_model_has_its_constructors() {
        let header = include_str!("../include/friction.h");
        for field in super::C_MODELS {
            for scalar in ["f32", "f64"] {
                let name = std::format!("friction_{field}_init_{scalar}(");
                assert!(header.contains(&name), "{name} is missing from friction.h");
            }
        }
    }
}
