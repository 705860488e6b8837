//! The fit at the end of a commissioning run, in `f64` (outside the control
//! interrupt; on a core without a double-precision FPU it runs in software):
//! see [`Commissioned`].

use super::{
    CommissioningAbort, CommissioningParams, CommissioningState, Plateau, BINS,
    COMMISSIONING_MAX_SPEEDS,
};
use crate::model::ParamError;
use crate::stribeck::StribeckParams;
use crate::{LuGreParams, Scalar};

/// Which parameters the run measured (the rest are documented fallbacks).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CommissioningIdentified {
    /// `fc` (per direction).
    pub coulomb: bool,
    /// `fs`, `vs` and the exponent.
    pub stribeck: bool,
    /// `sigma2`.
    pub viscous: bool,
    /// `sigma0`.
    pub stiffness: bool,
    /// `sigma1`.
    pub damping: bool,
    /// The load coefficient.
    pub load: bool,
}

/// A commissioning run's result.
///
/// The fit at the end of a commissioning run, in `f64` (outside the
/// control interrupt; on a core without a double-precision FPU it runs in
/// software).
///
/// **The steady curve.** Each plateau the loop held steadily gives a point
/// `(v, F)`. Steady: the distances over blocks of 8 ticks vary by less than
/// 30 % RMS of their mean beyond the variance `c^2 / 4` that the encoder's
/// count adds (a steady slide's quantized distances take two adjacent
/// values); `c`, the count as a fraction of a block's distance, must be at
/// most 1/4, or the plateau is too slow for the encoder to judge; and the
/// mean distance within 25 % of the reference's (an axis that lagged the
/// reference was not at the plateau's speed). The point
/// is `v` the distance over
/// the time, `F = kc` times the mean command. A plateau in stick-slip (the
/// loop's damping below the curve's falling slope) is left out. Per
/// direction
///
/// ```text
/// F(v) = ±(Fc± + (Fs± - Fc±) exp(-|v / vs|^delta)) + sigma2± v
/// ```
///
/// is linear in `Fc+`, `Fc-`, `Fs+ - Fc+`, `Fs- - Fc-`, `sigma2+` and
/// `sigma2-` (a viscous coefficient per direction) for a
/// given `(vs, delta)`: least squares over a grid of `vs` (48 log-spaced
/// values across the measured speeds) and `delta` (1 to 4 by 0.25), then a
/// golden-section refinement of each around the best. A fit with a negative
/// Stribeck excess is not physical and is skipped. The Stribeck terms count
/// (`stribeck` identified) only where their excess is at least 2 % of `Fc`
/// and they at least halve the RMS of the flat fit (`Fs = Fc`). Where the
/// slowest plateau has reached 90 % of the excess, the static levels, `vs`
/// and `delta` are the curve's (identified); else the curve's `vs` and
/// `delta` are an extrapolation (not identified) and the static levels are
/// the break-away levels. Otherwise
/// the curve is flat down to the slowest steady plateau `v_lo`, the static
/// levels are the break-away levels, `delta = 2`, and `vs` is the largest
/// value that leaves under 2 % of `Fc` of the excess at `v_lo`: `vs = v_lo /
/// sqrt(ln((Fs - Fc) / (0.02 Fc)))`, an upper bound.
///
/// **Stiffness.** At rest under a force `a` the LuGre bristle holds `z =
/// a / sigma0`; reversing to `-a` slowly moves it along `dz/dx = 1 + sigma0
/// z / Fs`, so the rest positions are `dx = (Fs / sigma0) ln((Fs + a) /
/// (Fs - a))` apart, which gives `sigma0`. Where `dx` is under 8 encoder
/// counts, or the axis slipped, `sigma0` is not identified. The
/// measurement then only rules out the bristles softer than `Fs / (8
/// counts)` (or `Fs / breakaway_travel` with an exact encoder); among the
/// stiffer ones, a bristle whose presliding resonance `sqrt(sigma0 / J)`
/// is above a tenth of the sampling rate is not seen by the loop, and a
/// softer one makes the observer lag at every reversal. So `sigma0` is
/// the larger of that bound and `J (2 pi / (10 h))^2`.
///
/// **Load.** Each plateau also keeps its commands by position, over four
/// equal stretches of the window its moves cover (`0.9 travel` ahead of
/// the start). At one speed both directions pass a stretch under the same
/// position-dependent torque `G` (gravity), so there the half-difference
/// of their mean commands `D = (u+ - u-) / 2` is the friction without
/// `G`, and their mean magnitude `L = (|u+| + |u-|) / 2` the torque the
/// drive transmitted. The load-dependent curve of the per-parameter
/// observer, `g = Fc + Ds s(v) + mu |kc u|`, makes `D = a(v) + mu L`
/// exactly; `mu` is the least-squares slope of `D` on `L` within each
/// speed (the speed's means removed), over at least 4 stretches whose `L`
/// spreads by at least 10 % of the mean `D` RMS, and identified where it is in
/// `[0, 1)`. `L` spreads only where `G` exceeds the friction over part of
/// the window (the axis would fall without the motor); a stretch where it
/// changes sign within the stretch mixes both regimes and biases `mu`
/// upward. Where `mu` is identified, the curve is fitted to each speed's
/// `D` moved by `mu` to the mean transmitted torque (symmetric: the
/// directions' offsets are `G`'s), unless that fit finds no friction or
/// fits poorly; then to the directions' own means as without a load. The
/// levels are the curve at the mean transmitted torque `load_torque`: at no
/// load they are lower by `mu load_torque`.
///
/// **Damping.** Stepping the force down from `+a` to `a / 2` in stick makes
/// the inertia `J` ring on the bristle; the overshoot of the displacement
/// (lowest position against the rest position after the hold, as a ratio
/// of the step's displacement) falls as `sigma1` grows. `sigma1` is the
/// value whose step, simulated on the fitted model (the core's LuGre step,
/// 20 steps a period, over the routine's hold), has the measured ratio:
/// from `4 sigma_c` (`sigma_c = 2 sqrt(sigma0 J)`) down a grid of 40 to
/// `sigma_c / 100`, the first value whose overshoot reaches the measured
/// one, then 30 bisections. Where
/// the step moved less than 16 counts, its overshoot is under 2 counts (or
/// absent: overdamped), `sigma0` was not measured, or the loop runs
/// faster than 100 kHz (the simulations are bounded at 20,000 periods of
/// the hold, so the fit stays bounded in time), `sigma1` is not
/// identified and is Canudas de Wit et al. 1995's rule of thumb, the
/// bristle critically damped on the inertia: `sigma_c`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Commissioned {
    /// The LuGre model (levels and viscous coefficient the means of the
    /// two directions).
    pub model: LuGreParams,
    /// Coulomb levels forward and backward (force units, both positive).
    pub fc: [f64; 2],
    /// Static levels forward and backward.
    pub fs: [f64; 2],
    /// Viscous coefficients forward and backward.
    pub sigma2: [f64; 2],
    /// Break-away levels of the ramps, forward and backward.
    pub breakaway: [f64; 2],
    /// The load coefficient `mu >= 0`: friction per unit of the torque the
    /// drive transmits, `|kc u|` (0 where not identified).
    pub load: f64,
    /// The mean transmitted torque `|kc u|` over the plateaus: the levels
    /// above are the curve at this load, and `fc - load * load_torque` is
    /// the Coulomb level at no load.
    pub load_torque: f64,
    /// What was measured.
    pub identified: CommissioningIdentified,
    /// RMS of the curve fit over the plateaus, relative to the mean `fc`,
    /// to a tenth of the static level or to the lowest friction the curve
    /// has at the plateaus' speeds, whichever is largest.
    pub residual: f64,
    /// Slowest and fastest measured plateau speed.
    pub speed_range: [f64; 2],
    /// Plateaus measured.
    pub plateaus: u8,
}

