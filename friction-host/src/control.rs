//! The core's [`Compensator`] as the host runs it: one servo axis (the
//! built tick and its state) behind an object-safe trait, so that the layers
//! above (`servo`, the robustness map) run any compensation without naming
//! a model. Each model's host module builds its own observer-based
//! controllers ([`crate::models::HostModel::observer_controller`]) through
//! [`observer_controller`].

use std::any::Any;

use friction_core::{
    AdaptiveParams, Compensation, Compensator, CompensatorParams, CompensatorState,
    CompensatorTick, CoulombViscousParams, Observable, Observer, ParamError, Setpoint,
    SupervisorParams,
};

/// One servo axis: the core's compensator tick with its state.
pub trait Controller: Send {
    /// One tick with measured position `x` towards the setpoint `r`.
    fn tick(&mut self, x: f64, r: Setpoint<f64>) -> CompensatorTick<f64>;
    /// The adapted quantities after the last tick, named by
    /// [`Controller::adapted_names`] (`θ^` for an adaptive observer, the
    /// Coulomb level and viscous coefficient for least squares).
    fn adapted(&self) -> Vec<f64> {
        Vec::new()
    }
    /// The names of [`Controller::adapted`]'s values.
    fn adapted_names(&self) -> &'static [&'static str] {
        &[]
    }
    /// Sets the external torque on the axis that the command does not
    /// include ([`Compensator::set_external_torque`]).
    fn set_external_torque(&mut self, torque: f64);
    /// Re-tunes the running axis between two ticks: its compensation
    /// becomes `next`'s (an axis built the same way around the new model),
    /// its loop and state carried on ([`Compensator::retune`]). Refused,
    /// touching nothing, when `next` runs another kind of compensation
    /// ([`Retune::OtherKind`]) or the core refuses it ([`Retune::Refused`]).
    fn retune(&mut self, next: Box<dyn Controller>) -> Result<(), Retune>;
    /// The axis as [`Any`], for [`Controller::retune`] to take its own kind back.
    fn into_any(self: Box<Self>) -> Box<dyn Any>;
}

/// Why [`Controller::retune`] refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Retune {
    /// The new axis runs another kind of compensation (another model
    /// family, or another law).
    OtherKind,
    /// The core refused the swap.
    Refused(ParamError),
}

impl core::fmt::Display for Retune {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::OtherKind => write!(
                f,
                "the new compensation is of another kind (model family or law) than the running one"
            ),
            Self::Refused(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for Retune {}

/// Reads the adapted quantities of a compensation's state.
pub type Reader<C> = fn(&C, &<C as Compensation<f64>>::State) -> Vec<f64>;

struct Axis<C: Compensation<f64>> {
    ctl: Compensator<f64, C>,
    state: CompensatorState<f64, C::State>,
    names: &'static [&'static str],
    read: Reader<C>,
}

impl<C: Compensation<f64> + Clone + Send + 'static> Controller for Axis<C>
where
    C::State: Send,
{
    fn tick(&mut self, x: f64, r: Setpoint<f64>) -> CompensatorTick<f64> {
        self.ctl.tick(&mut self.state, x, r)
    }
    fn adapted(&self) -> Vec<f64> {
        (self.read)(self.ctl.compensation(), self.state.friction())
    }
    fn adapted_names(&self) -> &'static [&'static str] {
        self.names
    }
    fn set_external_torque(&mut self, torque: f64) {
        self.ctl.set_external_torque(&mut self.state, torque);
    }
    fn retune(&mut self, next: Box<dyn Controller>) -> Result<(), Retune> {
        let next = next
            .into_any()
            .downcast::<Self>()
            .map_err(|_| Retune::OtherKind)?;
        self.ctl
            .retune(&mut self.state, next.ctl.compensation().clone())
            .map_err(Retune::Refused)?;
        (self.names, self.read) = (next.names, next.read);
        Ok(())
    }
    fn into_any(self: Box<Self>) -> Box<dyn Any> {
        self
    }
}

/// What the compensator around a compensation looks like.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Loop {
    /// The PID, inertia, torque constant and limit.
    pub params: CompensatorParams,
    /// Cut-off (Hz) of the velocity low-pass, if any.
    pub velocity_filter: Option<f64>,
    /// Bandwidth (Hz) of the velocity observer, if any.
    pub velocity_observer: Option<f64>,
}

/// Builds one axis around `compensation` with nothing to read.
pub fn controller<C>(setup: &Loop, compensation: C) -> Result<Box<dyn Controller>, ParamError>
where
    C: Compensation<f64> + Clone + Send + 'static,
    C::State: Send,
{
    controller_reading(setup, compensation, &[], |_, _| Vec::new())
}

