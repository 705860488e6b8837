//! Model-free adaptive feed-forward: Coulomb + viscous friction (and
//! optionally a constant offset) fitted online by recursive least squares
//! with forgetting (Ljung & Söderström 1983; as friction identification:
//! Canudas de Wit & Lischinsky 1997): see [`RlsFeedForward`].

use crate::bits::Flag;
use crate::compensator::{Compensation, FrictionSample};
use crate::model::{convert, positive, ParamError};
use crate::Scalar;

/// Design-time parameters of the least-squares feed-forward, in `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RlsParams {
    /// Forgetting factor `0 < λ <= 1`.
    pub forgetting: f64,
    /// Minimum speed `v_min > 0` of a sample that updates the fit.
    pub min_speed: f64,
    /// Speed scale `v_ref > 0` of the viscous regressor `v / v_ref`.
    pub speed_scale: f64,
    /// Initial covariance `p0 > 0` (dimensionless).
    pub initial_covariance: f64,
    /// Bound `p_max >= p0` on the trace of the covariance; the scalar must
    /// hold twice it (three times with the offset), or the build refuses it.
    pub max_covariance: f64,
    /// Bound `F_max > 0` on each weight and on the estimate (force units).
    pub max_force: f64,
    /// Initial Coulomb level `w0` (force units), within `±F_max` (a negative
    /// one is fed forward as 0, see [`RlsFeedForward::force`]).
    pub initial_coulomb: f64,
    /// Initial viscous coefficient (force per speed unit), with
    /// `|coefficient v_ref| <= F_max`.
    pub initial_viscous: f64,
    /// Also fit a constant force offset `w2` (starting at 0): a Coulomb
    /// level per direction, `w0 ± w2`.
    pub offset: bool,
}

impl RlsParams {
    /// Checks every parameter; the error names the first offending one.
    ///
    /// ```
    /// use friction_core::RlsParams;
    /// let p = RlsParams::new(0.63, 10.0);
    /// assert!(p.validate().is_ok());
    /// assert!(RlsParams { forgetting: 1.5, ..p }.validate().is_err());
    /// ```
    pub fn validate(&self) -> Result<(), ParamError> {
        positive("forgetting", self.forgetting)?;
        if self.forgetting > 1.0 {
            return Err(ParamError::NotBelow {
                name: "forgetting",
                limit: "1 (inclusive)",
            });
        }
        positive("min_speed", self.min_speed)?;
        positive("speed_scale", self.speed_scale)?;
        positive("initial_covariance", self.initial_covariance)?;
        positive("max_covariance", self.max_covariance)?;
        if self.max_covariance < self.initial_covariance {
            return Err(ParamError::NotBelow {
                name: "initial_covariance",
                limit: "max_covariance (inclusive)",
            });
        }
        positive("max_force", self.max_force)?;
        let ok = |x: f64| x.is_finite() && x.abs() <= self.max_force;
        if !ok(self.initial_coulomb) {
            return Err(ParamError::NotBelow {
                name: "initial_coulomb",
                limit: "max_force in magnitude",
            });
        }
        if !ok(self.initial_viscous * self.speed_scale) {
            return Err(ParamError::NotBelow {
                name: "initial_viscous",
                limit: "max_force / speed_scale in magnitude",
            });
        }
        Ok(())
    }

    /// Defaults for a motion of peak speed `speed_scale` and friction below
    /// `max_force`: `λ = 0.999` (about a second of memory at 1 kHz),
    /// `v_min = speed_scale / 50`, `p0 = 10`, `p_max = 100`, starting from 0,
    /// no offset.
    pub fn new(speed_scale: f64, max_force: f64) -> Self {
        Self {
            forgetting: 0.999,
            min_speed: speed_scale / 50.0,
            speed_scale,
            initial_covariance: 10.0,
            max_covariance: 100.0,
            max_force,
            initial_coulomb: 0.0,
            initial_viscous: 0.0,
            offset: false,
        }
    }