/// Why a run gave no parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum CommissionError {
    /// The routine has not finished.
    NotFinished,
    /// The routine stopped early.
    Aborted(CommissioningAbort),
    /// Fewer than three usable plateaus in a direction.
    TooFewPlateaus,
    /// The curve fits the plateaus worse than 10 % RMS of `fc`, of a
    /// tenth of `fs` or of the curve's lowest friction at the plateaus'
    /// speeds, whichever is largest (the figure is the relative
    /// RMS).
    PoorFit(f64),
    /// The fitted Coulomb level is not positive.
    NoFriction,
    /// The fitted parameters do not build a LuGre model.
    Invalid(ParamError),
}

/// Largest relative RMS of an accepted fit.
const MAX_RESIDUAL: f64 = 0.1;
/// A Stribeck fit counts only if it leaves at most this fraction of the
/// flat fit's sum of squares (its RMS halved).
const SIGNIFICANT: f64 = 0.25;
/// Stribeck excess below this fraction of `fc`: no Stribeck effect.
const MIN_EXCESS: f64 = 0.02;
/// A Stribeck fit's Coulomb level is at least this fraction of its static
/// level: a harmonic drive's curve can be nearly all Stribeck (BAM's
/// eRob80, a Coulomb level of 1e-4 of it), where a shape with a negative
/// one can fit best.
const MIN_COULOMB: f64 = 1e-3;
/// The residual's scale is at least this fraction of the static level.
const RESIDUAL_SCALE: f64 = 0.1;
/// A plateau whose mean distance per block differs from the reference's by
/// more than this fraction did not keep up with it.
const TRACKED: f64 = 0.25;
/// A plateau whose distance per block varies by more than 30 % RMS of its
/// mean (beyond what the encoder's counts explain) was not sliding
/// steadily.
const STEADY: f64 = 0.09;
/// The fitted static levels count where the slowest plateau has reached
/// this fraction of the Stribeck excess; below, the break-away levels.
const REACHED: f64 = 0.9;
/// A stretch of a plateau counts toward the load coefficient if the
/// plateau spent at least this many ticks in it.
const MIN_BIN_TICKS: u32 = 16;
/// The load coefficient needs at least this many stretches measured in
/// both directions at one speed...
const MIN_STRETCHES: usize = 4;
/// ... whose loads spread by at least this fraction of `fc` RMS.
const LOAD_SPREAD: f64 = 0.1;
/// A bristle resonating above the sampling rate over this is not seen by
/// the loop.
const UNSEEN: f64 = 10.0;
/// Presliding shorter than this many counts is not measured.
const MIN_COUNTS: f64 = 8.0;
/// The most loop periods of the presliding hold the damping fit simulates
/// (the hold at 100 kHz); a faster loop leaves `sigma1` not identified.
const MAX_SIMULATED_PERIODS: f64 = 20_000.0;