/// Builds one axis around `compensation`, reading its adapted quantities.
pub fn controller_reading<C>(
    setup: &Loop,
    compensation: C,
    names: &'static [&'static str],
    read: Reader<C>,
) -> Result<Box<dyn Controller>, ParamError>
where
    C: Compensation<f64> + Clone + Send + 'static,
    C::State: Send,
{
    let mut ctl = setup.params.build::<f64, C>(compensation)?;
    if let Some(cutoff) = setup.velocity_filter {
        ctl = ctl.with_velocity_filter(cutoff)?;
    }
    if let Some(bandwidth) = setup.velocity_observer {
        ctl = ctl.with_velocity_observer(bandwidth)?;
    }
    Ok(Box::new(Axis {
        ctl,
        state: CompensatorState::default(),
        names,
        read,
    }))
}

/// An observer-based compensation, as a model's host module builds it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObserverRequest {
    /// Factor on the observer model's friction level: `fc`, `fs` and what
    /// must scale with them (`z_ba` for elasto-plastic, `z0` for the reset
    /// integrator, `delta_s` for bristle); 1 for the nominal model.
    pub scale: f64,
    /// Factor on the observer model's stiffness: `sigma0` (and what keeps
    /// its deflections consistent: `z_ba`, `z0`, `delta_s` by
    /// `scale / stiffness`), the GMS and Xiong element stiffnesses, Leuven's
    /// `xs` by `1 / stiffness`; 1 for the nominal model.
    pub stiffness: f64,
    /// Observer correction gain (1/s).
    pub gain: f64,
    /// Whether the estimate includes `sigma1 dz^/dt`.
    pub damping: bool,
    /// The θ adaptation, if any.
    pub adaptive: Option<AdaptiveParams>,
    /// The supervisor of the θ adaptation, if any (see [`Fallback`]).
    pub supervisor: Option<Fallback>,
}

/// A supervisor ([`friction_core::Supervised`]) and the static map it falls
/// back to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fallback {
    /// Window, memory, hysteresis and warm-up.
    pub params: SupervisorParams,
    /// The Coulomb + viscous feed-forward it falls back to.
    pub map: CoulombViscousParams,
}

/// The controller of `request` around the model `build(scale, stiffness)`
/// builds (see [`ObserverRequest`]): the
/// plain observer, or the θ-adaptive one (`adapted`: `theta`), supervised
/// where the request says (`adapted`: `theta`, `mode`).
pub fn observer_controller<M>(
    setup: &Loop,
    request: &ObserverRequest,
    build: impl Fn(f64, f64) -> Result<M, ParamError>,
) -> Result<Box<dyn Controller>, ParamError>
where
    M: Observable<f64> + Clone + Send + 'static,
    M::State: Send,
{
    let model = build(request.scale, request.stiffness)?;
    let observer = Observer::new(model, request.gain)?.with_damping(request.damping);
    let h = setup.params.h;
    match (request.adaptive, request.supervisor) {
        (None, _) => controller(setup, observer),
        (Some(p), None) => controller_reading(setup, p.build(observer, h)?, &["theta"], |c, s| {
            vec![c.theta(s)]
        }),
        (Some(p), Some(f)) => controller_reading(
            setup,
            f.params
                .build(p.build(observer, h)?, f.map.build::<f64>()?, &setup.params)?,
            &["theta", "mode"],
            |c, s| {
                vec![
                    c.primary().theta(&s.primary),
                    f64::from(c.status(s).mode.code()),
                ]
            },
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use friction_core::{LuGreParams, NoCompensation};

    /// A re-tune keeps the axis running (the next tick is the core's
    /// retuned tick) and refuses another kind of compensation untouched.
    #[test]
    fn retune_swaps_the_same_kind_and_refuses_another() {
        let setup = Loop {
            params: CompensatorParams {
                h: 1e-3,
                kp: 60.0,
                ki: 200.0,
                kd: 1.2,
                inertia: 0.0023,
                torque_constant: 1.02,
                limit: 10.0,
            },
            velocity_filter: Some(200.0),
            velocity_observer: None,
        };
        let observer = |sigma0: f64| {
            let p = LuGreParams {
                sigma0,
                ..LuGreParams::OLSSON_1998
            };
            Observer::new(p.build::<f64>().unwrap(), 20.0).unwrap()
        };
        let mut axis = controller(&setup, observer(260.0)).unwrap();
        let mut core = setup
            .params
            .build(observer(260.0))
            .unwrap()
            .with_velocity_filter(200.0)
            .unwrap();
        let mut state = CompensatorState::default();
        let r = Setpoint {
            x: 0.0,
            v: 0.1,
            a: 0.0,
        };
        for k in 0..300 {
            let x = 1e-4 * f64::from(k);
            if k == 150 {
                let other = controller(&setup, NoCompensation).unwrap();
                assert_eq!(axis.retune(other).err(), Some(Retune::OtherKind));
                axis.retune(controller(&setup, observer(650.0)).unwrap())
                    .unwrap();
                core.retune(&mut state, observer(650.0)).unwrap();
            }
            assert_eq!(axis.tick(x, r), core.tick(&mut state, x, r), "tick {k}");
        }
    }
}