    /// Validates and builds the run-time form.
    ///
    /// ```
    /// use friction_core::{CompensatorParams, CompensatorState, RlsParams, Setpoint};
    /// let rls = RlsParams::new(0.63, 10.0).build::<f32>()?;
    /// let servo = CompensatorParams {
    ///     h: 1e-3, kp: 60.0, ki: 200.0, kd: 1.2,
    ///     inertia: 0.0023, torque_constant: 1.02, limit: 10.0,
    /// }
    /// .build(rls)?;
    /// let mut state = CompensatorState::default();
    /// let tick = servo.tick(&mut state, 0.0, Setpoint { x: 1e-3, v: 0.1, a: 0.0 });
    /// assert!(tick.accepted && tick.friction == 0.0); // nothing learnt yet
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    pub fn build<S: Scalar>(&self) -> Result<RlsFeedForward<S>, ParamError> {
        self.validate()?;
        // the trace sums the diagonal's entries (three with the offset), each
        // up to the bound: the sum must be a number of S as well
        let entries = if self.offset { 3.0 } else { 2.0 };
        convert::<S>("max_covariance", entries * self.max_covariance)?;
        Ok(RlsFeedForward {
            inv_forgetting: convert("forgetting", 1.0 / self.forgetting)?,
            min_speed: convert("min_speed", self.min_speed)?,
            inv_speed_scale: convert("speed_scale", 1.0 / self.speed_scale)?,
            initial_covariance: convert("initial_covariance", self.initial_covariance)?,
            max_covariance: convert("max_covariance", self.max_covariance)?,
            max_force: convert("max_force", self.max_force)?,
            forgetting: convert("forgetting", self.forgetting)?,
            initial: [
                S::from_f64(self.initial_coulomb),
                S::from_f64(self.initial_viscous * self.speed_scale),
                S::ZERO,
            ],
            initial_offset_covariance: if self.offset {
                convert("initial_covariance", self.initial_covariance)?
            } else {
                S::ZERO
            },
            params: *self,
        })
    }
}

/// The state of an [`RlsFeedForward`]: weights and covariance. `Default` is
/// before the first sample (the built initial weights, `P = p0 I`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RlsState<S> {
    /// `false` until the first update: the weights are the built initial
    /// ones and `P = p0 I`, its offset's entry 0 without the offset (a
    /// byte: `crate::bits`).
    primed: Flag,
    /// `(Coulomb level, viscous weight, offset)`.
    w: [S; 3],
    /// `P` (symmetric) as `(p00, p01, p02, p11, p12, p22)`.
    p: [S; 6],
    updates: u32,
}

impl<S: Scalar> RlsState<S> {
    /// The number of samples that updated the fit (saturating).
    pub fn updates(&self) -> u32 {
        self.updates
    }
}

/// The built least-squares feed-forward: a [`Compensation`] that learns from
/// the compensator's [`FrictionSample`]s.
///
/// Model-free adaptive feed-forward: Coulomb + viscous friction, and with
/// [`RlsParams::offset`] a constant force offset, fitted online by recursive
/// least squares with forgetting (Ljung & Söderström 1983; as friction
/// identification: Canudas de Wit & Lischinsky 1997).
///
/// The compensator measures the friction residual over the last two periods
/// ([`FrictionSample`]: command force minus inertia times the measured
/// acceleration). Each sample above a minimum speed updates the weights `w`
/// of the regressors `φ = (sign v, v / v_ref, 1)`:
///
/// ```text
/// K = P φ / (λ + φᵀ P φ)
/// w = w + K (y - φᵀ w)
/// P = (P - K φᵀ P) / λ,   then scaled down to trace(P) <= p_max
/// F^ = sat(F_max, max(w0 + w2 sign v, 0) sign v + w1 v / v_ref)  on the measured velocity (0 at rest)
/// ```
///
/// so `w0` estimates the Coulomb level, `w1 / v_ref` the viscous
/// coefficient and `w2` the offset. Without the offset its covariance
/// starts (and stays) at 0, so `w2` stays 0: the fit is Coulomb + viscous
/// alone. With it the fit is the model offline identification fits (a
/// constant load such as an axis' cable or tilt), the same as a Coulomb
/// level per direction, `w0 + w2` forward and `w0 - w2` backward; on a
/// swinging joint it takes the part of gravity that correlates with the
/// direction for an offset. `v_ref` (the speed scale, e.g. the largest
/// speed of the motion) makes the regressors of order one, so that `P` is
/// dimensionless and one `p0` suits them all. Forgetting `λ < 1` follows
/// drift with a memory of about `1 / (1 - λ)` samples; a too small `λ`
/// follows the noise of a quantized acceleration. Samples below `v_min` are
/// skipped (at rest the sign regressor is meaningless and the residual is
/// stiction), and nothing is forgotten without a sample, so a standstill
/// cannot wind `P` up; the trace bound holds it bounded in any case, and
/// `|w| <= F_max`. An update whose denominator `λ + φᵀPφ` falls below
/// `λ / 2` (a `P` rounding has left indefinite) restarts `P` at its
/// initial value and keeps `w`.
///
/// `P` starts at `p0 I` (its offset's entry 0 without the offset) and `w`
/// at 0 (or the given initial weights): the first samples move `w` fast,
/// by about `p0 / (1 + p0)` of each residual.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RlsFeedForward<S> {
    forgetting: S,
    inv_forgetting: S,
    min_speed: S,
    inv_speed_scale: S,
    initial_covariance: S,
    /// `p0` with the offset, 0 without.
    initial_offset_covariance: S,
    max_covariance: S,
    max_force: S,
    initial: [S; 3],
    params: RlsParams,
}

