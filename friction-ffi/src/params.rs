//! Parameter structs as C sees them (all `double`, SI units), each the
//! mirror of a core `*Params` struct; the field docs give the ranges the
//! constructors check.

use friction_core::{
    AdaptiveParams, AsymmetricCoulombViscousParams, BristleParams, CompensatorParams,
    CoulombViscousParams, DahlParams, ElastoPlasticParams, GmsElement, GmsParams, LeuvenParams,
    LuGreParams, ParameterAdaptiveParams, ResetIntegratorParams, StribeckMapParams, StribeckParams,
    SupervisorParams, XiongElement, XiongParams,
};

/// Element count of the GMS and Xiong models in this ABI.
pub const FRICTION_ELEMENTS: usize = 4;
/// Bristle count of the bristle model in this ABI.
pub const FRICTION_BRISTLES: usize = 8;
/// Memory capacity (stored reversals) of the Leuven model in this ABI.
pub const FRICTION_LEUVEN_MEMORY: usize = 16;

/// The Stribeck curve `g(v) = fc + (fs - fc) exp(-|v/vs|^exponent)`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_stribeck {
    /// Coulomb force `fc > 0` (N).
    pub fc: f64,
    /// Static force `fs >= fc` (N).
    pub fs: f64,
    /// Stribeck velocity `vs > 0` (m/s).
    pub vs: f64,
    /// Stribeck exponent `> 0` (2 is usual).
    pub exponent: f64,
}

impl From<friction_stribeck> for StribeckParams {
    fn from(p: friction_stribeck) -> Self {
        Self {
            fc: p.fc,
            fs: p.fs,
            vs: p.vs,
            exponent: p.exponent,
        }
    }
}

/// Coulomb plus viscous friction `F = fc sign(v) + sigma2 v` (a static map).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_coulomb_viscous_params {
    /// Coulomb force `fc > 0` (N).
    pub fc: f64,
    /// Viscous coefficient `sigma2 >= 0` (N s/m).
    pub sigma2: f64,
}

impl From<&friction_coulomb_viscous_params> for CoulombViscousParams {
    fn from(p: &friction_coulomb_viscous_params) -> Self {
        Self {
            fc: p.fc,
            sigma2: p.sigma2,
        }
    }
}

/// Coulomb plus viscous friction with its own levels for each direction
/// (a static map): `F = fc_pos + sigma2_pos v` for `v > 0`,
/// `F = -fc_neg + sigma2_neg v` for `v < 0`, 0 at rest.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_asymmetric_coulomb_viscous_params {
    /// Coulomb force for `v > 0`, `fc_pos > 0` (N).
    pub fc_pos: f64,
    /// Viscous coefficient for `v > 0`, `sigma2_pos >= 0` (N s/m).
    pub sigma2_pos: f64,
    /// Coulomb force (a magnitude) for `v < 0`, `fc_neg > 0` (N).
    pub fc_neg: f64,
    /// Viscous coefficient for `v < 0`, `sigma2_neg >= 0` (N s/m).
    pub sigma2_neg: f64,
}

impl From<&friction_asymmetric_coulomb_viscous_params> for AsymmetricCoulombViscousParams {
    fn from(p: &friction_asymmetric_coulomb_viscous_params) -> Self {
        Self {
            fc_pos: p.fc_pos,
            sigma2_pos: p.sigma2_pos,
            fc_neg: p.fc_neg,
            sigma2_neg: p.sigma2_neg,
        }
    }
}

/// The static Stribeck map `F = g(v) sign(v) + sigma2 v`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_stribeck_map_params {
    /// The Stribeck curve.
    pub curve: friction_stribeck,
    /// Viscous coefficient `sigma2 >= 0` (N s/m).
    pub sigma2: f64,
}

impl From<&friction_stribeck_map_params> for StribeckMapParams {
    fn from(p: &friction_stribeck_map_params) -> Self {
        Self {
            curve: p.curve.into(),
            sigma2: p.sigma2,
        }
    }
}

/// The bristle model (Haessig and Friedland 1991) with
/// [`FRICTION_BRISTLES`] bristles.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_bristle_params {
    /// Bristle stiffness `sigma0 > 0` (N/m).
    pub sigma0: f64,
    /// Largest bristle deflection before it snaps, `delta_s > 0` (m).
    pub delta_s: f64,
    /// Seed of the bristles' re-bond positions.
    pub seed: u64,
}

