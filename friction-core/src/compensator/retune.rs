//! Re-tuning a running drive: a new compensation (a model from
//! commissioning, a host, a user) swapped in between two ticks without a
//! bump.
//!
//! The swap touches only the compensation and its state: the integral
//! action, the last position, the velocity estimate (filter or observer)
//! and the gains are those of the running loop. The compensation's state
//! is carried over by [`Compensation::carry_over`]: an observer keeps the
//! force its state holds (LuGre's elastic force `sigma0 z`, within the new
//! `±Fs`), an adaptive law restarts its estimates from the new model's
//! nominal values, a least-squares fit restarts, a supervisor keeps its
//! applied mode and restarts its evidence. So at the first tick after the
//! swap, against the same tick without it,
//!
//! ```text
//! |u_swapped - u_kept| <= |F^_new - F^_old| / kc
//! ```
//!
//! where `F^_new` and `F^_old` are the two compensations' estimates at that
//! tick (each term is clamped and the command saturated, both of which can
//! only shrink a difference). One exception: on a tick where one of the two
//! commands saturates, the conditional integration may integrate in one
//! and not the other, adding at most `ki h |e|` (an integral step).
//!
//! How large `F^_new - F^_old` is depends on the models, not on the loop:
//! with force-continuous carry-over it is the change of the viscous and
//! damping terms and of the first step's relaxation toward the new curve;
//! a model without its own carry-over (only LuGre and Dahl have one among
//! the state models) restarts at rest and loses its elastic force.

use super::{runs_at, Compensation, Compensator, CompensatorState};
use crate::model::ParamError;
use crate::Scalar;

impl<S: Scalar, C: Compensation<S>> Compensator<S, C> {
    /// This compensator with `compensation` in place of its own: the same
    /// loop (gains, limit, velocity filter or observer). Refuses a
    /// compensation built for another period, as
    /// [`CompensatorParams::build`](crate::CompensatorParams::build) does
    /// ([`ParamError::PeriodMismatch`]). The states of the axes it is to
    /// drive must then be carried over ([`Compensator::carry_over`]); for
    /// one axis, [`Compensator::retune`] does both.
    pub fn retuned(&self, compensation: C) -> Result<Self, ParamError> {
        runs_at(&compensation, self.params.h)?;
        Ok(Self {
            compensation,
            ..*self
        })
    }

    /// Makes `state`, an axis driven by `old` until now, an axis of this
    /// compensator: the compensation's state is carried over
    /// ([`Compensation::carry_over`]), the rest of the axis (integral, last
    /// position, velocity estimate) is kept as it is.
    pub fn carry_over(&self, old: &Self, state: &mut CompensatorState<S, C::State>) {
        self.compensation
            .carry_over(&old.compensation, &mut state.friction);
    }

