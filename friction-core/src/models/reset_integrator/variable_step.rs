//! The reset integrator's step: [`ResetIntegrator`].

use crate::bits::Flag;
use crate::model::{checked_inputs, FrictionModel};
use crate::observer::Observable;
use crate::stribeck::StribeckCurve;
use crate::Scalar;

/// The built reset integrator.
///
/// The reset integrator (Haessig & Friedland 1991).
///
/// ```text
/// dz/dt = 0   if (v > 0 and z >= z0) or (v < 0 and z <= -z0),   else v
/// F     = (1 + a(z)) sigma0(v) z + sigma1 dz/dt,   a(z) = a if |z| < z0, else 0
/// ```
///
/// One bond strain `z` grows with the displacement until the breakaway
/// deflection `z0`, where it stops ("resets" the integrator). While
/// `|z| < z0` the stiction factor `a` raises the force; it drops to
/// `sigma0 z0` once the bond breaks: the force is discontinuous in `z`.
/// With the optional Stribeck curve, `sigma0(v) = sigma0 g(v) / Fs`.
///
/// Discretisation: with `v` held, `z` moves by `v h` and stops exactly at
/// `±z0` within the step (the switching instant is handled inside the
/// step, not at its end). Exact for held `v`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ResetIntegrator<S> {
    pub(super) sigma0: S,
    pub(super) sigma1: S,
    pub(super) z0: S,
    pub(super) a: S,
    /// The Stribeck curve, if `shaped` (stored as a curve and a flag, not
    /// an `Option`: see `crate::bits`).
    pub(super) curve: StribeckCurve<S>,
    pub(super) shaped: Flag,
    pub(super) inv_fs: S,
}

/// The reset-integrator state: the bond strain `z` (m), within `±z0`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ResetIntegratorState<S> {
    /// Bond strain `z`.
    pub z: S,
}

impl<S: Scalar> ResetIntegrator<S> {
    /// `sigma0(v)`.
    #[inline]
    fn stiffness(&self, v: S) -> S {
        if self.shaped.get() {
            self.sigma0 * (self.curve.eval(v) * self.inv_fs)
        } else {
            self.sigma0
        }
    }

    /// `(1 + a(z)) sigma0(v) z`.
    #[inline]
    fn elastic(&self, z: S, v: S) -> S {
        let a = if z.abs() < self.z0 { self.a } else { S::ZERO };
        (S::ONE + a) * (self.stiffness(v) * z)
    }

    /// The breakaway deflection `z0`.
    pub fn z0(&self) -> S {
        self.z0
    }
}

impl<S: Scalar> ResetIntegrator<S> {
    /// One step of the bond strain driven by `u = v - c` (`c` an observer's
    /// correction, 0 for the model): `z + u h`, stopped at `±z0` inside the
    /// step; the bond rate `dz/dt` is `u`, or 0 once the bond has reset.
    /// `h = 0` leaves the state untouched.
    #[inline]
    fn advance(&self, state: &mut ResetIntegratorState<S>, v: S, c: S, h: S) -> S {
        let u = v - c;
        let z = state.z;
        let (z_next, dz) = if h > S::ZERO {
            let zn = z + u * h;
            let reset = zn.abs() >= self.z0;
            let zn = zn.sat(self.z0);
            state.z = zn;
            (zn, if reset { S::ZERO } else { u })
        } else if z.abs() >= self.z0 && u * z > S::ZERO {
            (z, S::ZERO)
        } else {
            (z, u)
        };
        self.elastic(z_next, v) + self.sigma1 * dz
    }
}

impl<S: Scalar> FrictionModel<S> for ResetIntegrator<S> {
    type State = ResetIntegratorState<S>;

    fn step(&self, state: &mut ResetIntegratorState<S>, v: S, h: S) -> S {
        match checked_inputs(v, h) {
            Some(v) => self.advance(state, v, S::ZERO, h),
            None => self.hold_force(state),
        }
    }

    /// `(1 + a(z)) sigma0 z` at `v = 0`.
    fn hold_force(&self, state: &ResetIntegratorState<S>) -> S {
        self.elastic(state.z, S::ZERO)
    }
}

/// Observer form: the correction offsets the velocity that strains the bond.
/// The bond has no separate damping state: `damping` has no effect (the
/// `sigma1 dz/dt` term is part of the force law).
impl<S: Scalar> Observable<S> for ResetIntegrator<S> {
    fn step_corrected(
        &self,
        state: &mut ResetIntegratorState<S>,
        v: S,
        correction: S,
        h: S,
        _damping: bool,
    ) -> S {
        self.advance(state, v, correction, h)
    }

    /// `(1 + a) sigma0(v) z0 + sigma1 |v|`.
    fn force_bound(&self, v: S) -> S {
        (S::ONE + self.a) * (self.stiffness(v) * self.z0) + self.sigma1 * v.abs()
    }
}