#[derive(Clone, Copy, Default)]
struct Point {
    v: f64,
    f: f64,
}

/// The coefficients and the sum of squares.
type Linear = ([f64; COEFFICIENTS], f64);

/// `Fc+`, `Fc-`, `dS+`, `dS-`, `sigma2+`, `sigma2-`.
const COEFFICIENTS: usize = 6;

pub(super) fn fit<S: Scalar>(
    params: &CommissioningParams,
    state: &CommissioningState<S>,
) -> Result<Commissioned, CommissionError> {
    let plateaus = measured(params, state);
    let loads = loads(params, state, &plateaus);
    let (points, n) = points(&plateaus);
    let per_direction = points.get(..n).unwrap_or(&[]);
    // a load that changes along the window (gravity) shifts each
    // direction's levels by the torque over its stretch: the curve from
    // the directions' half-differences first, symmetric; where that curve
    // finds no friction or fits poorly, the directions' own
    let load = loads.coefficient();
    if let Some(mu) = load {
        let (points, n) = loads.symmetric(mu);
        let symmetric = fit_curve(
            params,
            state,
            load,
            loads.torque,
            points.get(..n).unwrap_or(&[]),
        );
        if !matches!(
            symmetric,
            Err(CommissionError::NoFriction | CommissionError::PoorFit(_))
        ) {
            return symmetric;
        }
    }
    fit_curve(params, state, load, loads.torque, per_direction)
}