impl From<&friction_bristle_params> for BristleParams {
    fn from(p: &friction_bristle_params) -> Self {
        Self {
            sigma0: p.sigma0,
            delta_s: p.delta_s,
            seed: p.seed,
        }
    }
}

/// The reset integrator (Haessig and Friedland 1991).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_reset_integrator_params {
    /// Stiffness `sigma0 > 0` (N/m).
    pub sigma0: f64,
    /// Damping `sigma1 >= 0` (N s/m).
    pub sigma1: f64,
    /// Breakaway deflection `z0 > 0` (m).
    pub z0: f64,
    /// Stiction factor `>= 0`.
    pub stiction: f64,
    /// Non-zero: shape the stiffness by `curve` (`sigma0 g(v) / fs`).
    pub has_curve: u8,
    /// The optional Stribeck curve (read only when `has_curve`).
    pub curve: friction_stribeck,
}

impl From<&friction_reset_integrator_params> for ResetIntegratorParams {
    fn from(p: &friction_reset_integrator_params) -> Self {
        Self {
            sigma0: p.sigma0,
            sigma1: p.sigma1,
            z0: p.z0,
            stiction: p.stiction,
            curve: (p.has_curve != 0).then(|| p.curve.into()),
        }
    }
}

/// The Dahl model (Dahl 1968).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_dahl_params {
    /// Rest stiffness `sigma > 0` (N/m).
    pub sigma: f64,
    /// Coulomb force `fc > 0` (N).
    pub fc: f64,
    /// Shape exponent `delta >= 1`.
    pub delta: f64,
    /// Viscous coefficient `sigma2 >= 0` (N s/m).
    pub sigma2: f64,
}

impl From<&friction_dahl_params> for DahlParams {
    fn from(p: &friction_dahl_params) -> Self {
        Self {
            sigma: p.sigma,
            fc: p.fc,
            delta: p.delta,
            sigma2: p.sigma2,
        }
    }
}

/// The LuGre model (Canudas de Wit et al. 1995).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_lugre_params {
    /// The Stribeck curve.
    pub curve: friction_stribeck,
    /// Bristle stiffness `sigma0 > 0` (N/m).
    pub sigma0: f64,
    /// Micro-damping `sigma1 >= 0` (N s/m).
    pub sigma1: f64,
    /// Viscous coefficient `sigma2 >= 0` (N s/m).
    pub sigma2: f64,
    /// Velocity scale `vd` of `sigma1(v) = sigma1 exp(-(v/vd)^2)`; 0: constant `sigma1`.
    pub vd: f64,
}

impl From<&friction_lugre_params> for LuGreParams {
    fn from(p: &friction_lugre_params) -> Self {
        Self {
            curve: p.curve.into(),
            sigma0: p.sigma0,
            sigma1: p.sigma1,
            sigma2: p.sigma2,
            vd: (p.vd != 0.0).then_some(p.vd),
        }
    }
}

/// The elasto-plastic model (Dupont et al. 2002).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_elasto_plastic_params {
    /// The LuGre parameters the model extends.
    pub lugre: friction_lugre_params,
    /// Break-away displacement `0 < z_ba < fc / sigma0` (m).
    pub z_ba: f64,
}

impl From<&friction_elasto_plastic_params> for ElastoPlasticParams {
    fn from(p: &friction_elasto_plastic_params) -> Self {
        Self {
            lugre: (&p.lugre).into(),
            z_ba: p.z_ba,
        }
    }
}

/// The Leuven model (Swevers et al. 2000) with a memory of
/// [`FRICTION_LEUVEN_MEMORY`] reversals.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_leuven_params {
    /// The Stribeck curve.
    pub curve: friction_stribeck,
    /// Micro-damping `sigma1 >= 0` (N s/m).
    pub sigma1: f64,
    /// Viscous coefficient `sigma2 >= 0` (N s/m).
    pub sigma2: f64,
    /// Shape exponent `n >= 1` of the transition to sliding.
    pub n: f64,
    /// Characteristic pre-sliding displacement `xs > 0` (m).
    pub xs: f64,
}

impl From<&friction_leuven_params> for LeuvenParams {
    fn from(p: &friction_leuven_params) -> Self {
        Self {
            curve: p.curve.into(),
            sigma1: p.sigma1,
            sigma2: p.sigma2,
            n: p.n,
            xs: p.xs,
        }
    }
}