impl<S: Scalar> RlsFeedForward<S> {
    /// The parameters it was built from.
    pub fn params(&self) -> &RlsParams {
        &self.params
    }

    /// The fitted `(Coulomb level, viscous coefficient)` of `state`.
    pub fn coefficients(&self, state: &RlsState<S>) -> (f64, f64) {
        let [w0, w1, _] = self.weights(state);
        (w0.to_f64(), w1.to_f64() * self.inv_speed_scale.to_f64())
    }

    /// The fitted force offset of `state` (0 without
    /// [`RlsParams::offset`]).
    pub fn offset(&self, state: &RlsState<S>) -> f64 {
        let [_, _, w2] = self.weights(state);
        w2.to_f64()
    }

    /// The trace of the covariance `P`.
    pub fn covariance_trace(&self, state: &RlsState<S>) -> S {
        let [p00, _, _, p11, _, p22] = self.covariance(state);
        p00 + p11 + p22
    }

    fn weights(&self, state: &RlsState<S>) -> [S; 3] {
        if state.primed.get() {
            state.w
        } else {
            self.initial
        }
    }

    fn covariance(&self, state: &RlsState<S>) -> [S; 6] {
        let p0 = self.initial_covariance;
        if state.primed.get() {
            state.p
        } else {
            [
                p0,
                S::ZERO,
                S::ZERO,
                p0,
                S::ZERO,
                self.initial_offset_covariance,
            ]
        }
    }

    /// The regressor `(sign v, v / v_ref, 1)`, the second within the
    /// scalar's velocity limit.
    #[inline]
    fn regressor(&self, v: S) -> [S; 3] {
        [
            v.sign(),
            (v * self.inv_speed_scale).sat(S::VELOCITY_LIMIT),
            S::ONE,
        ]
    }

    /// The estimate `max(w0 + w2 sign v, 0) sign v + w1 v / v_ref` within
    /// `±F_max` (0 at rest).
    ///
    /// A Coulomb level is never negative: a fit that makes one negative has
    /// taken a load that changes sign with the direction (gravity on a
    /// swinging joint) for friction, and fed forward it would push along
    /// the motion. The fit itself keeps it (the least squares stay
    /// unbiased); only the feed-forward drops it.
    #[inline]
    pub fn force(&self, state: &RlsState<S>, v: S) -> S {
        if !v.is_finite() {
            return S::ZERO;
        }
        let [w0, w1, w2] = self.weights(state);
        let [sign, speed, _] = self.regressor(v.sat(S::VELOCITY_LIMIT));
        let level = (w0 + w2 * sign).max(S::ZERO);
        let viscous = (w1 * speed).sat(self.max_force);
        (level * sign + viscous).sat(self.max_force)
    }