/// The fit on the curve points `points`, with the load coefficient `load`
/// and the mean transmitted torque `load_torque` as measured.
fn fit_curve<S: Scalar>(
    params: &CommissioningParams,
    state: &CommissioningState<S>,
    load: Option<f64>,
    load_torque: f64,
    points: &[Point],
) -> Result<Commissioned, CommissionError> {
    let n = points.len();
    let forward = points.iter().filter(|p| p.v > 0.0).count();
    if forward < 3 || n - forward < 3 {
        return Err(CommissionError::TooFewPlateaus);
    }
    let lo = points.iter().fold(f64::INFINITY, |m, p| m.min(p.v.abs()));
    let hi = points.iter().fold(0.0f64, |m, p| m.max(p.v.abs()));

    let flat = linear(points, |_| 0.0, false, true).ok_or(CommissionError::TooFewPlateaus)?;
    let level = |c: &[f64; COEFFICIENTS]| 0.5 * (c[0] + c[1]);
    let curved = stribeck_search(points, lo, hi).filter(|((c, sse), _, _)| {
        0.5 * (c[2] + c[3]) >= MIN_EXCESS * level(c) && *sse <= SIGNIFICANT * flat.1
    });
    let stribeck = curved.is_some();
    let ((mut c, mut sse), vs, delta) = curved.unwrap_or((flat, lo, 2.0));
    let mut viscous = true;
    if c[4] < 0.0 || c[5] < 0.0 {
        // a falling curve at speed is not viscous friction: refit without
        let g = |v: f64| stribeck_shape(v, vs, delta);
        if let Some((refit, s)) = linear(points, g, stribeck, false) {
            c = refit;
            sse = s;
        }
        viscous = false;
    }
    let [fc_pos, fc_neg, ds_pos, ds_neg, sigma2_pos, sigma2_neg] = c;
    let sigma2 = 0.5 * (sigma2_pos + sigma2_neg);
    let fc = 0.5 * (fc_pos + fc_neg);
    if !(fc > 0.0 && fc.is_finite()) {
        return Err(CommissionError::NoFriction);
    }
    // relative to the Coulomb level, to the static one's tenth where the
    // curve is nearly all Stribeck, or to the lowest friction the curve has
    // at the plateaus' speeds where that is larger: where the plateaus lie
    // on the Stribeck branch, the Coulomb level is an extrapolation beyond
    // the fastest of them that the data hardly fix, and a good fit must not
    // be refused for where that extrapolation lands
    let ds = 0.5 * (ds_pos + ds_neg);
    let lowest = points.iter().fold(f64::INFINITY, |m, p| {
        let v = libm::fabs(p.v);
        m.min(fc + ds * stribeck_shape(v, vs, delta) + sigma2 * v)
    });
    let scale = fc.max(RESIDUAL_SCALE * (fc + ds)).max(lowest);
    let residual = libm::sqrt(sse / n as f64) / scale;
    if residual.is_nan() || residual > MAX_RESIDUAL {
        return Err(CommissionError::PoorFit(residual));
    }
    let kc = params.servo.torque_constant;
    let breakaway = state.breakaway.map(|b| kc * b.to_f64());
    let [b_pos, b_neg] = breakaway;
    // the slowest plateau still on the branch: its static end (and its
    // shape) is an extrapolation; the break-away ramps measured the end
    let reached = stribeck_shape(lo, vs, delta) >= REACHED;
    let (fs_pos, fs_neg, vs) = if stribeck && reached {
        (fc_pos + ds_pos, fc_neg + ds_neg, vs)
    } else if stribeck {
        (b_pos.max(fc_pos), b_neg.max(fc_neg), vs)
    } else {
        // flat down to the slowest plateau: the static levels from the
        // break-away ramps, and the largest vs that leaves under 2 % of
        // the excess at the slowest plateau (delta = 2)
        let (fs_pos, fs_neg) = (b_pos.max(fc_pos), b_neg.max(fc_neg));
        let excess = 0.5 * (fs_pos - fc_pos + fs_neg - fc_neg);
        let ratio = excess / (MIN_EXCESS * fc);
        let vs = if ratio > core::f64::consts::E {
            lo / libm::sqrt(libm::log(ratio))
        } else {
            lo
        };
        (fs_pos, fs_neg, vs)
    };
    let fs = 0.5 * (fs_pos + fs_neg);
    let (sigma0, stiffness) = stiffness(params, state, fs);
    let sigma2 = sigma2.max(0.0);
    let curve = StribeckParams {
        fc,
        fs,
        vs,
        exponent: delta,
    };
    let undamped = LuGreParams {
        curve,
        sigma0,
        sigma1: 0.0,
        sigma2,
        vd: None,
    };
    let (sigma1, damping) = damping(params, state, undamped, stiffness);
    let model = LuGreParams { sigma1, ..undamped };
    model.validate().map_err(CommissionError::Invalid)?;
    Ok(Commissioned {
        model,
        fc: [fc_pos, fc_neg],
        fs: [fs_pos, fs_neg],
        sigma2: [sigma2_pos.max(0.0), sigma2_neg.max(0.0)],
        breakaway,
        load: load.unwrap_or(0.0),
        load_torque,
        identified: CommissioningIdentified {
            coulomb: true,
            stribeck: stribeck && reached,
            viscous,
            stiffness,
            damping,
            load: load.is_some(),
        },
        residual,
        speed_range: [lo, hi],
        plateaus: n as u8,
    })
}

/// The steady plateaus of `measured` as `(v, F)`.
fn points(
    measured: &[Option<PlateauPoint>; 2 * COMMISSIONING_MAX_SPEEDS],
) -> ([Point; 2 * COMMISSIONING_MAX_SPEEDS], usize) {
    let mut out = [Point::default(); 2 * COMMISSIONING_MAX_SPEEDS];
    let mut n = 0;
    for p in measured.iter().flatten() {
        if let (true, Some(slot)) = (p.steady, out.get_mut(n)) {
            *slot = Point {
                v: p.speed,
                f: p.force,
            };
            n += 1;
        }
    }
    (out, n)
}

/// One measured plateau.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PlateauPoint {
    /// Its mean speed (signed).
    pub speed: f64,
    /// Its mean friction (force units, signed).
    pub force: f64,
    /// Whether the loop held it steadily (only steady plateaus are fitted).
    pub steady: bool,
}