/// One Maxwell-slip element of the GMS model.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_gms_element {
    /// Stiffness `k > 0` (N/m).
    pub k: f64,
    /// Weight `alpha > 0` (the weights sum to 1).
    pub alpha: f64,
    /// Damping `sigma1 >= 0` (N s/m).
    pub sigma1: f64,
}

/// The generalised Maxwell-slip model (Al-Bender et al. 2005) with
/// [`FRICTION_ELEMENTS`] elements.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_gms_params {
    /// The Stribeck curve.
    pub curve: friction_stribeck,
    /// Viscous coefficient `sigma2 >= 0` (N s/m).
    pub sigma2: f64,
    /// Attraction rate `c > 0` (N/s): a slipping element follows the curve
    /// with time constant `alpha g(v) / c`.
    pub c: f64,
    /// The elements.
    pub elements: [friction_gms_element; FRICTION_ELEMENTS],
}

impl From<&friction_gms_params> for GmsParams<FRICTION_ELEMENTS> {
    fn from(p: &friction_gms_params) -> Self {
        Self {
            curve: p.curve.into(),
            sigma2: p.sigma2,
            c: p.c,
            elements: p.elements.map(|e| GmsElement {
                k: e.k,
                alpha: e.alpha,
                sigma1: e.sigma1,
            }),
        }
    }
}

/// One element of the Xiong model.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_xiong_element {
    /// Stiffness `k > 0` (N/m).
    pub k: f64,
    /// Viscosity `sigma > 0` (N s/m).
    pub sigma: f64,
    /// Weight `lambda > 0` (the weights sum to 1).
    pub lambda: f64,
}

/// The Xiong model (Xiong et al. 2013) with [`FRICTION_ELEMENTS`] elements.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_xiong_params {
    /// The Stribeck curve.
    pub curve: friction_stribeck,
    /// Lag time `tau > 0` (s) of the frictional-lag level.
    pub tau: f64,
    /// Viscous coefficient `sigma2 >= 0` (N s/m).
    pub sigma2: f64,
    /// The elements.
    pub elements: [friction_xiong_element; FRICTION_ELEMENTS],
}

impl From<&friction_xiong_params> for XiongParams<FRICTION_ELEMENTS> {
    fn from(p: &friction_xiong_params) -> Self {
        Self {
            curve: p.curve.into(),
            tau: p.tau,
            sigma2: p.sigma2,
            elements: p.elements.map(|e| XiongElement {
                k: e.k,
                sigma: e.sigma,
                lambda: e.lambda,
            }),
        }
    }
}

/// The servo loop around the compensation: a PID with acceleration
/// feed-forward (`friction_core::CompensatorParams`).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_servo_params {
    /// Sample period `h > 0` (s).
    pub h: f64,
    /// Proportional gain `kp >= 0`.
    pub kp: f64,
    /// Integral gain `ki >= 0`.
    pub ki: f64,
    /// Derivative gain `kd >= 0`.
    pub kd: f64,
    /// Inertia (or mass) `>= 0` of the feed-forward `J a_ref`.
    pub inertia: f64,
    /// Force per command unit `> 0` (1 for a torque command).
    pub torque_constant: f64,
    /// Command limit `> 0`.
    pub limit: f64,
}

impl From<&friction_servo_params> for CompensatorParams {
    fn from(p: &friction_servo_params) -> Self {
        Self {
            h: p.h,
            kp: p.kp,
            ki: p.ki,
            kd: p.kd,
            inertia: p.inertia,
            torque_constant: p.torque_constant,
            limit: p.limit,
        }
    }
}

/// The theta-adaptive observer's adaptation (`friction_core::AdaptiveParams`):
/// the estimate is scaled by `theta`, learnt from the measured friction.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_adaptive_params {
    /// Adaptation gain `gamma >= 0` on the position error.
    pub gamma: f64,
    /// Adaptation gain `gamma_derivative >= 0` on the error's rate.
    pub gamma_derivative: f64,
    /// Leakage towards `theta0`, `>= 0` (1/s).
    pub leakage: f64,
    /// Initial and leakage target `theta0` within the bounds.
    pub theta0: f64,
    /// Lower projection bound `theta_min >= 0`.
    pub theta_min: f64,
    /// Upper projection bound `theta_max > theta_min`.
    pub theta_max: f64,
}

