//! The core's models behind one type per family, so that the core's
//! generic observer and compensator run on whichever model C built: each
//! enum implements the core traits by dispatching on its variant.
//!
//! A state enum starts as `Rest` (its `Default`, which the core's generic
//! code asks for); the first step turns it into the model's own state at
//! rest, so that a state can never step with another model's variant.

use crate::params::{FRICTION_BRISTLES, FRICTION_ELEMENTS, FRICTION_LEUVEN_MEMORY};
use friction_core::{
    Bristle, CoulombViscous, Dahl, DahlAt, ElastoPlastic, ElastoPlasticAt, FixedStepModel,
    FixedStepObservable, FrictionModel, Gms, GmsAt, Leuven, LuGre, LuGreAt, Observable,
    ResetIntegrator, Scalar, StribeckMap, Xiong, XiongAt,
};

/// A static map: no state.
#[derive(Clone, Copy, Debug)]
pub(crate) enum StaticMap<S> {
    CoulombViscous(CoulombViscous<S>),
    StribeckMap(StribeckMap<S>),
}

impl<S: Scalar> FrictionModel<S> for StaticMap<S> {
    type State = ();

    fn step(&self, state: &mut (), v: S, h: S) -> S {
        match self {
            Self::CoulombViscous(m) => m.step(state, v, h),
            Self::StribeckMap(m) => m.step(state, v, h),
        }
    }

    fn hold_force(&self, state: &()) -> S {
        match self {
            Self::CoulombViscous(m) => m.hold_force(state),
            Self::StribeckMap(m) => m.hold_force(state),
        }
    }
}

/// Declares a model enum, its state enum and their dispatch.
macro_rules! family {
    (
        $(#[$doc:meta])* $model:ident, $state:ident, $tr:ident,
        [$($variant:ident: $ty:ty),* $(,)?]
    ) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug)]
        pub(crate) enum $model<S: Scalar> {
            $($variant($ty),)*
        }

        /// The state of the matching model variant; `Rest` until the first step.
        #[derive(Clone, Copy, Debug, Default)]
        pub(crate) enum $state<S: Scalar> {
            #[default]
            Rest,
            $($variant(<$ty as $tr<S>>::State),)*
        }

        impl<S: Scalar> $model<S> {
            /// Makes `state` this model's state at rest (a state of another
            /// variant, or `Rest`, before the first step).
            #[cold]
            #[inline(never)]
            fn own<'a>(&self, state: &'a mut $state<S>) -> &'a mut $state<S> {
                *state = match self {
                    $(Self::$variant(_) => $state::$variant(Default::default()),)*
                };
                state
            }
        }
    };
}

family!(
    /// A variable-step state model (stepped with its `h` each call).
    Variable, VariableState, FrictionModel,
    [
        Bristle: Bristle<S, FRICTION_BRISTLES>,
        ResetIntegrator: ResetIntegrator<S>,
        Dahl: Dahl<S>,
        LuGre: LuGre<S>,
        ElastoPlastic: ElastoPlastic<S>,
        Leuven: Leuven<S, FRICTION_LEUVEN_MEMORY>,
        Gms: Gms<S, FRICTION_ELEMENTS>,
        Xiong: Xiong<S, FRICTION_ELEMENTS>,
    ]
);

family!(
    /// A fixed-step state model (built for one period).
    Fixed, FixedState, FixedStepModel,
    [
        Dahl: DahlAt<S>,
        LuGre: LuGreAt<S>,
        ElastoPlastic: ElastoPlasticAt<S>,
        Gms: GmsAt<S, FRICTION_ELEMENTS>,
        Xiong: XiongAt<S, FRICTION_ELEMENTS>,
    ]
);

/// `$body` with `$m` and `$s` bound to the model and its state, for every
/// variant of a family. A state of another variant (or `Rest`) is first
/// made the model's own at rest (`own`, off the hot path).
macro_rules! each {
    ($model:ident, $state:ident, $self:expr, $st:expr, |$m:ident, $s:ident| $body:expr,
     [$($variant:ident),*]) => {{
        let state = $st;
        let matched = matches!((&*$self, &*state), $(($model::$variant(_), $state::$variant(_)))|*);
        let state = if matched { state } else { $self.own(state) };
        match ($self, state) {
            $(($model::$variant($m), $state::$variant($s)) => $body,)*
            // unreachable: `own` made the state match the model
            _ => S::ZERO,
        }
    }};
}

macro_rules! each_variable {
    ($self:expr, $st:expr, |$m:ident, $s:ident| $body:expr) => {
        each!(
            Variable,
            VariableState,
            $self,
            $st,
            |$m, $s| $body,
            [
                Bristle,
                ResetIntegrator,
                Dahl,
                LuGre,
                ElastoPlastic,
                Leuven,
                Gms,
                Xiong
            ]
        )
    };
}

macro_rules! each_fixed {
    ($self:expr, $st:expr, |$m:ident, $s:ident| $body:expr) => {
        each!(
            Fixed,
            FixedState,
            $self,
            $st,
            |$m, $s| $body,
            [Dahl, LuGre, ElastoPlastic, Gms, Xiong]
        )
    };
}

impl<S: Scalar> FrictionModel<S> for Variable<S> {
    type State = VariableState<S>;

    fn step(&self, state: &mut Self::State, v: S, h: S) -> S {
        each_variable!(self, state, |m, s| m.step(s, v, h))
    }

    fn hold_force(&self, state: &Self::State) -> S {
        let mut copy = *state;
        each_variable!(self, &mut copy, |m, s| m.hold_force(s))
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
        each_variable!(self, state, |m, s| m
            .step_corrected(s, v, correction, h, damping))
    }

    fn force_bound(&self, v: S) -> S {
        match self {
            Self::Bristle(m) => m.force_bound(v),
            Self::ResetIntegrator(m) => m.force_bound(v),
            Self::Dahl(m) => m.force_bound(v),
            Self::LuGre(m) => m.force_bound(v),
            Self::ElastoPlastic(m) => m.force_bound(v),
            Self::Leuven(m) => m.force_bound(v),
            Self::Gms(m) => m.force_bound(v),
            Self::Xiong(m) => m.force_bound(v),
        }
    }
}

impl<S: Scalar> FixedStepModel<S> for Fixed<S> {
    type State = FixedState<S>;

    fn period(&self) -> f64 {
        match self {
            Self::Dahl(m) => m.period(),
            Self::LuGre(m) => m.period(),
            Self::ElastoPlastic(m) => m.period(),
            Self::Gms(m) => m.period(),
            Self::Xiong(m) => m.period(),
        }
    }

    #[inline]
    fn step(&self, state: &mut Self::State, v: S) -> S {
        each_fixed!(self, state, |m, s| m.step(s, v))
    }

    fn hold_force(&self, state: &Self::State) -> S {
        let mut copy = *state;
        each_fixed!(self, &mut copy, |m, s| m.hold_force(s))
    }
}

impl<S: Scalar> FixedStepObservable<S> for Fixed<S> {
    #[inline]
    fn step_corrected(&self, state: &mut Self::State, v: S, correction: S, damping: bool) -> S {
        each_fixed!(self, state, |m, s| m
            .step_corrected(s, v, correction, damping))
    }

    fn force_bound(&self, v: S) -> S {
        match self {
            Self::Dahl(m) => m.force_bound(v),
            Self::LuGre(m) => m.force_bound(v),
            Self::ElastoPlastic(m) => m.force_bound(v),
            Self::Gms(m) => m.force_bound(v),
            Self::Xiong(m) => m.force_bound(v),
        }
    }
}