    /// One least-squares update from a sample: skipped below the minimum
    /// speed and for a non-finite sample.
    pub fn update(&self, state: &mut RlsState<S>, sample: FrictionSample<S>) {
        let (y, v) = (sample.force, sample.v);
        if !(y.is_finite() && v.is_finite()) || v.abs() <= self.min_speed {
            return;
        }
        let y = y.sat(self.max_force + self.max_force + self.max_force + self.max_force);
        let w = self.weights(state);
        let [p00, p01, p02, p11, p12, p22] = self.covariance(state);
        let phi = self.regressor(v);
        let [f0, f1, f2] = phi;
        // P φ and φᵀ P φ (P symmetric)
        let a0 = p00 * f0 + p01 * f1 + p02 * f2;
        let a1 = p01 * f0 + p11 * f1 + p12 * f2;
        let a2 = p02 * f0 + p12 * f1 + p22 * f2;
        let denom = self.forgetting + f0 * a0 + f1 * a1 + f2 * a2;
        if denom < S::from_f64(0.5) * self.forgetting {
            // φᵀ P φ < -λ / 2: rounding has left P indefinite (the pairwise
            // bound below holds a 2x2 P semi-definite, not a 3x3 one; with
            // the offset, motion in one direction makes sign v and 1 the
            // same regressor): start the covariance afresh, keep the weights
            state.p = self.covariance(&RlsState::default());
            state.w = w;
            state.primed = Flag::new(true);
            return;
        }
        let (k0, k1, k2) = (a0 / denom, a1 / denom, a2 / denom);
        let [w0, w1, w2] = w;
        // without the offset p02 = p12 = p22 = 0, so k2 = 0 and w2 stays 0
        let err = y - (w0 * f0 + w1 * f1 + w2 * f2);
        let w = [
            (w0 + k0 * err).sat(self.max_force),
            (w1 + k1 * err).sat(self.max_force),
            (w2 + k2 * err).sat(self.max_force),
        ];
        // P - K (P φ)ᵀ, over λ
        let over = self.inv_forgetting;
        let q00 = ((p00 - k0 * a0) * over).max(S::ZERO);
        let q11 = ((p11 - k1 * a1) * over).max(S::ZERO);
        let q22 = ((p22 - k2 * a2) * over).max(S::ZERO);
        // against rounding: q_ij^2 <= q_ii q_jj, as a semi-definite P's are
        let q01 = within_geometric_mean((p01 - k0 * a1) * over, q00, q11);
        let q02 = within_geometric_mean((p02 - k0 * a2) * over, q00, q22);
        let q12 = within_geometric_mean((p12 - k1 * a2) * over, q11, q22);
        let mut q = [q00, q01, q02, q11, q12, q22];
        // trace bound
        let trace = q00 + q11 + q22;
        if trace > self.max_covariance {
            let shrink = self.max_covariance / trace;
            q = q.map(|x| x * shrink);
        }
        if !(w.iter().all(|x| x.is_finite()) && q.iter().all(|x| x.is_finite())) {
            return;
        }
        state.w = w;
        state.p = q;
        state.primed = Flag::new(true);
        state.updates = state.updates.saturating_add(1);
    }
}

/// `q` with `q^2 <= a b` (for `a, b >= 0`): an off-diagonal covariance
/// bounded by its diagonal, as a positive semi-definite matrix's are.
#[inline]
fn within_geometric_mean<S: Scalar>(q: S, a: S, b: S) -> S {
    let det = a * b;
    if q * q > det && q != S::ZERO {
        det / q
    } else {
        q
    }
}

/// The feed-forward `F^ = max(w0 + w2 sign v, 0) sign v + w1 v / v_ref` on
/// the measured velocity, learning from every sample the compensator
/// measures.
impl<S: Scalar> Compensation<S> for RlsFeedForward<S> {
    type State = RlsState<S>;
    const LEARNS: bool = true;
    const USES_H: bool = false;
    #[inline]
    fn estimate(&self, state: &mut RlsState<S>, v: S, _e: S, _h: S) -> S {
        self.force(state, v)
    }
    #[inline]
    fn learn(&self, state: &mut RlsState<S>, sample: FrictionSample<S>) {
        self.update(state, sample);
    }
    /// Restarts the fit from this one's initial weights and covariance:
    /// the old fit's confidence belongs to the old settings.
    fn carry_over(&self, _old: &Self, state: &mut RlsState<S>) {
        *state = RlsState::default();
    }
}
