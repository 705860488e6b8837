//! The bristle model (Haessig & Friedland 1991) on the host. Its state jumps
//! at random snaps, so its reference is not an ODE: it is the exact
//! event-driven solution on the signal's displacement, with the same seeded
//! generator (the random numbers are part of the model's definition).

use super::HostParams;
use super::ReferenceRun;
use super::{
    boxed, from_toml, in_scalar, model_file, Expectations, HostModel, ScalarKind, Stepper, N, U, Y,
};
use crate::control::{observer_controller, Controller, Loop, ObserverRequest};
use crate::signals::Signal;
use anyhow::{bail, Result};
use friction_core::CounterRng;
use friction_core::{Bristle, BristleParams, BristleState, ParamError, Scalar};

/// The largest bristle count the host dispatches onto the core's const
/// generic `N` (every count from 1 to this; the core itself takes any `N >= 1`).
pub const MAX_BRISTLES: usize = 64;

/// Re-bonds per bristle and step the desk allows (the core's default, 2,
/// bounds a firmware step's worst case): the exact event sequence at any
/// speed the experiments reach (64 N draws a step).
const DESK_SNAPS: u32 = 64;

/// Bristle parameters with the number of bristles `N`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BristleSpec {
    /// The parameters.
    pub params: BristleParams,
    /// Number of bristles `N`, 1 to [`MAX_BRISTLES`].
    pub bristles: usize,
}

fn default_bristles() -> usize {
    25
}

fn default_seed() -> u64 {
    1
}

model_file!(BristleFile {
    sigma0: f64,
    delta_s: f64,
    #[serde(default = "default_bristles")]
    bristles: usize,
    #[serde(default = "default_seed")]
    seed: u64,
});

impl HostParams for BristleParams {
    type Spec = BristleSpec;
    fn parse(text: &str, origin: &str, name: &'static str) -> Result<BristleSpec> {
        let f: BristleFile = from_toml(text, origin, name)?;
        if !(1..=MAX_BRISTLES).contains(&f.bristles) {
            bail!(
            "{origin}: `bristles` = {} is out of range: the host runs 1 to {MAX_BRISTLES} bristles",
            f.bristles
        );
        }
        Ok(BristleSpec {
            params: BristleParams {
                sigma0: f.sigma0,
                delta_s: f.delta_s,
                seed: f.seed,
            },
            bristles: f.bristles,
        })
    }
}

fn strains<S: Scalar, const K: usize>(s: &BristleState<S, K>) -> Vec<f64> {
    s.strain.iter().map(|x| x.to_f64()).collect()
}

fn build_n<S: Scalar + 'static, const K: usize>(
    p: &BristleParams,
) -> Result<Box<dyn Stepper>, ParamError> {
    let names: Vec<String> = (0..K).map(|i| format!("s{i}")).collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    Ok(boxed::<Bristle<S, K>, S>(
        p.build::<S, K>()?.with_snap_budget(DESK_SNAPS),
        &names,
        strains::<S, K>,
    ))
}

fn build<S: Scalar + 'static>(spec: &BristleSpec) -> Result<Box<dyn Stepper>, ParamError> {
    // every count from 1 to MAX_BRISTLES onto the const generic N
    macro_rules! dispatch {
        ($($n:literal)*) => {
            match spec.bristles {
                $($n => build_n::<S, $n>(&spec.params),)*
                _ => Err(ParamError::NotBelow { name: "bristles", limit: "65" }),
            }
        };
    }
    dispatch!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28 29 30
        31 32 33 34 35 36 37 38 39 40 41 42 43 44 45 46 47 48 49 50 51 52 53 54 55 56 57 58 59
        60 61 62 63 64)
}

/// The observer controller with `K` bristles: `sigma0` by the stiffness
/// factor, `delta_s` by `scale / stiffness`, so that the sliding force
/// `N sigma0 delta_s / 3` scales by `scale`.
fn observer_n<const K: usize>(
    p: &BristleParams,
    setup: &Loop,
    request: &ObserverRequest,
) -> Result<Box<dyn Controller>, ParamError> {
    observer_controller(setup, request, |s, k| {
        BristleParams {
            sigma0: p.sigma0 * k,
            delta_s: p.delta_s * s / k,
            ..*p
        }
        .build::<f64, K>()
        .map(|m| m.with_snap_budget(DESK_SNAPS))
    })
}

