//! The simulated drive ([`Drive`]): the plant's inertia and friction, the
//! external torque, the command's delay and the encoder.

use crate::models::ModelSpec;
use crate::params::servo::ServoConfig;
use anyhow::Result;
use friction_core::ParamError;
use std::collections::VecDeque;

/// The plant's friction before the drift, load, asymmetry and ripple
/// factors: the parameter file's model stepped by the core, or a BAM
/// budget (`plant_bam`).
enum Plant {
    Model(Box<dyn crate::models::Stepper>),
    Bam(Box<BamPlant>),
}

impl Plant {
    fn new(cfg: &ServoConfig, spec: &ModelSpec) -> Result<Self> {
        Ok(match &cfg.plant_bam {
            Some(p) => Plant::Bam(Box::new(BamPlant::new(p, cfg)?)),
            None => Plant::Model(spec.host().stepper(crate::models::ScalarKind::F64)?),
        })
    }

    /// The friction over a step of `h` at speed `v` with motor torque
    /// `motor` and external torque `external`.
    fn step(&mut self, v: f64, motor: f64, external: f64, h: f64) -> f64 {
        match self {
            Plant::Model(m) => m.step(v, h),
            Plant::Bam(b) => b.step(v, motor, external, h),
        }
    }
}

/// A BAM budget as a plant: a bristle of stiffness `k = breakaway /
/// presliding` (critically damped with the plant's inertia, `c = 2 sqrt(k
/// J)`) holds the joint while its force is within the sticking budget and
/// slips at it; the viscous part acts apart:
///
/// ```text
/// z   = clamp(z + v h, ±budget / k)
/// F   = clamp(k z + c dz/dt, ±budget) + Fv v
/// ```
pub struct BamPlant {
    budget: friction_core::LoadFriction<f64>,
    stiffness: f64,
    damping: f64,
    z: f64,
}

impl BamPlant {
    /// The plant of `params` in the set-up `cfg` (its `presliding` and `inertia`).
    pub fn new(
        params: &friction_core::LoadFrictionParams,
        cfg: &ServoConfig,
    ) -> Result<Self, ParamError> {
        let budget = params.build::<f64>()?;
        // a budget without a break-away level sticks with the stiffness of
        // one that breaks away at 1e-3
        let stiffness = params.breakaway().max(1e-3) / cfg.presliding;
        Ok(Self {
            budget,
            stiffness,
            damping: 2.0 * (stiffness * cfg.inertia).sqrt(),
            z: 0.0,
        })
    }

    /// One step of `h` (see the type's documentation).
    pub fn step(&mut self, v: f64, motor: f64, external: f64, h: f64) -> f64 {
        let (b, viscous) = self.budget.budget(v, motor, external);
        let limit = b / self.stiffness;
        let z = (self.z + v * h).clamp(-limit, limit);
        let rate = (z - self.z) / h;
        self.z = z;
        (self.stiffness * z + self.damping * rate).clamp(-b, b) + viscous * v
    }
}

/// A position far beyond any sensible error: the loop has diverged.
const DIVERGED: f64 = 1e6;

/// The simulated drive: the plant's inertia and friction (with the drift,
/// load, asymmetry and ripple factors), the external torque, the command's
/// delay and the encoder, integrated at the plant rate.
pub(crate) struct Drive<'a> {
    cfg: &'a ServoConfig,
    plant: Option<Plant>,
    x: f64,
    v: f64,
    pending: VecDeque<f64>,
    substeps: usize,
    hp: f64,
    count: f64,
}

impl<'a> Drive<'a> {
    /// The drive of `cfg` at rest at 0, with the friction of `spec` (none
    /// if `friction` is false).
    pub(crate) fn new(cfg: &'a ServoConfig, spec: &ModelSpec, friction: bool) -> Result<Self> {
        Ok(Self {
            cfg,
            plant: if friction {
                Some(Plant::new(cfg, spec)?)
            } else {
                None
            },
            x: 0.0,
            v: 0.0,
            pending: std::iter::repeat_n(0.0, cfg.delay_ticks).collect(),
            substeps: (cfg.plant_rate / cfg.rate).round() as usize,
            hp: 1.0 / cfg.plant_rate,
            count: if cfg.encoder_counts > 0.0 {
                2.0 * std::f64::consts::PI / cfg.encoder_counts
            } else {
                0.0
            },
        })
    }

    /// The true position.
    pub(crate) fn position(&self) -> f64 {
        self.x
    }

    /// The position the encoder reads.
    pub(crate) fn measured(&self) -> f64 {
        if self.count > 0.0 {
            (self.x / self.count).round() * self.count
        } else {
            self.x
        }
    }

    /// Issues `command` at time `t` and runs one controller period (the
    /// drive applies the command `delay_ticks` later); returns the
    /// friction scale of the period (drift times load factor).
    pub(crate) fn apply(&mut self, command: f64, t: f64) -> f64 {
        let cfg = self.cfg;
        self.pending.push_back(command);
        let applied = self.pending.pop_front().unwrap_or(0.0);
        let torque = cfg.torque_constant * applied;
        let scale = cfg.drift(t) * (1.0 + cfg.load_friction * torque.abs());
        for _ in 0..self.substeps {
            let (x, v) = (self.x, self.v);
            let external = cfg.external_torque(x);
            let f = self
                .plant
                .as_mut()
                .map_or(0.0, |p| p.step(v, torque, external, self.hp));
            let f = scale * cfg.friction_factor(x, v) * f;
            self.v += self.hp * (torque + external - f) / cfg.inertia;
            self.x += self.hp * self.v;
        }
        scale
    }

    /// Whether the loop has diverged.
    pub(crate) fn diverged(&self) -> bool {
        !(self.x.abs() < DIVERGED && self.v.is_finite())
    }
}