    /// Swaps in `compensation` between two ticks of the axis `state`. The
    /// loop and the axis's integral, last position and velocity estimate
    /// are kept; the compensation's state is carried over
    /// ([`Compensation::carry_over`]: an observer keeps the force its state
    /// holds where the new model's bounds allow, an adaptive law restarts at
    /// the new nominal values, a supervisor keeps its applied mode and
    /// restarts its evidence). So at the next tick, against the same tick
    /// without the swap,
    ///
    /// ```text
    /// |u_swapped - u_kept| <= |F^_new - F^_old| / kc
    /// ```
    ///
    /// with `F^_new`, `F^_old` the two compensations' estimates at that tick
    /// (the term clamps and the command limit only shrink a difference);
    /// on a tick where one of the two commands saturates, conditional
    /// integration may add one integral step, at most `ki h |e|`.
    ///
    /// On an error (a compensation built for another period:
    /// [`ParamError::PeriodMismatch`]) neither the compensator nor the
    /// state is touched.
    ///
    /// A compensator shared by several axes is re-tuned with
    /// [`retuned`](Self::retuned) and [`carry_over`](Self::carry_over) on
    /// each axis, between the same two ticks:
    ///
    /// ```
    /// use friction_core::{FixedPeriod, CompensatorParams, CompensatorState, LuGreParams, Observer, ParamError, Setpoint};
    /// let p = CompensatorParams { h: 1e-3, kp: 60.0, ki: 200.0, kd: 1.2,
    ///     inertia: 0.0023, torque_constant: 1.02, limit: 10.0 };
    /// let first = LuGreParams::OLSSON_1998.build_fixed_step::<f32>(1e-3)?;
    /// let mut servo = p.build(FixedPeriod(Observer::new(first, 20.0)?))?;
    /// let mut axis = CompensatorState::default();
    /// let r = Setpoint { x: 0.0, v: 0.1, a: 0.0 };
    /// for k in 0..100 {
    ///     servo.tick(&mut axis, 1e-4 * k as f32, r);
    /// }
    /// // commissioning measured more friction: swap it in, one axis
    /// let measured = LuGreParams { sigma0: 400.0, sigma2: 0.03, ..LuGreParams::OLSSON_1998 };
    /// servo.retune(&mut axis, FixedPeriod(Observer::new(measured.build_fixed_step(1e-3)?, 20.0)?))?;
    /// let tick = servo.tick(&mut axis, 1e-2, r);
    /// assert!(tick.accepted && tick.command.abs() <= 10.0);
    /// // a model for another period is refused, the axis untouched
    /// let before = axis;
    /// let other = FixedPeriod(Observer::new(measured.build_fixed_step(5e-4)?, 20.0)?);
    /// assert_eq!(servo.retune(&mut axis, other).err(), Some(ParamError::PeriodMismatch));
    /// assert_eq!(axis, before);
    /// // several axes on one compensator: one new compensator, each axis carried over
    /// let (mut a, mut b) = (axis, axis);
    /// let next = servo.retuned(FixedPeriod(Observer::new(first, 20.0)?))?;
    /// next.carry_over(&servo, &mut a);
    /// next.carry_over(&servo, &mut b);
    /// servo = next;
    /// # let _ = (servo, a, b);
    /// # Ok::<(), ParamError>(())
    /// ```
    pub fn retune(
        &mut self,
        state: &mut CompensatorState<S, C::State>,
        compensation: C,
    ) -> Result<(), ParamError> {
        let next = self.retuned(compensation)?;
        next.carry_over(self, state);
        *self = next;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_servo::olsson_servo as servo;
    use crate::{
        AdaptiveParams, CoulombViscousParams, FixedPeriod, FrictionModel, LuGreParams, LuGreState,
        Observer, ParameterAdaptiveParams, RlsParams, Setpoint, SupervisorParams,
    };
    use proptest::prelude::*;
    use std::vec;
    use std::vec::Vec;

    /// The commissioning result the tests swap in: every parameter the
    /// observer uses moved (stiffer bristles, higher levels, more viscous
    /// friction).
    const MEASURED: LuGreParams = LuGreParams {
        curve: crate::StribeckParams {
            fc: 0.36,
            fs: 0.45,
            vs: 0.01,
            exponent: 2.0,
        },
        sigma0: 650.0,
        sigma1: 0.6,
        sigma2: 0.03,
        vd: None,
    };

    /// What a swap did: the command step at the swap tick against the
    /// same tick without it, the bound `|F^_new - F^_old| / kc` (NaN
    /// without a swap), and the RMS tracking error over the last second.
    #[derive(Debug)]
    struct Swap {
        bump: f64,
        bound: f64,
        tail: f64,
    }

    /// The Olsson plant (LuGre in f64 at 100 kHz, its levels `scale` times
    /// the 1998 ones) on `0.5 sin(2 pi 0.2 t)` rad under `ctl` for
    /// `seconds`; at tick `at` the compensation becomes `next`.
    fn run<S: Scalar, C: Compensation<S> + Copy>(
        ctl: Compensator<S, C>,
        next: C,
        at: usize,
        seconds: usize,
        scale: f64,
    ) -> (Swap, Compensator<S, C>, CompensatorState<S, C::State>) {
        run_with(ctl, next, at, seconds, scale, true)
    }

    /// [`run`], with the compensation's state carried over (`carry`) or
    /// restarted at rest (what a swap without carry-over would do).
    fn run_with<S: Scalar, C: Compensation<S> + Copy>(
        mut ctl: Compensator<S, C>,
        next: C,
        at: usize,
        seconds: usize,
        scale: f64,
        carry: bool,
    ) -> (Swap, Compensator<S, C>, CompensatorState<S, C::State>) {
        let plant = LuGreParams {
            curve: crate::StribeckParams {
                fc: 0.28 * scale,
                fs: 0.33 * scale,
                ..LuGreParams::OLSSON_1998.curve
            },
            ..LuGreParams::OLSSON_1998
        }
        .build::<f64>()
        .unwrap();
        let mut ps = LuGreState::default();
        let mut state = CompensatorState::default();
        let (mut x, mut v) = (0.0f64, 0.0f64);
        let w = 2.0 * core::f64::consts::PI * 0.2;
        let mut errors = Vec::new();
        let (mut bump, mut bound) = (f64::NAN, f64::NAN);
        for k in 0..seconds * 1000 {
            let t = k as f64 * 1e-3;
            let r = Setpoint {
                x: S::from_f64(0.5 * libm::sin(w * t)),
                v: S::from_f64(0.5 * w * libm::cos(w * t)),
                a: S::from_f64(-0.5 * w * w * libm::sin(w * t)),
            };
            let measured = S::from_f64(x);
            let tick = if k == at {
                let (mut kept_state, kept) = (state, ctl);
                let kept = kept.tick(&mut kept_state, measured, r);
                ctl.retune(&mut state, next).unwrap();
                if !carry {
                    state.friction = Default::default();
                }
                let tick = ctl.tick(&mut state, measured, r);
                bump = (tick.command - kept.command).to_f64().abs();
                bound = (tick.friction - kept.friction).to_f64().abs() / 1.02;
                tick
            } else {
                ctl.tick(&mut state, measured, r)
            };
            assert!(tick.accepted && tick.command.to_f64().abs() <= 10.0);
            let u = tick.command.to_f64();
            for _ in 0..100 {
                let f = plant.step(&mut ps, v, 1e-5);
                v += 1e-5 * (1.02 * u - f) / 0.0023;
                x += 1e-5 * v;
            }
            errors.push(x - r.x.to_f64());
        }
        let rms = |e: &[f64]| libm::sqrt(e.iter().map(|e| e * e).sum::<f64>() / e.len() as f64);
        let swap = Swap {
            bump,
            bound,
            tail: rms(&errors[errors.len() - 1000..]),
        };
        (swap, ctl, state)
    }

    /// The stated tolerance on the bound: the two commands round their sums
    /// apart, so two units in the last place of the loop's limit (10) in a
    /// float, two steps of Q16.16 (1/65536).
    fn tolerance<S: Scalar>() -> f64 {
        if S::from_f64(1.0 + 1e-9) != S::ONE {
            2.0 * f64::EPSILON * 10.0
        } else if S::ALWAYS_FINITE {
            2.0 / 65536.0
        } else {
            2.0 * f64::from(f32::EPSILON) * 10.0
        }
    }

    fn observer_fixed<S: Scalar>(
        p: LuGreParams,
    ) -> FixedPeriod<Observer<crate::LuGreFixedStep<S>, S>> {
        FixedPeriod(Observer::new(p.build_fixed_step::<S>(1e-3).unwrap(), 20.0).unwrap())
    }

    /// Swaps at a reversal (t = 1.25 s), mid-stroke (2.3 s) and near the
    /// peak speed (2.5 s).
    const SWAPS: [usize; 3] = [1250, 2300, 2500];

    /// No swap in the run.
    const NEVER: usize = usize::MAX;

    fn check(name: &str, swap: &Swap, tol: f64) {
        assert!(swap.bump <= swap.bound + tol, "{name}: {swap:?}");
        // the model changed: the bound is not vacuous (0 would make the test trivial)
        assert!(swap.bound > 0.0, "{name}: {swap:?}");
    }

    /// Each swap of `runs` (the last is the new compensation all along)
    /// within its bound, and tracking as well as the new compensation
    /// all along in the last second (the plant has the measured levels).
    fn tracks_on(name: &str, runs: &[Swap], tol: f64) {
        let (all_along, swaps) = runs.split_last().unwrap();
        for swap in swaps {
            check(name, swap, tol);
            assert!(
                swap.tail <= 1.1 * all_along.tail,
                "{name}: {swap:?} {all_along:?}"
            );
        }
    }

    #[test]
    fn the_lugre_observer_swaps_with_a_step_within_the_estimate_change() {
        fn each<S: Scalar>() -> Vec<Swap> {
            let ctl = servo()
                .build(Observer::new(LuGreParams::OLSSON_1998.build::<S>().unwrap(), 20.0).unwrap())
                .unwrap();
            let next = Observer::new(MEASURED.build::<S>().unwrap(), 20.0).unwrap();
            let mut out: Vec<Swap> = SWAPS.map(|at| run(ctl, next, at, 5, 1.3).0).into();
            // the measured model all along
            out.push(run(ctl.retuned(next).unwrap(), next, NEVER, 5, 1.3).0);
            out
        }
        for (s, tol) in [
            (each::<f64>(), tolerance::<f64>()),
            (each::<f32>(), tolerance::<f32>()),
        ] {
            tracks_on("lugre", &s, tol);
        }
        // at a reversal the bristle holds nearly all the friction: carried
        // over, the step is a small part of it; restarted at rest, most of it
        let ctl = servo()
            .build(Observer::new(LuGreParams::OLSSON_1998.build::<f64>().unwrap(), 20.0).unwrap())
            .unwrap();
        let next = Observer::new(MEASURED.build::<f64>().unwrap(), 20.0).unwrap();
        let carried = run(ctl, next, SWAPS[0], 2, 1.3).0;
        let restarted = run_with(ctl, next, SWAPS[0], 2, 1.3, false).0;
        assert!(carried.bump < 0.01 * 0.28 / 1.02, "{carried:?}");
        assert!(restarted.bump > 0.5 * 0.28 / 1.02, "{restarted:?}");
    }

    #[test]
    fn the_fixed_step_observer_swaps_with_a_step_within_the_estimate_change() {
        fn each<S: Scalar>() -> Vec<Swap> {
            let ctl = servo()
                .build(observer_fixed::<S>(LuGreParams::OLSSON_1998))
                .unwrap();
            let next = observer_fixed::<S>(MEASURED);
            let mut out: Vec<Swap> = SWAPS.map(|at| run(ctl, next, at, 5, 1.3).0).into();
            out.push(run(ctl.retuned(next).unwrap(), next, NEVER, 5, 1.3).0);
            out
        }
        #[cfg_attr(not(feature = "fixed"), allow(unused_mut))]
        let mut all = vec![
            (each::<f64>(), tolerance::<f64>()),
            (each::<f32>(), tolerance::<f32>()),
        ];
        #[cfg(feature = "fixed")]
        all.push((each::<crate::Fixed32>(), tolerance::<crate::Fixed32>()));
        for (s, tol) in all {
            tracks_on("lugre at", &s, tol);
        }
    }

    /// The elastic force is what is carried: swapping to a model with
    /// another stiffness keeps `sigma0 z`, and clamps it to the new `Fs`.
    #[test]
    fn the_lugre_state_keeps_its_force_within_the_new_bound() {
        let old = LuGreParams::OLSSON_1998.build::<f64>().unwrap();
        let new = MEASURED.build::<f64>().unwrap();
        let mut s = LuGreState { z: 0.3 / 260.0 };
        crate::Observable::carry_over(&new, &old, &mut s);
        assert!((new.hold_force(&s) - 0.3).abs() < 1e-12, "{s:?}");
        // back to a model whose Fs (0.2) is below the force held
        let low = LuGreParams {
            curve: crate::StribeckParams {
                fc: 0.15,
                fs: 0.2,
                ..MEASURED.curve
            },
            ..MEASURED
        }
        .build::<f64>()
        .unwrap();
        crate::Observable::carry_over(&low, &new, &mut s);
        assert_eq!(s.z, low.z_max());
    }

    #[test]
    fn the_parameter_adaptive_law_restarts_at_the_new_values() {
        fn each<S: Scalar>() -> (Vec<Swap>, f64) {
            let fallback = |fc: f64| {
                CoulombViscousParams { fc, sigma2: 0.0176 }
                    .build::<S>()
                    .unwrap()
            };
            let sup = SupervisorParams {
                tolerance: 0.01 * 0.28,
                ..SupervisorParams::DEFAULT
            };
            let law = |m: LuGreParams| {
                let p = ParameterAdaptiveParams {
                    speed: 0.63,
                    ..ParameterAdaptiveParams::new(m, 20.0)
                };
                sup.build(
                    p.build_fixed_step::<S>(&servo()).unwrap(),
                    fallback(m.curve.fc),
                    &servo(),
                )
                .unwrap()
            };
            let ctl = servo().build(law(LuGreParams::OLSSON_1998)).unwrap();
            let next = law(MEASURED);
            let mut out: Vec<Swap> = SWAPS.map(|at| run(ctl, next, at, 5, 1.3).0).into();
            out.push(run(ctl.retuned(next).unwrap(), next, NEVER, 5, 1.3).0);
            // the state a swap gives after 3 s of adaptation, before any tick
            let (_, mut c, mut s) = run(ctl, next, NEVER, 3, 1.3);
            let adapted = c.compensation().primary().estimates(&s.friction().primary);
            let status = c.compensation().status(s.friction());
            assert!(status.windows > 0);
            c.retune(&mut s, next).unwrap();
            let after = c.compensation().status(s.friction());
            // the applied mode kept, the evidence restarted
            assert_eq!((after.mode, after.windows), (status.mode, 0));
            let estimates = c.compensation().primary().estimates(&s.friction().primary);
            let nominal = [0.36, 0.36, 0.09, 0.03, 0.0];
            // adaptation had moved them: the restart is seen
            assert!(adapted
                .iter()
                .zip(nominal)
                .any(|(a, n)| (a.to_f64() - n).abs() > 1e-3));
            let worst = estimates
                .iter()
                .zip(nominal)
                .map(|(e, n)| (e.to_f64() - n).abs())
                .fold(0.0, f64::max);
            (out, worst)
        }
        #[cfg_attr(not(feature = "fixed"), allow(unused_mut))]
        let mut all = vec![
            (each::<f64>(), tolerance::<f64>()),
            (each::<f32>(), tolerance::<f32>()),
        ];
        #[cfg(feature = "fixed")]
        all.push((each::<crate::Fixed32>(), tolerance::<crate::Fixed32>()));
        for ((s, worst), tol) in all {
            // the estimates are the new nominal values, to the scalar's rounding
            assert!(worst <= tol, "{worst}");
            tracks_on("parameter adaptive", &s, tol);
        }
    }

    #[test]
    fn the_variable_step_parameter_law_and_theta_restart() {
        let law = |m| {
            ParameterAdaptiveParams::new(m, 20.0)
                .build::<f64>(&servo())
                .unwrap()
        };
        let (swap, c, s) = run(
            servo().build(law(LuGreParams::OLSSON_1998)).unwrap(),
            law(MEASURED),
            2300,
            4,
            1.3,
        );
        check(
            "parameter adaptive (variable step)",
            &swap,
            tolerance::<f64>(),
        );
        // adapted after the swap: restart from a fresh swap on the run's end state
        let (mut c, mut s) = (c, s);
        assert_ne!(
            s.friction().estimates(),
            law(MEASURED).initial().estimates()
        );
        c.retune(&mut s, law(LuGreParams::OLSSON_1998)).unwrap();
        assert_eq!(
            s.friction().estimates(),
            law(LuGreParams::OLSSON_1998).initial().estimates()
        );

        let theta = |m: LuGreParams| {
            let p = AdaptiveParams {
                gamma: AdaptiveParams::gain_for_rate(4.0, 60.0, 1.02, 0.33),
                ..AdaptiveParams::DEFAULT
            };
            FixedPeriod(
                p.build(
                    Observer::new(m.build_fixed_step::<f64>(1e-3).unwrap(), 20.0).unwrap(),
                    1e-3,
                )
                .unwrap(),
            )
        };
        let (swap, mut c, mut s) = run(
            servo().build(theta(LuGreParams::OLSSON_1998)).unwrap(),
            theta(MEASURED),
            NEVER,
            3,
            1.3,
        );
        assert!(swap.bump.is_nan());
        assert_ne!(c.compensation().0.theta(s.friction()), 1.0);
        c.retune(&mut s, theta(MEASURED)).unwrap();
        assert_eq!(c.compensation().0.theta(s.friction()), 1.0);
    }

    #[test]
    fn least_squares_restart_from_the_new_settings() {
        let rls = |c0: f64| {
            RlsParams {
                initial_coulomb: c0,
                ..RlsParams::new(0.1, 5.0)
            }
            .build::<f64>()
            .unwrap()
        };
        let (_, mut c, mut s) = run(servo().build(rls(0.28)).unwrap(), rls(0.3), NEVER, 2, 1.0);
        assert!(s.friction().updates() > 0);
        c.retune(&mut s, rls(0.36)).unwrap();
        assert_eq!(s.friction().updates(), 0);
        assert_eq!(c.compensation().coefficients(s.friction()).0, 0.36);
    }

    #[test]
    fn a_swap_to_another_period_is_refused_and_touches_nothing() {
        let (_, mut c, mut s) = run(
            servo()
                .build(observer_fixed::<f32>(LuGreParams::OLSSON_1998))
                .unwrap(),
            observer_fixed::<f32>(MEASURED),
            NEVER,
            1,
            1.0,
        );
        let (c0, s0) = (c, s);
        let other = FixedPeriod(
            Observer::new(MEASURED.build_fixed_step::<f32>(2e-3).unwrap(), 20.0).unwrap(),
        );
        assert_eq!(
            c.retune(&mut s, other).err(),
            Some(ParamError::PeriodMismatch)
        );
        assert_eq!(c.retuned(other).err(), Some(ParamError::PeriodMismatch));
        assert_eq!((c, s), (c0, s0));
    }

    fn log_uniform(low: f64, high: f64) -> impl Strategy<Value = f64> {
        (libm::log10(low)..libm::log10(high)).prop_map(|e| libm::pow(10.0, e))
    }

    /// LuGre parameters at the edges of their ranges (each built only when
    /// the scalar can carry it).
    fn hostile_model() -> impl Strategy<Value = LuGreParams> {
        (
            log_uniform(1e-3, 1e4),
            1.0f64..100.0,
            log_uniform(1e-5, 1e2),
            log_uniform(1e-2, 1e9),
            prop_oneof![Just(0.0), log_uniform(1e-3, 1e5)],
            prop_oneof![Just(0.0), log_uniform(1e-3, 1e4)],
        )
            .prop_map(|(fc, ratio, vs, sigma0, sigma1, sigma2)| LuGreParams {
                curve: crate::StribeckParams {
                    fc,
                    fs: fc * ratio,
                    vs,
                    exponent: 2.0,
                },
                sigma0,
                sigma1,
                sigma2,
                vd: None,
            })
    }

    /// Ticks on `positions` (hostile, finite), swapping to the next of
    /// `models` every 7 ticks: every command within the limit.
    fn hostile_run<S: Scalar, C: Compensation<S> + Copy>(
        models: &[C],
        positions: &[f64],
    ) -> Result<(), TestCaseError> {
        let Some((first, _)) = models.split_first() else {
            return Ok(());
        };
        let mut ctl = servo().build(*first).unwrap();
        let mut state = CompensatorState::default();
        for (k, x) in positions.iter().enumerate() {
            if k % 7 == 6 {
                ctl.retune(&mut state, models[(k / 7) % models.len()])
                    .unwrap();
            }
            let r = Setpoint {
                x: S::ZERO,
                v: S::from_f64(x * 1e-3),
                a: S::ZERO,
            };
            let t = ctl.tick(&mut state, S::from_f64(*x), r);
            prop_assert!(t.accepted);
            prop_assert!(t.command.to_f64().abs() <= 10.0, "{t:?}");
            prop_assert!(t.command.is_finite() && t.friction.is_finite(), "{t:?}");
        }
        Ok(())
    }

    fn hostile_positions() -> impl Strategy<Value = Vec<f64>> {
        prop::collection::vec(
            prop_oneof![
                -1.0f64..1.0,
                -1e-4f64..1e-4,
                Just(1e30),
                Just(-1e30),
                Just(0.0)
            ],
            20..60,
        )
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        #[test]
        fn swaps_between_extreme_models_stay_finite_and_within_the_limit(
            models in prop::collection::vec(hostile_model(), 2..4),
            positions in hostile_positions(),
        ) {
            let variable: Vec<_> = models.iter()
                .filter_map(|m| Observer::new(m.build::<f32>().ok()?, 20.0).ok())
                .collect();
            hostile_run::<f32, _>(&variable, &positions)?;
            let at: Vec<_> = models.iter()
                .filter_map(|m| Observer::new(m.build_fixed_step::<f32>(1e-3).ok()?, 20.0).ok().map(FixedPeriod))
                .collect();
            hostile_run::<f32, _>(&at, &positions)?;
            #[cfg(feature = "fixed")]
            {
                let q: Vec<_> = models.iter()
                    .filter_map(|m| {
                        Observer::new(m.build_fixed_step::<crate::Fixed32>(1e-3).ok()?, 20.0).ok().map(FixedPeriod)
                    })
                    .collect();
                hostile_run::<crate::Fixed32, _>(&q, &positions)?;
            }
            let adaptive: Vec<_> = models.iter()
                .filter_map(|m| ParameterAdaptiveParams::new(*m, 20.0).build_fixed_step::<f32>(&servo()).ok())
                .collect();
            hostile_run::<f32, _>(&adaptive, &positions)?;
        }
    }
}