/// Every measured plateau, in the order run (fastest first, forward
/// first); `None` where none was measured.
pub(super) fn measured<S: Scalar>(
    params: &CommissioningParams,
    state: &CommissioningState<S>,
) -> [Option<PlateauPoint>; 2 * COMMISSIONING_MAX_SPEEDS] {
    let mut out = [None; 2 * COMMISSIONING_MAX_SPEEDS];
    let (h, kc) = (params.servo.h, params.servo.torque_constant);
    let count = usize::from(params.speeds);
    for (index, (p, slot)) in state.plateaus.iter().zip(out.iter_mut()).enumerate() {
        if p.ticks < 2 {
            continue;
        }
        // the distance spans one period fewer than the commands summed
        let periods = f64::from(p.ticks - 1);
        let speed = p.distance.to_f64() / (periods * h);
        let force = kc * p.command_mean.to_f64();
        let mean = p.ratio_mean.to_f64();
        let variance = p.square_mean.to_f64() - mean * mean;
        let step = 8.0 * params.speed(count.saturating_sub(1 + index / 2)) * h;
        let counts = resolution::<S>(params) / step;
        // a steady slide's block distances differ by at most one count:
        // their variance is at most c^2 / 4
        let resolved = counts <= 0.25;
        // and it kept up with the reference: a lagging axis is not at the
        // plateau's speed
        let tracked = (mean - 1.0).abs() <= TRACKED;
        let steady =
            resolved && tracked && variance - 0.25 * counts * counts <= STEADY * mean * mean;
        let finite = speed.is_finite() && force.is_finite() && speed != 0.0;
        if finite {
            *slot = Some(PlateauPoint {
                speed,
                force,
                steady,
            });
        }
    }
    out
}

/// `exp(-|v / vs|^delta)`.
fn stribeck_shape(v: f64, vs: f64, delta: f64) -> f64 {
    libm::exp(-libm::pow(libm::fabs(v / vs), delta))
}

/// Least squares for the coefficients with shape `g`, with or without the
/// Stribeck excesses and the viscous term; `None` if singular, if an
/// excess comes out negative, or (with them) if the mean Coulomb level
/// comes out below [`MIN_COULOMB`] of the static level.
fn linear(
    points: &[Point],
    g: impl Fn(f64) -> f64,
    stribeck: bool,
    viscous: bool,
) -> Option<Linear> {
    let used = [true, true, stribeck, stribeck, viscous, viscous];
    let mut a = [[0.0f64; COEFFICIENTS]; COEFFICIENTS];
    let mut b = [0.0f64; COEFFICIENTS];
    for p in points {
        let s = g(p.v);
        let mut phi = if p.v > 0.0 {
            [1.0, 0.0, s, 0.0, p.v, 0.0]
        } else {
            [0.0, -1.0, 0.0, -s, 0.0, p.v]
        };
        for (x, on) in phi.iter_mut().zip(used) {
            if !on {
                *x = 0.0;
            }
        }
        for ((row, bi), pi) in a.iter_mut().zip(b.iter_mut()).zip(phi) {
            *bi += pi * p.f;
            for (aij, pj) in row.iter_mut().zip(phi) {
                *aij += pi * pj;
            }
        }
    }
    // an unused coefficient solves to 0
    for (i, (row, on)) in a.iter_mut().zip(used).enumerate() {
        if let (false, Some(d)) = (on, row.get_mut(i)) {
            *d = 1.0;
        }
    }
    let c = solve(a, b)?;
    if stribeck && (c[2] < 0.0 || c[3] < 0.0) {
        return None;
    }
    let coulomb = 0.5 * (c[0] + c[1]);
    if stribeck && coulomb < MIN_COULOMB * (coulomb + 0.5 * (c[2] + c[3])) {
        return None;
    }
    let sse = points
        .iter()
        .map(|p| {
            let s = g(p.v);
            let model = if p.v > 0.0 {
                c[0] + c[2] * s + c[4] * p.v
            } else {
                -(c[1] + c[3] * s) + c[5] * p.v
            };
            (p.f - model) * (p.f - model)
        })
        .sum();
    Some((c, sse))
}