impl From<&friction_adaptive_params> for AdaptiveParams {
    fn from(p: &friction_adaptive_params) -> Self {
        Self {
            gamma: p.gamma,
            gamma_derivative: p.gamma_derivative,
            leakage: p.leakage,
            theta0: p.theta0,
            theta_min: p.theta_min,
            theta_max: p.theta_max,
        }
    }
}

/// The per-parameter adaptive observer (`friction_core::ParameterAdaptiveParams`):
/// a LuGre observer whose Coulomb level per direction, Stribeck excess,
/// viscous and load coefficients are each estimated within a box.
/// `friction_parameter_adaptive_defaults` fills the defaults around a model.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_parameter_adaptive_params {
    /// The nominal model: its `fc` (both directions), `fs - fc` and `sigma2`
    /// start the estimates; `vd` is not used.
    pub model: friction_lugre_params,
    /// Observer gain `k >= 0` (1/s).
    pub observer_gain: f64,
    /// Adaptation rate `>= 0` (1/s).
    pub rate: f64,
    /// Weight `>= 0` of the error's rate in the adaptation signal.
    pub derivative_weight: f64,
    /// Leakage toward the nominal values, `>= 0` (1/s).
    pub leakage: f64,
    /// Box factor `>= 1` of the projection.
    pub box_factor: f64,
    /// Dead zone `>= 0` on `|e|` (position units; e.g. one encoder count).
    pub dead_zone: f64,
    /// Adaptation only while `|v| >= min_speed >= 0`.
    pub min_speed: f64,
    /// Reference speed `> 0` of the viscous estimate (e.g. the peak speed).
    pub speed: f64,
    /// Nominal load coefficient `>= 0` (friction per unit of transmitted torque).
    pub load: f64,
    /// Upper bound `load_max >= load` of the load coefficient (0: no load term).
    pub load_max: f64,
    /// Non-zero: the bristle takes LuGre's exact step (the `adaptive` rows
    /// of `friction servo`; `ParameterAdaptiveParams::exact_step`) instead of
    /// the implicit one (0, the default). It costs the Cortex-M tick more
    /// (the cost guide's `servo-parameter-exact` rows).
    pub exact_step: u8,
}

impl From<&friction_parameter_adaptive_params> for ParameterAdaptiveParams {
    fn from(p: &friction_parameter_adaptive_params) -> Self {
        Self {
            model: (&p.model).into(),
            observer_gain: p.observer_gain,
            rate: p.rate,
            derivative_weight: p.derivative_weight,
            leakage: p.leakage,
            box_factor: p.box_factor,
            dead_zone: p.dead_zone,
            min_speed: p.min_speed,
            speed: p.speed,
            load: p.load,
            load_max: p.load_max,
            // the fixed-step form the C servo runs has neither the
            // prediction law nor the stiffness law
            prediction_rate: 0.0,
            stiffness_rate: 0.0,
            stiffness_box: 10.0,
            exact_step: p.exact_step != 0,
        }
    }
}

/// The supervisor (`friction_core::SupervisorParams`): it applies whichever
/// of the adaptive observer, the static fallback and no compensation
/// predicts the measured friction best, with hysteresis.
/// `friction_supervisor_defaults` fills the defaults.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_supervisor_params {
    /// Evidence window `> 0` (s), at least seven controller periods.
    pub window: f64,
    /// Memory of the mean-square prediction errors, in windows (`>= 1`).
    pub memory: f64,
    /// Switch when the best candidate's error is below `ratio` times the
    /// active one's (`0 < ratio <= 1`).
    pub ratio: f64,
    /// Windows before the first switch (`>= 0`).
    pub warm_up: f64,
    /// Windows in a fallback mode after which the adaptive observer is
    /// tried again (`>= 0`; 0: never), unless the fallback tracks clearly
    /// better than the observer did.
    pub retry: f64,
    /// Prediction errors below this (force units) count as equal (`>= 0`).
    pub tolerance: f64,
}

impl From<&friction_supervisor_params> for SupervisorParams {
    fn from(p: &friction_supervisor_params) -> Self {
        Self {
            window: p.window,
            memory: p.memory,
            ratio: p.ratio,
            warm_up: p.warm_up,
            retry: p.retry,
            tolerance: p.tolerance,
        }
    }
}

impl From<SupervisorParams> for friction_supervisor_params {
    fn from(p: SupervisorParams) -> Self {
        Self {
            window: p.window,
            memory: p.memory,
            ratio: p.ratio,
            warm_up: p.warm_up,
            retry: p.retry,
            tolerance: p.tolerance,
        }
    }
}