impl HostModel for BristleSpec {
    /// Measured at 8 and 64 bristles instead of the file's count, with
    /// `sigma0` scaled by 25 / N so that the total stiffness stays that of
    /// 25 bristles (reported; plots for N = 64).
    fn validation_variants(&self) -> Vec<super::Variant> {
        [8, 64]
            .into_iter()
            .map(|n| super::Variant {
                suffix: format!(" N={n}"),
                spec: super::ModelSpec::Bristle(BristleSpec {
                    params: BristleParams {
                        sigma0: self.params.sigma0 * 25.0 / n as f64,
                        ..self.params
                    },
                    bristles: n,
                }),
                bounded: false,
                plots: n == 64,
            })
            .collect()
    }
    fn validates_itself(&self) -> bool {
        false
    }
    /// See `observer_n`.
    fn observer_controller(
        &self,
        setup: &Loop,
        request: &ObserverRequest,
    ) -> Option<Result<Box<dyn Controller>, ParamError>> {
        macro_rules! dispatch {
            ($($n:literal)*) => {
                match self.bristles {
                    $($n => observer_n::<$n>(&self.params, setup, request),)*
                    _ => Err(ParamError::NotBelow { name: "bristles", limit: "65" }),
                }
            };
        }
        Some(
            dispatch!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28
            29 30 31 32 33 34 35 36 37 38 39 40 41 42 43 44 45 46 47 48 49 50 51 52 53 54 55 56 57
            58 59 60 61 62 63 64),
        )
    }
    fn validate(&self) -> Result<(), ParamError> {
        self.params.validate()
    }
    fn stepper(&self, scalar: ScalarKind) -> Result<Box<dyn Stepper>, ParamError> {
        in_scalar!(scalar, build(self))
    }
    fn max_static_force(&self) -> f64 {
        self.bristles as f64 * self.params.sigma0 * self.params.delta_s
    }
    fn presliding_scale(&self) -> f64 {
        self.params.delta_s
    }
    fn continuous(&self) -> Option<Box<dyn super::Continuous>> {
        None
    }
    fn own_reference(&self, signal: &Signal, t: &[f64]) -> Option<ReferenceRun> {
        Some(bristle_reference(&self.params, self.bristles, signal, t))
    }
    /// The sliding mean `N sigma0 delta_s / 3`.
    fn steady_force(&self, v: f64) -> f64 {
        self.max_static_force() / 3.0 * v.signum()
    }
    fn stochastic(&self) -> bool {
        true
    }
    /// The force is random in x, so F-v loops enclose area without any
    /// lag: rate independence is the relevant check.
    fn expectations(&self) -> Expectations {
        Expectations {
            stribeck: Y,
            presliding: N,
            frictional_lag: U,
            breakaway: N,
            stick_slip: U,
            drift: N,
            rate_independence: Y,
            nonlocal_memory: N,
        }
    }
    /// Its bristles snap.
    fn switching(&self) -> bool {
        true
    }
}

/// Splits the signal's displacement over `[a, b]` at its velocity reversals
/// (located by bisection), so that each piece is monotone.
fn monotone_pieces(signal: &Signal, a: f64, b: f64) -> Vec<f64> {
    const PROBES: usize = 8;
    let mut cuts = vec![a];
    for j in 0..PROBES {
        let (mut lo, mut hi) = (
            a + (b - a) * j as f64 / PROBES as f64,
            a + (b - a) * (j + 1) as f64 / PROBES as f64,
        );
        let (vlo, vhi) = (signal.v(lo), signal.v(hi));
        if vlo * vhi < 0.0 {
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if signal.v(mid) * vlo > 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            cuts.push(0.5 * (lo + hi));
        }
    }
    cuts.push(b);
    cuts.windows(2)
        .map(|w| signal.x(w[1]) - signal.x(w[0]))
        .collect()
}

/// The bristle model driven exactly by the signal's displacement: strains
/// move with each monotone piece of `x(t)` and snap when they reach
/// `±delta_s`, re-bonding at the strain the model's generator gives
/// (stream = bristle, index = its re-bond count).
pub fn bristle_reference(
    params: &BristleParams,
    n: usize,
    signal: &Signal,
    t: &[f64],
) -> ReferenceRun {
    let rng = CounterRng::new(params.seed);
    let ds = params.delta_s;
    let mut strain = vec![0.0f64; n];
    let mut bonds = vec![0u32; n];
    let mut run = ReferenceRun {
        force: vec![0.0],
        switching: vec![false],
    };
    for k in 1..t.len() {
        let mut snapped = false;
        for dx in monotone_pieces(signal, t[k - 1], t[k]) {
            let dir = dx.signum();
            for (i, (s, b)) in strain.iter_mut().zip(bonds.iter_mut()).enumerate() {
                let mut x = *s + dx;
                while dir * x >= ds {
                    let beyond = dir * x - ds;
                    *b += 1;
                    let u: f64 = rng.unit(i as u32, *b);
                    x = ds * (2.0 * u - 1.0) + dir * beyond;
                    snapped = true;
                }
                *s = x;
            }
        }
        run.force.push(params.sigma0 * strain.iter().sum::<f64>());
        run.switching.push(snapped);
    }
    run
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The module's parser, as the registry calls it.
    fn parse(text: &str, origin: &str) -> Result<BristleSpec> {
        <BristleParams as HostParams>::parse(text, origin, "bristle")
    }

    #[test]
    fn every_count_from_1_to_64_dispatches() {
        for n in 1..=MAX_BRISTLES {
            let text =
                format!("model = \"bristle\"\nsigma0 = 1e3\ndelta_s = 1e-5\nbristles = {n}\n");
            let spec = parse(&text, "t").unwrap();
            for scalar in [ScalarKind::F32, ScalarKind::F64] {
                let mut m = spec.stepper(scalar).unwrap();
                assert_eq!(m.state_names().len(), n);
                let f = m.step(1e-3, 1e-3); // 1 µm: every bristle strained by 1 µm
                assert!(
                    (f - n as f64 * 1e3 * 1e-6).abs() < 1e-6 * n as f64,
                    "{n}: {f}"
                );
            }
        }
        let e = parse(
            "model = \"bristle\"\nsigma0 = 1e3\ndelta_s = 1e-5\nbristles = 65\n",
            "t",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("1 to 64"), "{e}");
    }
}