/// Gaussian elimination with partial pivoting; `None` if a pivot is below
/// `1e-12` of the largest diagonal.
// every index runs below N on `[_; N]`: the indexing cannot panic
#[allow(clippy::indexing_slicing)]
fn solve<const N: usize>(mut a: [[f64; N]; N], mut b: [f64; N]) -> Option<[f64; N]> {
    let scale = (0..N).fold(0.0f64, |m, i| m.max(libm::fabs(a[i][i])));
    for col in 0..N {
        let pivot =
            (col..N).max_by(|&i, &j| libm::fabs(a[i][col]).total_cmp(&libm::fabs(a[j][col])))?;
        let size = libm::fabs(a[pivot][col]);
        if size.is_nan() || size <= 1e-12 * scale {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        let top = a[col];
        for row in col + 1..N {
            let k = a[row][col] / top[col];
            for (x, y) in a[row].iter_mut().zip(top).skip(col) {
                *x -= k * y;
            }
            b[row] -= k * b[col];
        }
    }
    let mut x = [0.0f64; N];
    for i in (0..N).rev() {
        let tail: f64 = (i + 1..N).map(|j| a[i][j] * x[j]).sum();
        x[i] = (b[i] - tail) / a[i][i];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// The best Stribeck fit over the grid of `vs` in `[lo, hi]` and `delta`
/// in `[1, 4]`, refined by golden sections: `(coefficients, vs, delta)`.
fn stribeck_search(points: &[Point], lo: f64, hi: f64) -> Option<(Linear, f64, f64)> {
    const VS_GRID: usize = 48;
    const DELTA_GRID: usize = 13;
    let ratio = if hi > lo { hi / lo } else { 1.0 };
    let step = libm::pow(ratio, 1.0 / (VS_GRID - 1) as f64);
    let sse_at = |vs: f64, delta: f64| {
        linear(points, |v| stribeck_shape(v, vs, delta), true, true).map(|(_, s)| s)
    };
    let mut best: Option<(f64, f64, f64)> = None;
    for i in 0..VS_GRID {
        let vs = lo * libm::pow(step, i as f64);
        for j in 0..DELTA_GRID {
            let delta = 1.0 + 0.25 * j as f64;
            if let Some(sse) = sse_at(vs, delta) {
                if best.is_none_or(|(b, _, _)| sse < b) {
                    best = Some((sse, vs, delta));
                }
            }
        }
    }
    let (_, vs, delta) = best?;
    let penalised = |s: Option<f64>| s.unwrap_or(f64::INFINITY);
    let log_vs = golden(libm::log(vs / step), libm::log(vs * step), |u| {
        penalised(sse_at(libm::exp(u), delta))
    });
    let vs = libm::exp(log_vs).clamp(lo, hi.max(lo));
    let delta = golden((delta - 0.25).max(1.0), delta + 0.25, |d| {
        penalised(sse_at(vs, d))
    });
    let c = linear(points, |v| stribeck_shape(v, vs, delta), true, true)?;
    Some((c, vs, delta))
}

/// The minimum of `f` on `[a, b]` by 40 golden sections.
fn golden(mut a: f64, mut b: f64, f: impl Fn(f64) -> f64) -> f64 {
    const INV_PHI: f64 = 0.618_033_988_749_894_8;
    let mut c = b - INV_PHI * (b - a);
    let mut d = a + INV_PHI * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..40 {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - INV_PHI * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + INV_PHI * (b - a);
            fd = f(d);
        }
    }
    0.5 * (a + b)
}

/// What the plateaus' position stretches say (see the [module docs](self)).
struct Loads {
    /// Per speed measured steadily both ways, `(v, F)`: the mean speed and
    /// the half-difference of the two directions' mean commands over the
    /// stretches both passed (the friction, free of any position-dependent
    /// torque).
    pairs: [Point; COMMISSIONING_MAX_SPEEDS],
    /// Their mean load `L` over those stretches.
    pair_loads: [f64; COMMISSIONING_MAX_SPEEDS],
    count: usize,
    /// Within each speed, the sums of the load's (`L`) squared deviations
    /// from the speed's mean, and of its products with the friction's; the
    /// stretches they count.
    sxx: f64,
    sxy: f64,
    stretches: usize,
    /// The mean transmitted torque over the steady plateaus.
    torque: f64,
}

impl Loads {
    /// The RMS spread of the load within the speeds.
    fn spread(&self) -> f64 {
        libm::sqrt(self.sxx / self.stretches as f64)
    }

    /// The mean friction `|D|` of the pairs.
    fn friction(&self) -> f64 {
        let pairs = self.pairs.iter().take(self.count);
        pairs.map(|p| libm::fabs(p.f)).sum::<f64>() / self.count as f64
    }

    /// The load coefficient, where the spread is at least `LOAD_SPREAD`
    /// times the pairs' mean friction and the slope within `[0, 1)`: one
    /// decision for the curve and the result.
    fn coefficient(&self) -> Option<f64> {
        let mu = self.sxy / self.sxx;
        let spread =
            self.stretches >= MIN_STRETCHES && self.spread() >= LOAD_SPREAD * self.friction();
        (spread && mu.is_finite() && (0.0..1.0).contains(&mu)).then_some(mu)
    }

    /// The symmetric curve points `(v, F)` and `(-v, -F)` of every pair,
    /// with the friction moved by `mu` from the pair's load to the mean
    /// transmitted torque.
    fn symmetric(&self, mu: f64) -> ([Point; 2 * COMMISSIONING_MAX_SPEEDS], usize) {
        let mut out = [Point::default(); 2 * COMMISSIONING_MAX_SPEEDS];
        let pairs = self.pairs.iter().zip(self.pair_loads).take(self.count);
        for (k, (p, load)) in pairs.enumerate() {
            let p = Point {
                v: p.v,
                f: p.f - mu * (load - self.torque),
            };
            if let Some(slot) = out.get_mut(2 * k) {
                *slot = p;
            }
            if let Some(slot) = out.get_mut(2 * k + 1) {
                *slot = Point { v: -p.v, f: -p.f };
            }
        }
        (out, 2 * self.count)
    }
}

fn loads<S: Scalar>(
    params: &CommissioningParams,
    state: &CommissioningState<S>,
    points: &[Option<PlateauPoint>; 2 * COMMISSIONING_MAX_SPEEDS],
) -> Loads {
    let kc = params.servo.torque_constant;
    let steady = |i: usize| match points.get(i) {
        Some(Some(p)) if p.steady => Some(p.speed),
        _ => None,
    };
    let (total, count) = points
        .iter()
        .flatten()
        .filter(|p| p.steady)
        .fold((0.0, 0.0), |(t, c), p| (t + libm::fabs(p.force), c + 1.0));
    let mut out = Loads {
        pairs: [Point::default(); COMMISSIONING_MAX_SPEEDS],
        pair_loads: [0.0; COMMISSIONING_MAX_SPEEDS],
        count: 0,
        sxx: 0.0,
        sxy: 0.0,
        stretches: 0,
        torque: if count > 0.0 { total / count } else { 0.0 },
    };
    // within each speed, the half-difference of the two directions' mean
    // commands (the friction) against their mean magnitude (the load),
    // stretch by stretch
    for pair in 0..COMMISSIONING_MAX_SPEEDS {
        let (i, j) = (2 * pair, 2 * pair + 1);
        let (Some(forward), Some(backward)) = (state.plateaus.get(i), state.plateaus.get(j)) else {
            continue;
        };
        let (Some(v_up), Some(v_down)) = (steady(i), steady(j)) else {
            continue;
        };
        let mut stretches = [(0.0f64, 0.0f64); BINS];
        let mut m = 0;
        for b in 0..BINS {
            let (Some(up), Some(down)) = (bin_mean(forward, b), bin_mean(backward, b)) else {
                continue;
            };
            let (up, down) = (kc * up, kc * down);
            if let Some(slot) = stretches.get_mut(m) {
                *slot = (0.5 * (libm::fabs(up) + libm::fabs(down)), 0.5 * (up - down));
                m += 1;
            }
        }
        let used = stretches.get(..m).unwrap_or(&[]);
        if m == 0 {
            continue;
        }
        let (l_mean, d_mean) = used.iter().fold((0.0, 0.0), |(l, d), (x, y)| {
            (l + x / m as f64, d + y / m as f64)
        });
        if let (Some(slot), Some(load)) = (
            out.pairs.get_mut(out.count),
            out.pair_loads.get_mut(out.count),
        ) {
            *slot = Point {
                v: 0.5 * (v_up - v_down),
                f: d_mean,
            };
            *load = l_mean;
            out.count += 1;
        }
        if m < 2 {
            continue;
        }
        for (l, d) in used {
            out.sxy += (l - l_mean) * (d - d_mean);
            out.sxx += (l - l_mean) * (l - l_mean);
        }
        out.stretches += m;
    }
    out
}

/// The mean command over stretch `b` of plateau `p`, if it spans at least
/// [`MIN_BIN_TICKS`].
fn bin_mean<S: Scalar>(p: &Plateau<S>, b: usize) -> Option<f64> {
    let ticks = *p.bin_ticks.get(b)?;
    if ticks < MIN_BIN_TICKS {
        return None;
    }
    // the sums are scaled by 1 / p.ticks, as the plateau's mean
    Some(p.bins.get(b)?.to_f64() * f64::from(p.ticks) / f64::from(ticks))
}

/// `sigma0` from the presliding reversal and whether it was measured (see
/// [`Commissioned`]).
fn stiffness<S: Scalar>(
    params: &CommissioningParams,
    state: &CommissioningState<S>,
    fs: f64,
) -> (f64, bool) {
    let [plus, minus] = state.presliding;
    let dx = plus.to_f64() - minus.to_f64();
    let a = params.servo.torque_constant * state.presliding_level.to_f64();
    let count = resolution::<S>(params);
    // a float's own resolution is far below any presliding: then the
    // floor is the displacement that counts as breaking away
    let floor = if count > 1e-6 * params.breakaway_travel {
        MIN_COUNTS * count
    } else {
        params.breakaway_travel
    };
    let resolved = dx.is_finite() && dx > 0.0 && dx >= MIN_COUNTS * count;
    if state.slipped.get() || !resolved {
        // the measurement only rules out the softer bristles; from the
        // stiffness whose resonance is a tenth of the sampling rate up, the
        // loop cannot tell them apart, and a stiff bristle lags the least
        let omega = core::f64::consts::TAU / (UNSEEN * params.servo.h);
        return (
            (fs / floor).max(params.servo.inertia * omega * omega),
            false,
        );
    }
    let sigma0 = if a < 0.95 * fs {
        fs / dx * libm::log((fs + a) / (fs - a))
    } else {
        2.0 * a / dx
    };
    (sigma0, true)
}

/// `sigma1` from the step's overshoot and whether it was measured (see
/// [`Commissioned`]): the `sigma1` whose simulated step has the measured
/// overshoot ratio, by bisection (the ratio falls as `sigma1` grows).
fn damping<S: Scalar>(
    params: &CommissioningParams,
    state: &CommissioningState<S>,
    model: LuGreParams,
    measured: bool,
) -> (f64, bool) {
    let inertia = params.servo.inertia;
    let critical = 2.0 * libm::sqrt(model.sigma0 * inertia);
    let [before, lowest, last] = state.step_response.map(|x| x.to_f64());
    let (drop, overshoot) = (before - last, last - lowest);
    let count = resolution::<S>(params);
    let seen = drop > 0.0 && drop >= 2.0 * MIN_COUNTS * count && overshoot > 2.0 * count;
    let target = overshoot / drop;
    if !(measured && seen && target > 0.0 && target < 1.0 && inertia > 0.0) {
        return (critical, false);
    }
    let a = params.servo.torque_constant * state.presliding_level.to_f64();
    let ratio = |sigma1: f64| step_overshoot(params, LuGreParams { sigma1, ..model }, a);
    // from the heavily damped end down, the first value whose overshoot
    // reaches the measured one brackets it (below some damping the hold
    // ends mid-swing and the ratio is no longer monotonic)
    const GRID: u32 = 40;
    let at = |k: u32| 4.0 * critical * libm::pow(0.0025, f64::from(k) / f64::from(GRID));
    let Some(k) = (0..=GRID).find(|&k| ratio(at(k)) >= target) else {
        return (critical, false);
    };
    if k == 0 {
        return (critical, false);
    }
    let (mut lo, mut hi) = (at(k), at(k - 1));
    for _ in 0..30 {
        let mid = 0.5 * (lo + hi);
        if ratio(mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (0.5 * (lo + hi), true)
}

/// The overshoot ratio of the presliding step simulated on `model` with
/// the loop's inertia: from rest under `a` (`z = a / sigma0`), the force
/// stepped to `a / 2` and held as the routine holds it, the position
/// sampled at the loop's period (20 integration steps each).
fn step_overshoot(params: &CommissioningParams, model: LuGreParams, a: f64) -> f64 {
    const SUBSTEPS: u32 = 20;
    let Ok(lugre) = model.build::<f64>() else {
        return f64::NAN;
    };
    let h = params.servo.h / f64::from(SUBSTEPS);
    let inertia = params.servo.inertia;
    let mut z = crate::LuGreState {
        z: a / model.sigma0,
    };
    let (mut x, mut v, mut lowest) = (0.0f64, 0.0f64, 0.0f64);
    let periods = libm::ceil(super::PRESLIDING_HOLD / params.servo.h);
    // a loop faster than 100 kHz (or a period C's memory garbled) would
    // make the fit's up to 71 simulations of the hold unbounded in time:
    // sigma1 is then not identified (the NaN ratio fails every check)
    if periods.is_nan() || periods > MAX_SIMULATED_PERIODS {
        return f64::NAN;
    }
    let periods = periods as u32;
    for _ in 0..periods {
        for _ in 0..SUBSTEPS {
            let f = crate::FrictionModel::step(&lugre, &mut z, v, h);
            v += h * (0.5 * a - f) / inertia;
            x += h * v;
        }
        lowest = lowest.min(x);
    }
    (x - lowest) / -x
}

/// The position's resolution: the encoder's count, or the scalar's own
/// where it is coarser (Q16.16 holds a position to 1/65536).
fn resolution<S: Scalar>(params: &CommissioningParams) -> f64 {
    params.resolution.max(S::MIN_POSITIVE.to_f64())
}
