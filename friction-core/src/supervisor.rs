//! A supervisor that makes an adaptive compensation safe to ship enabled: it
//! applies whichever of three candidates predicts the measured friction best,
//! with hysteresis: see [`Supervised`].

use crate::bits::Flag;
use crate::compensator::{Compensation, CompensatorParams, FrictionSample};
use crate::gain::Gain;
use crate::model::{non_negative, positive, FrictionModel, ParamError};
use crate::Scalar;

/// Which candidate the supervisor applies.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SupervisorMode {
    /// The primary (adaptive) compensation.
    #[default]
    Primary,
    /// The static feed-forward fallback.
    Fallback,
    /// No compensation.
    Off,
}

impl SupervisorMode {
    const ALL: [SupervisorMode; 3] = [
        SupervisorMode::Primary,
        SupervisorMode::Fallback,
        SupervisorMode::Off,
    ];

    fn index(self) -> usize {
        match self {
            SupervisorMode::Primary => 0,
            SupervisorMode::Fallback => 1,
            SupervisorMode::Off => 2,
        }
    }

    /// A number for traces: 0 primary, 1 fallback, 2 off.
    pub fn code(self) -> u8 {
        self.index() as u8
    }

    /// The mode of a [`SupervisorMode::code`], any byte being one (`Primary` for a
    /// byte no mode has): a state stores the code (`crate::bits`).
    fn of_code(code: u8) -> Self {
        match code {
            1 => SupervisorMode::Fallback,
            2 => SupervisorMode::Off,
            _ => SupervisorMode::Primary,
        }
    }
}

/// The fewest controller periods an evidence window may span: a window's
/// close, spread over the ticks from it on (close, force, square, blend,
/// track, judge, choose), ends before the next one closes.
pub const MIN_WINDOW_TICKS: u32 = 7;

/// Design-time parameters of the supervisor, in `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SupervisorParams {
    /// Evidence window (s, `> 0`): one prediction error per window, of at
    /// least [`MIN_WINDOW_TICKS`] controller periods (its close is spread
    /// over that many ticks).
    pub window: f64,
    /// Memory of the mean-square prediction errors, in windows (`>= 1`).
    pub memory: f64,
    /// Hysteresis: switch when the best candidate's error is below `ratio`
    /// times the active one's (`0 < ratio <= 1`).
    pub ratio: f64,
    /// Windows before the first switch (`>= 0`).
    pub warm_up: f64,
    /// Windows in a fallback mode after which the primary is tried again
    /// (`>= 0`; 0: never), unless the fallback tracks clearly better than
    /// the primary had. A primary whose adaptation holds while it is not
    /// applied can only learn while it is: a retry lets one that was judged
    /// too early catch up, once the fallback no longer tracks clearly better
    /// than the primary's last figure.
    pub retry: f64,
    /// Prediction errors below this (force units, RMS over a window) count
    /// as equal (`>= 0`): a few per cent of the friction level, so that
    /// two good candidates do not trade places on noise.
    pub tolerance: f64,
}

impl SupervisorParams {
    /// Windows of 0.1 s, a memory of 10 windows, ratio 0.7, warm-up 10
    /// windows, a retry after 100 windows, no tolerance (set one: e.g. a few
    /// per cent of the Coulomb level).
    pub const DEFAULT: Self = Self {
        window: 0.1,
        memory: 10.0,
        ratio: 0.7,
        warm_up: 10.0,
        retry: 100.0,
        tolerance: 0.0,
    };

    /// Checks every setting; the error names it.
    pub fn validate(&self) -> Result<(), ParamError> {
        positive("window", self.window)?;
        positive("memory", self.memory)?;
        if self.memory < 1.0 {
            return Err(ParamError::BelowOne("memory"));
        }
        positive("ratio", self.ratio)?;
        if self.ratio > 1.0 {
            return Err(ParamError::NotBelow {
                name: "ratio",
                limit: "1",
            });
        }
        non_negative("warm_up", self.warm_up)?;
        non_negative("retry", self.retry)?;
        non_negative("tolerance", self.tolerance)?;
        Ok(())
    }

    /// Validates and builds the supervisor of `primary` with the static map
    /// `fallback`, for the compensator of `servo` (its period, inertia and
    /// torque constant: the evidence is the friction they measure).
    ///
    /// ```
    /// use friction_core::{CompensatorParams, CoulombViscousParams, LuGreParams, Observer, SupervisorParams};
    /// let servo = CompensatorParams { h: 1e-3, kp: 60.0, ki: 200.0, kd: 1.2,
    ///     inertia: 0.0023, torque_constant: 1.02, limit: 10.0 };
    /// let observer: Observer<_, f32> = Observer::new(LuGreParams::OLSSON_1998.build::<f32>()?, 20.0)?;
    /// let fallback = CoulombViscousParams { fc: 0.28, sigma2: 0.0176 }.build::<f32>()?;
    /// let supervised = SupervisorParams::DEFAULT.build::<f32, _, _>(observer, fallback, &servo)?;
    /// # let _ = supervised;
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    pub fn build<S: Scalar, P, F>(
        &self,
        primary: P,
        fallback: F,
        servo: &CompensatorParams,
    ) -> Result<Supervised<P, F, S>, ParamError> {
        self.validate()?;
        servo.validate()?;
        let h = servo.h;
        let ticks = libm::round(self.window / h).max(1.0);
        // the window's sum of commands must fit the scalar (Q16.16: below
        // 32,768 command units)
        if ticks < f64::from(MIN_WINDOW_TICKS)
            || ticks > 1e6
            || S::try_from_f64(ticks * servo.limit).is_err()
        {
            return Err(ParamError::OutOfRange("window"));
        }
        Ok(Supervised {
            primary,
            fallback,
            window: ticks as u32,
            inv_window: S::from_f64(1.0 / ticks),
            torque_constant: Gain::new("torque_constant", servo.torque_constant)?,
            momentum: Gain::new("inertia", servo.inertia / h)?,
            period: h,
            blend: S::from_f64(1.0 / self.memory),
            ratio: S::from_f64(self.ratio),
            tracking_ratio: S::from_f64(self.ratio * self.ratio),
            floor: S::from_f64(self.tolerance * self.tolerance),
            warm_up: libm::ceil(self.warm_up).min(1e9) as u32,
            dwell: libm::ceil(self.memory).min(1e9) as u32,
            retry: libm::ceil(self.retry).min(1e9) as u32,
            params: *self,
        })
    }
}

impl Default for SupervisorParams {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// What the supervisor knows: the mode, how often it switched, each
/// candidate's filtered mean-square prediction error `[primary, fallback,
/// off]` (force units squared) and each mode's tracking while applied.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SupervisorStatus<S> {
    /// The applied candidate.
    pub mode: SupervisorMode,
    /// Switches so far.
    pub switches: u32,
    /// Completed evidence windows (each counted when its evidence has
    /// chosen the mode, six ticks after it closed).
    pub windows: u32,
    /// Windows since the last switch (counted as `windows`).
    pub since_switch: u32,
    /// Mean-square prediction errors `[primary, fallback, off]`.
    pub errors: [S; 3],
    /// Mean-square tracking errors `[primary, fallback, off]` while each
    /// was applied (position units squared; one sample a window, filtered
    /// over the memory; 0 until measured over half a dwell since it was
    /// last switched to).
    pub tracking: [S; 3],
}

/// The supervisor's state: the primary's, the status and the window's sums.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SupervisedState<T, S> {
    /// The primary compensation's state.
    pub primary: T,
    status: StoredStatus<S>,
    /// Sums over the window's ticks: commands issued, primary and fallback
    /// estimates.
    sums: [S; 3],
    /// The same three at the latest tick, and at the tick before the
    /// window's first: the window's ends count half (see [`Supervised`]).
    last: [S; 3],
    before: [S; 3],
    /// The measured velocity at the window's first tick.
    start_velocity: S,
    /// Ticks in the window so far.
    count: u32,
    /// Whether the window began at a close: the first window after a
    /// start, a skipped tick or a swap is not measured (its first
    /// velocity and commands are not the window's).
    measuring: Flag,
    /// The last closed window's sums `[commands, primary, fallback]` (their
    /// ends counted half) until its force is formed, then its errors
    /// `[primary, fallback, off]` (summed, then squared means), until
    /// blended in.
    pending: [S; 3],
    /// A [`Stage`]'s code.
    stage: u8,
    /// Each mode's filtered mean-square tracking error while applied, and
    /// how many windows measured it since it was last switched to.
    tracking: [S; 3],
    tracked: [u8; 3],
    /// The tracking error at the last close.
    error_sample: S,
    /// The measured velocity's change across the last closed window, until
    /// its momentum is formed ([`Stage::Force`]).
    velocity_change: S,
    /// The modes the applied one tracked better and worse than, a bit per
    /// mode (see [`Supervised`]'s `judge_modes`).
    beaten: u8,
    beaten_by: u8,
    /// Whether the applied primary is a retry, not judged yet.
    retried: Flag,
}

/// A [`SupervisorStatus`] as a state stores it: the mode as its code, so
/// that every bit pattern is a value (`crate::bits`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct StoredStatus<S> {
    mode: u8,
    switches: u32,
    windows: u32,
    since_switch: u32,
    errors: [S; 3],
}

impl<S: Copy + Default> StoredStatus<S> {
    fn new(s: SupervisorStatus<S>) -> Self {
        Self {
            mode: s.mode.code(),
            switches: s.switches,
            windows: s.windows,
            since_switch: s.since_switch,
            errors: s.errors,
        }
    }

    fn get(&self) -> SupervisorStatus<S> {
        SupervisorStatus {
            mode: self.mode(),
            switches: self.switches,
            windows: self.windows,
            since_switch: self.since_switch,
            errors: self.errors,
            ..SupervisorStatus::default()
        }
    }

    #[inline]
    fn mode(&self) -> SupervisorMode {
        SupervisorMode::of_code(self.mode)
    }
}

/// The built supervisor around a primary compensation `P` and a static
/// fallback map `F`: a [`Compensation`] itself.
///
/// A supervisor that makes an adaptive compensation safe to ship enabled:
/// it applies whichever of three candidates predicts the measured friction
/// best, with hysteresis, unless the tracking each had while applied says
/// otherwise.
///
/// The candidates are the primary compensation (an adaptive observer), a
/// static feed-forward map `F(v)` on the measured velocity (the fallback),
/// and no compensation at all. All three run every tick; only the active
/// one reaches the command. The evidence is the friction the compensator
/// measures, the sum of the [`FrictionSample`]s (commands less inertia
/// times the second difference of the position) over a window of `N`
/// ticks, written without forming them: the second differences telescope
/// into the change of the measured velocity across the window, so the
/// window needs only the sum of the commands and carries the encoder's
/// rounding only from its two ends:
///
/// ```text
/// sum x   = x[-1] / 2 + x[0] + ... + x[N-2] + x[N-1] / 2               x[-1]: the tick before the window
/// E_c     = (kc sum u - J (v_end - v_start) / h - sum F_c) / N     each candidate c, per window
/// P_c    += (E_c^2 - P_c) / memory                                  per window
/// switch from the active a to the best b when P_b < ratio P_a (after warm-up, and at most once per window)
/// T_a    += (e^2 - T_a) / memory                                    per window, the applied mode's tracking
/// but stay in a when T_a < ratio^2 T_b (both known); a retried primary goes back when T_m < ratio^2 T_primary
/// retry the primary after `retry` windows in a fallback mode m, unless T_m < ratio^2 T_primary (both known)
/// ```
///
/// The sums run over the window's ticks (`u` the commands issued, `F_c` the
/// candidate's estimates), with the ends counted half as the samples,
/// which average two ticks, count them; `v_start` and
/// `v_end` are the measured velocities at the window's first tick and at
/// the tick after its last (with a velocity filter or observer, its
/// estimate). The first window after a start, a skipped tick (a non-finite
/// input) or a swap ([`Compensation::carry_over`]) is not measured: its
/// first velocity is not the window's. An external torque (gravity, a load) is
/// in the measured friction for every candidate alike. A candidate that
/// predicts worse than no compensation loses to it: the compensator falls
/// back to the static map or to nothing, and returns to the primary when its
/// prediction is better again. The primary keeps running in the background
/// on the measured velocity, with its adaptation held (it sees no tracking
/// error while it is not applied).
///
/// The friction a candidate predicts is evidence for all three at once;
/// what each does to the tracking is known only for the modes applied, and
/// it is what counts: an observer whose levels wander can still track well
/// on its correction, and one that rings at reversals can predict a
/// window's mean friction well. So each mode's tracking error `T` (the
/// position error at each window's close, squared and filtered over the
/// memory) is measured while it is applied, from half a dwell after the
/// switch to it (the switch's transient settled), and counts once it has
/// been measured over half a dwell since it was last switched to. The
/// tracking overrules the prediction in two ways, by the ratio on the rms
/// (`ratio^2` on the mean squares: tracking errors of different times are
/// compared, so only a clear difference counts): the applied mode stays
/// while it tracks better than the mode the prediction chooses had
/// tracked; and a primary retried after `retry` windows in a fallback mode
/// goes back at the end of its dwell if it tracks worse than the fallback
/// (or no compensation) did, to the fallback where both did. The first rule
/// holds for the retry as well: it waits while the applied fallback mode
/// (the static map or none) tracks clearly better than the primary had (a
/// retry in mid-run costs a dwell of the primary's worse tracking and its
/// adaptation's transient).
///
/// Limits: one sample a window is a coarse measure (a periodic reference
/// can alias with the windows); a mode's figure is renewed only while it
/// is applied, so the applied mode is kept while it tracks better than an
/// old figure of the other (measured in a worse stretch, it holds the
/// applied mode longer; a primary that tracked worse while it was still
/// learning is not retried while the fallback keeps tracking better than
/// that); in Q16.16 an error below a few mrad squares to 0 (two such modes
/// are equal, and the prediction decides).
///
/// The state and the reason are readable ([`Supervised::status`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Supervised<P, F, S> {
    primary: P,
    fallback: F,
    window: u32,
    inv_window: S,
    torque_constant: Gain<S>,
    /// `J / h`: the window's momentum change per unit of velocity change.
    momentum: Gain<S>,
    /// The compensator's period it was built for.
    period: f64,
    blend: S,
    ratio: S,
    /// `ratio^2`: the ratio on the rms tracking errors.
    tracking_ratio: S,
    floor: S,
    warm_up: u32,
    dwell: u32,
    retry: u32,
    params: SupervisorParams,
}

impl<P, F, S: Scalar> Supervised<P, F, S> {
    /// The primary compensation.
    pub fn primary(&self) -> &P {
        &self.primary
    }

    /// The parameters it was built from.
    pub fn params(&self) -> &SupervisorParams {
        &self.params
    }

    /// The status of `state`.
    pub fn status<T>(&self, state: &SupervisedState<T, S>) -> SupervisorStatus<S> {
        let enough = self.tracking_windows();
        let mut status = state.status.get();
        for ((out, value), count) in status
            .tracking
            .iter_mut()
            .zip(state.tracking)
            .zip(state.tracked)
        {
            if count >= enough {
                *out = value;
            }
        }
        status
    }

    /// The windows a mode's tracking is measured over before it counts:
    /// half a dwell.
    fn tracking_windows(&self) -> u8 {
        (self.dwell / 2).clamp(1, 255) as u8
    }

    /// Ends a window at measured velocity `v` and tracking error `e` (the
    /// tick after its last): its sums, the velocity's change and `e` wait
    /// in `pending`, `velocity_change` and `error_sample` for the next six
    /// ticks, which form the measured force and the prediction errors
    /// ([`Self::form_force`]), square them ([`Self::square_errors`]), blend
    /// them in ([`Self::blend_errors`], [`Self::track_modes`]), judge the
    /// tracking ([`Self::judge_modes`]) and choose the mode
    /// ([`Self::choose_mode`]).
    // The window's work is spread over seven ticks: it runs inside the
    // control tick, and its cost is the tick's worst case.
    fn close_window<T>(&self, state: &mut SupervisedState<T, S>, v: S, e: S) {
        let sums = state.sums;
        let [last, before] = [state.last, state.before];
        let start_velocity = state.start_velocity;
        let measured = state.measuring.get();
        state.sums = [S::ZERO; 3];
        state.count = 0;
        state.before = last;
        state.start_velocity = v;
        state.measuring = Flag::new(true);
        if !measured {
            return;
        }
        // the window's ends count half: the sum of the friction samples
        // `kc (u[k-1] + u[k-2]) / 2 - J (v[k] - v[k-1]) / h` over its ticks
        // halved by a shift in fixed point (`Kernels::half`): the same bits
        let end = |sum: S, l: S, b: S| sum - (l - b).half();
        let ([c, p, f], [lc, lp, lf], [bc, bp, bf]) = (sums, last, before);
        state.pending = [end(c, lc, bc), end(p, lp, bp), end(f, lf, bf)];
        state.velocity_change = v - start_velocity;
        state.error_sample = e;
        state.stage = Stage::Force as u8;
    }

    /// The closed window's measured friction, `kc sum u - J dv / h`, and
    /// the candidates' summed prediction errors against it (a stage of its
    /// own: its two products would add to the close's tick).
    fn form_force<T>(&self, state: &mut SupervisedState<T, S>) {
        let [commands, primary, fallback] = state.pending;
        let force =
            self.torque_constant.times(commands) - self.momentum.times(state.velocity_change);
        state.pending = [force - primary, force - fallback, force];
        state.stage = Stage::Square as u8;
    }

    /// The closed window's next stage.
    fn next_stage<T>(&self, state: &mut SupervisedState<T, S>) {
        match Stage::of_code(state.stage) {
            Stage::Force => self.form_force(state),
            Stage::Square => self.square_errors(state),
            Stage::Blend => self.blend_errors(state),
            Stage::Track => self.track_modes(state),
            Stage::Judge => self.judge_modes(state),
            Stage::Choose => self.choose_mode(state),
            Stage::Idle => state.stage = Stage::Idle as u8,
        }
    }

    /// The closed window's summed errors into its squared mean errors.
    fn square_errors<T>(&self, state: &mut SupervisedState<T, S>) {
        for p in state.pending.iter_mut() {
            *p = bounded_square(*p * self.inv_window);
        }
        state.stage = Stage::Blend as u8;
    }

    /// The closed window's squared errors into the filtered ones.
    fn blend_errors<T>(&self, state: &mut SupervisedState<T, S>) {
        let st = &mut state.status;
        let first = st.windows == 0;
        for (p, squared) in st.errors.iter_mut().zip(state.pending) {
            *p = if first || !p.is_finite() {
                squared
            } else {
                *p + self.blend * (squared - *p)
            };
        }
        state.stage = Stage::Track as u8;
    }

    /// The applied mode's tracking error into its filtered one, once the
    /// switch's transient has settled (half a dwell).
    fn track_modes<T>(&self, state: &mut SupervisedState<T, S>) {
        state.stage = Stage::Judge as u8;
        // the window is counted in `choose_mode`: `since_switch + 1 <= dwell / 2`
        if state.status.since_switch < self.dwell / 2 {
            return;
        }
        let c = state.status.mode().index();
        // squared here, not at the close: the square stage is a worst case
        let sample = bounded_square(state.error_sample);
        // no indexing: the core never panics
        for (i, (t, count)) in state
            .tracking
            .iter_mut()
            .zip(&mut state.tracked)
            .enumerate()
        {
            if i == c {
                *t = if *count == 0 || !t.is_finite() {
                    sample
                } else {
                    *t + self.blend * (sample - *t)
                };
                *count = count.saturating_add(1);
            }
        }
    }

    /// The tracking's verdict for [`Self::choose_mode`] (a stage of its own:
    /// each stage's work adds to the tick's worst case): the modes the
    /// applied one tracked better and worse than, by the ratio on the rms
    /// (`beaten`, `beaten_by`, a bit per mode), of those whose tracking is
    /// known (measured over half a dwell since each was last switched to).
    fn judge_modes<T>(&self, state: &mut SupervisedState<T, S>) {
        state.stage = Stage::Choose as u8;
        let c = state.status.mode().index();
        let (mut own, mut own_count) = (S::ZERO, 0u8);
        for (i, (&t, &count)) in state.tracking.iter().zip(&state.tracked).enumerate() {
            if i == c {
                (own, own_count) = (t, count);
            }
        }
        let enough = self.tracking_windows();
        let (mut beaten, mut beaten_by) = (0u8, 0u8);
        if own_count >= enough {
            for (i, (&error, &count)) in state.tracking.iter().zip(&state.tracked).enumerate() {
                if i != c && count >= enough {
                    if own < self.tracking_ratio * error {
                        beaten |= 1 << i;
                    } else if error < self.tracking_ratio * own {
                        beaten_by |= 1 << i;
                    }
                }
            }
        }
        state.beaten = beaten;
        state.beaten_by = beaten_by;
    }

    /// Past the warm-up and the dwell, switches to the candidate whose
    /// error is below `ratio` times the active one's, or retries the primary.
    fn choose_mode<T>(&self, state: &mut SupervisedState<T, S>) {
        state.stage = Stage::Idle as u8;
        let st = &mut state.status;
        // the window counts here, not where its errors are blended: each
        // stage's work adds to the tick's worst case
        st.windows = st.windows.saturating_add(1);
        st.since_switch = st.since_switch.saturating_add(1);
        // a switch holds for `dwell` windows (the errors then reflect it)
        if st.windows <= self.warm_up || st.since_switch < self.dwell {
            return;
        }
        let [primary, fallback, off] = st.errors.map(|x| x.max(self.floor));
        let current = st.mode();
        let active = match current {
            SupervisorMode::Primary => primary,
            SupervisorMode::Fallback => fallback,
            SupervisorMode::Off => off,
        };
        // the candidate with the smallest error, the active one on a tie
        let (mut next, mut best) = (current, active);
        for (m, error) in SupervisorMode::ALL
            .into_iter()
            .zip([primary, fallback, off])
        {
            if error < best {
                (next, best) = (m, error);
            }
        }
        if best >= self.ratio * active {
            next = current;
        }
        // the applied mode stays while it tracks clearly better than the
        // one chosen had tracked (see `judge_modes`)
        let beaten = state.beaten;
        if beaten & (1 << next.index()) != 0 {
            next = current;
        }
        // a retried primary that tracks clearly worse than the fallback (or
        // no compensation) did before it goes back
        if state.retried.get() {
            state.retried = Flag::new(false);
            for m in [SupervisorMode::Off, SupervisorMode::Fallback] {
                if state.beaten_by & (1 << m.index()) != 0 {
                    next = m;
                }
            }
        }
        // the retry, unless the applied mode tracks clearly better than
        // the primary had (the rule above: a retry would spend a dwell on
        // what is known worse)
        if next == current
            && current != SupervisorMode::Primary
            && self.retry > 0
            && st.since_switch >= self.retry
            && beaten & (1 << SupervisorMode::Primary.index()) == 0
        {
            next = SupervisorMode::Primary;
            state.retried = Flag::new(true);
        }
        if next != current {
            for (i, count) in state.tracked.iter_mut().enumerate() {
                if i == next.index() {
                    *count = 0;
                }
            }
            st.mode = next.code();
            st.switches = st.switches.saturating_add(1);
            st.since_switch = 0;
        }
    }
}

/// `x²`, at most `1e30`; a non-finite `x` gives `1e30` (a window summed
/// from a non-finite estimate is the worst evidence).
#[inline]
fn bounded_square<S: Scalar>(x: S) -> S {
    let big = S::from_f64(1e30);
    let square = x * x;
    // one comparison, false for NaN and infinity: cheaper in the stage's
    // tick than a check of finiteness and a clamp before the product
    if square < big {
        square
    } else {
        big
    }
}

/// Where a closed window's evidence stands (a byte in the state, any value
/// other than these being `Idle`).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Stage {
    Idle = 0,
    Square = 1,
    Blend = 2,
    Track = 3,
    Judge = 4,
    Choose = 5,
    Force = 6,
}

impl Stage {
    fn of_code(code: u8) -> Self {
        match code {
            1 => Stage::Square,
            2 => Stage::Blend,
            3 => Stage::Track,
            4 => Stage::Judge,
            5 => Stage::Choose,
            6 => Stage::Force,
            _ => Stage::Idle,
        }
    }
}

impl<S: Scalar, P: Compensation<S>, F: FrictionModel<S, State = ()>> Compensation<S>
    for Supervised<P, F, S>
{
    type State = SupervisedState<P::State, S>;
    const LEARNS: bool = P::LEARNS;
    const LOADED: bool = P::LOADED;
    const USES_H: bool = P::USES_H;

    /// Steps every candidate and returns the active one's estimate. The
    /// primary sees the tracking error only while it is applied: inactive,
    /// it is given `e = 0`, so its model runs on the measured velocity and
    /// its adaptation (driven by `e`) holds. Adapting on an error that
    /// another compensation caused would teach it the wrong values.
    #[inline]
    fn estimate(&self, state: &mut Self::State, v: S, e: S, h: S) -> S {
        if state.count >= self.window {
            self.close_window(state, v, e);
        } else if state.stage != Stage::Idle as u8 {
            self.next_stage(state);
        }
        let e = if state.status.mode() == SupervisorMode::Primary {
            e
        } else {
            S::ZERO
        };
        // not made finite here: the compensator zeroes a non-finite
        // estimate, and the window that sums one is judged the worst
        let primary = self.primary.estimate(&mut state.primary, v, e, h);
        // a map without state ignores the period: a constant one lets the
        // compiler drop the period's checks from the tick
        let fallback = self.fallback.step(&mut (), v, S::ZERO);
        let [_, p, f] = &mut state.sums;
        *p = *p + primary;
        *f = *f + fallback;
        state.last[1] = primary;
        state.last[2] = fallback;
        // below the window (at most 1e6 ticks) but in a state of any bits
        state.count = state.count.wrapping_add(1);
        match state.status.mode() {
            SupervisorMode::Primary => primary,
            SupervisorMode::Fallback => fallback,
            SupervisorMode::Off => S::ZERO,
        }
    }

    /// The period it was built for: its window's momentum is `J / h`.
    fn period(&self) -> Option<f64> {
        Some(self.period)
    }

    #[inline]
    fn learn(&self, state: &mut Self::State, sample: FrictionSample<S>) {
        self.primary.learn(&mut state.primary, sample);
    }

    fn motor_torque(&self, state: &mut Self::State, torque: S) {
        self.primary.motor_torque(&mut state.primary, torque);
    }

    #[inline]
    fn commanded(&self, state: &mut Self::State, command: S) {
        self.primary.commanded(&mut state.primary, command);
        state.sums[0] = state.sums[0] + command;
        state.last[0] = command;
    }

    #[inline]
    fn set_external_torque(&self, state: &mut Self::State, torque: S) {
        self.primary.set_external_torque(&mut state.primary, torque);
    }

    /// The window restarts and is not measured: a gap's commands and
    /// velocities are not the compensator's.
    fn skipped(&self, state: &mut Self::State) {
        self.primary.skipped(&mut state.primary);
        state.sums = [S::ZERO; 3];
        state.count = 0;
        state.measuring = Flag::new(false);
    }

    /// The primary's state carried over ([`Compensation::carry_over`]; the
    /// fallback is a static map, with nothing to carry). The applied mode is
    /// kept, so the swap changes the command only by the change of the
    /// applied estimate; the evidence is restarted (errors, window, warm-up:
    /// it measured the old candidates, not these), and the switch count kept.
    fn carry_over(&self, old: &Self, state: &mut Self::State) {
        self.primary.carry_over(&old.primary, &mut state.primary);
        let mode = state.status.mode();
        let switches = state.status.switches;
        state.status = StoredStatus::new(SupervisorStatus {
            mode,
            switches,
            ..SupervisorStatus::default()
        });
        state.sums = [S::ZERO; 3];
        state.count = 0;
        state.measuring = Flag::new(false);
        state.stage = Stage::Idle as u8;
        state.tracked = [0; 3];
        state.retried = Flag::new(false);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{CompensatorState, CoulombViscous, CoulombViscousParams, FeedForward, Setpoint};

    use crate::test_servo::olsson_servo as servo;

    fn map(fc: f64) -> CoulombViscous<f64> {
        CoulombViscousParams { fc, sigma2: 0.0176 }.build().unwrap()
    }

    /// A supervised servo of the tests, around `primary` with the fallback map.
    type Servo<P> = crate::Compensator<f64, Supervised<P, CoulombViscous<f64>, f64>>;

    /// A plant `J dv/dt = kc u - scale(t) F_cv(v)` (Coulomb + viscous,
    /// smoothed over 1e-3 rad/s) under `ctl` for `ticks` ticks, its measured
    /// position `NaN` at the ticks in `gaps`: after each tick, the status and
    /// the plant's friction impulse since tick 0 (its integral over time).
    fn simulate<P: Compensation<f64>>(
        ctl: &Servo<P>,
        scale: impl Fn(f64) -> f64,
        ticks: usize,
        gaps: &[usize],
    ) -> std::vec::Vec<(SupervisorStatus<f64>, f64)> {
        let mut s = CompensatorState::default();
        let (mut x, mut v, mut impulse) = (0.0f64, 0.0f64, 0.0f64);
        let w = 2.0 * core::f64::consts::PI * 0.5;
        let mut out = std::vec::Vec::new();
        for k in 0..ticks {
            let t = k as f64 * 1e-3;
            let r = Setpoint {
                x: 0.5 * libm::sin(w * t),
                v: 0.5 * w * libm::cos(w * t),
                a: -0.5 * w * w * libm::sin(w * t),
            };
            let measured = if gaps.contains(&k) { f64::NAN } else { x };
            let u = ctl.tick(&mut s, measured, r).command;
            for _ in 0..100 {
                let f = scale(t) * (0.28 * libm::tanh(v / 1e-3) + 0.0176 * v);
                impulse += 1e-5 * f;
                v += 1e-5 * (1.02 * u - f) / 0.0023;
                x += 1e-5 * v;
            }
            out.push((ctl.compensation().status(s.friction()), impulse));
        }
        out
    }

    /// The mode after each second of [`simulate`] without gaps.
    fn run<P: Compensation<f64>>(
        ctl: &Servo<P>,
        scale: impl Fn(f64) -> f64,
        seconds: usize,
    ) -> std::vec::Vec<SupervisorMode> {
        simulate(ctl, scale, seconds * 1000, &[])
            .iter()
            .skip(999)
            .step_by(1000)
            .map(|(status, _)| status.mode)
            .collect()
    }

    #[test]
    fn falls_back_from_a_harmful_primary_and_releases_when_it_is_right_again() {
        // the primary is a feed-forward of three times the plant's friction
        // until the plant's friction triples at 20 s; the fallback is
        // right before and a third after
        let primary = FeedForward(map(0.84));
        let sup = SupervisorParams::DEFAULT
            .build(primary, map(0.28), &servo())
            .unwrap();
        let ctl = servo().build(sup).unwrap();
        let modes = run(&ctl, |t| if t < 20.0 { 1.0 } else { 3.0 }, 40);
        // the warm-up
        assert_eq!(modes[0], SupervisorMode::Primary, "{modes:?}");
        // in the fallback from the second second on, without a retry: the
        // fallback tracks clearly better than the primary did
        assert!(
            modes[1..20].iter().all(|m| *m == SupervisorMode::Fallback),
            "{modes:?}"
        );
        assert!(
            modes[30..].iter().all(|m| *m == SupervisorMode::Primary),
            "{modes:?}"
        );
    }

    #[test]
    fn a_primary_that_predicts_well_stays() {
        // the primary is the plant's own map, the fallback half of it
        let sup = SupervisorParams::DEFAULT
            .build(FeedForward(map(0.28)), map(0.14), &servo())
            .unwrap();
        let ctl = servo().build(sup).unwrap();
        let modes = run(&ctl, |_| 1.0, 20);
        assert!(
            modes.iter().all(|m| *m == SupervisorMode::Primary),
            "{modes:?}"
        );
    }

    /// The supervisor driven directly for `seconds`: the velocity held at
    /// 0.1 rad/s, the commands those of a plant whose friction is the map
    /// of level `truth(t)`, the tracking error 1e-4 rad while the primary is
    /// applied and `fallback_error` otherwise; the mode after each second.
    fn drive(
        sup: &Supervised<FeedForward<CoulombViscous<f64>>, CoulombViscous<f64>, f64>,
        truth: impl Fn(f64) -> f64,
        fallback_error: f64,
        seconds: usize,
    ) -> std::vec::Vec<SupervisorMode> {
        let mut s = SupervisedState::default();
        let mut modes = std::vec::Vec::new();
        for k in 0..seconds * 1000 {
            let t = k as f64 * 1e-3;
            let e = match sup.status(&s).mode {
                SupervisorMode::Primary => 1e-4,
                _ => fallback_error,
            };
            sup.estimate(&mut s, 0.1, e, 1e-3);
            let friction = map(truth(t)).step(&mut (), 0.1, 0.0);
            sup.commanded(&mut s, friction / 1.02);
            if k % 1000 == 999 {
                modes.push(sup.status(&s).mode);
            }
        }
        modes
    }

    #[test]
    fn a_primary_that_tracks_better_is_kept_though_it_predicts_worse() {
        // the primary predicts twice the friction, the fallback the
        // friction itself; the primary tracks to 0.1 mrad, the fallback to
        // 10 mrad
        let sup = SupervisorParams::DEFAULT
            .build(FeedForward(map(0.56)), map(0.28), &servo())
            .unwrap();
        let modes = drive(&sup, |_| 0.28, 1e-2, 30);
        // the prediction chooses the fallback after the warm-up; the
        // primary, retried after 10 s in it, tracks clearly better than the
        // fallback did and is kept for good
        assert!(
            modes[1..10].iter().all(|m| *m == SupervisorMode::Fallback),
            "{modes:?}"
        );
        assert!(
            modes[11..].iter().all(|m| *m == SupervisorMode::Primary),
            "{modes:?}"
        );
        // with equal tracking the prediction decides: the fallback, but
        // for the retries of the primary
        let modes = drive(&sup, |_| 0.28, 1e-4, 30);
        let primary = modes[2..]
            .iter()
            .filter(|m| **m == SupervisorMode::Primary)
            .count();
        assert!((1..=3).contains(&primary), "{modes:?}");
    }

    #[test]
    fn a_fallback_that_tracked_better_is_kept_though_the_primary_predicts_better() {
        // the fallback predicts the friction for 3 s, the primary after
        // it; the fallback tracks to 0.1 mrad until 20 s and to 10 mrad
        // after, the primary to 10 mrad
        let sup = SupervisorParams::DEFAULT
            .build(FeedForward(map(0.56)), map(0.28), &servo())
            .unwrap();
        let mut s = SupervisedState::default();
        let truth = |t: f64| if t < 3.0 { 0.28 } else { 0.56 };
        let mut modes = std::vec::Vec::new();
        for k in 0..30_000 {
            let t = k as f64 * 1e-3;
            let e = match sup.status(&s).mode {
                SupervisorMode::Primary => 1e-2,
                _ if t < 20.0 => 1e-4,
                _ => 1e-2,
            };
            sup.estimate(&mut s, 0.1, e, 1e-3);
            sup.commanded(&mut s, map(truth(t)).step(&mut (), 0.1, 0.0) / 1.02);
            if k % 1000 == 999 {
                modes.push(sup.status(&s).mode);
            }
        }
        // in the fallback from the second second on (from 3 s, when the
        // primary predicts better, because the fallback tracked better),
        // without the retry due at 11 s while the fallback tracks clearly
        // better than the primary did; once it no longer does (from 20 s)
        // the prediction's choice of the primary is no longer held back,
        // and it is kept
        assert!(
            modes[1..20].iter().all(|m| *m == SupervisorMode::Fallback),
            "{modes:?}"
        );
        assert!(
            modes[23..].iter().all(|m| *m == SupervisorMode::Primary),
            "{modes:?}"
        );
    }

    /// No compensation as the primary: its error is the measured mean
    /// friction itself, as the window's commands and velocities give it.
    fn measuring_servo() -> Servo<crate::NoCompensation> {
        let sup = SupervisorParams::DEFAULT
            .build(crate::NoCompensation, map(0.28), &servo())
            .unwrap();
        servo().build(sup).unwrap()
    }

    /// A window's measured mean friction (the root of its mean-square
    /// error `error`) within 0.5 % of the Coulomb level of the plant's
    /// `truth`.
    fn assert_measures(error: f64, truth: f64) {
        let measured = libm::sqrt(error);
        assert!(
            (measured - truth.abs()).abs() < 0.005 * 0.28,
            "measured {measured}, plant {truth}"
        );
    }

    #[test]
    fn a_window_measures_the_plants_mean_friction() {
        // the plant's own integral of its friction is the truth
        let run = simulate(&measuring_servo(), |_| 1.0, 207, &[]);
        // the window of ticks 0..100 (the first after a start, not
        // measured) closes at tick 100, the window of ticks 100..200 at
        // tick 200; its force is formed at 201, its errors squared at 202,
        // blended (the first: taken as they are) at 203 and the window
        // counted at the choice, at 206
        assert_eq!(run[202].0.errors, [0.0; 3]);
        assert_ne!(run[203].0.errors, [0.0; 3]);
        assert_eq!(run[205].0.windows, 0);
        let status = run[206].0;
        assert_eq!(status.windows, 1);
        assert_eq!(status.errors, run[203].0.errors);
        // the plant's mean friction over ticks 100..200 (its impulse after
        // tick 199 less that after tick 99, over 0.1 s)
        assert_measures(status.errors[0], (run[199].1 - run[99].1) / 0.1);
        assert_eq!(status.errors[0], status.errors[2]);
        // the fallback, the plant's map on the measured velocity, predicts
        // it far better than no compensation
        assert!(status.errors[1] < 1e-3 * status.errors[2], "{status:?}");
    }

    #[test]
    fn a_skipped_tick_restarts_the_window() {
        let run = simulate(&measuring_servo(), |_| 1.0, 500, &[150]);
        // the window of ticks 100..150 is cut at the gap; the window that
        // restarts at tick 151 closes at 251, not measured; the next, of
        // ticks 251..351, closes at 351 (blended at 354, counted at 357)
        assert_eq!(run[149].0.windows, 0);
        assert_eq!(run[353].0.errors, [0.0; 3]);
        assert_eq!(run[356].0.windows, 0);
        let status = run[357].0;
        assert_eq!(status.windows, 1);
        assert_measures(status.errors[2], (run[350].1 - run[250].1) / 0.1);
    }

    #[test]
    fn settings_are_checked() {
        let bad = |p: SupervisorParams, e: ParamError| {
            let r = p.build::<f64, _, _>(crate::NoCompensation, map(0.28), &servo());
            assert_eq!(r.err(), Some(e));
        };
        let d = SupervisorParams::DEFAULT;
        bad(
            SupervisorParams { window: 0.0, ..d },
            ParamError::NotPositive("window"),
        );
        bad(
            SupervisorParams { memory: 0.5, ..d },
            ParamError::BelowOne("memory"),
        );
        bad(
            SupervisorParams { ratio: 1.5, ..d },
            ParamError::NotBelow {
                name: "ratio",
                limit: "1",
            },
        );
        bad(
            SupervisorParams {
                warm_up: f64::NAN,
                ..d
            },
            ParamError::NotFinite("warm_up"),
        );
        // six ticks at 1 kHz: the close would not end before the next
        bad(
            SupervisorParams { window: 6e-3, ..d },
            ParamError::OutOfRange("window"),
        );
        assert!(SupervisorParams { window: 7e-3, ..d }
            .build::<f64, _, _>(crate::NoCompensation, map(0.28), &servo())
            .is_ok());
    }

    #[cfg(feature = "fixed")]
    #[test]
    fn a_fixed_point_window_holds_its_sum_of_commands() {
        let d = SupervisorParams::DEFAULT;
        // in Q16.16 a window's sum of commands stays below 32,768: 10 s of
        // commands up to 10 do not fit, 3 s do
        let fixed = |window: f64| {
            let map = CoulombViscousParams {
                fc: 0.28,
                sigma2: 0.0176,
            }
            .build::<crate::Fixed32>()
            .unwrap();
            SupervisorParams { window, ..d }
                .build::<crate::Fixed32, _, _>(crate::NoCompensation, map, &servo())
                .err()
        };
        assert_eq!(fixed(10.0), Some(ParamError::OutOfRange("window")));
        assert_eq!(fixed(3.0), None);
    }

    #[test]
    fn a_windows_error_is_squared_within_its_bound() {
        assert_eq!(bounded_square(3.0f32), 9.0);
        assert_eq!(bounded_square(-3.0f64), 9.0);
        // just under the bound, as it is
        assert_eq!(bounded_square(1e14f32), 1e14f32 * 1e14f32);
        assert_eq!(bounded_square(-9.9e14f64), 9.9e14 * 9.9e14);
        // past the bound, and every non-finite error, is the worst evidence
        for x in [
            1e16f32,
            -1e16,
            f32::MAX,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ] {
            assert_eq!(bounded_square(x), 1e30, "{x}");
        }
        for x in [1e16f64, f64::INFINITY, f64::NAN] {
            assert_eq!(bounded_square(x), 1e30, "{x}");
        }
    }

    #[cfg(feature = "fixed")]
    #[test]
    fn a_fixed_point_windows_error_saturates_its_square() {
        // in Q16.16 the bound is the largest value and the product
        // saturates to it: the worst evidence, as in floating point
        use crate::Fixed32;
        let x = Fixed32::from_f64(3.0);
        assert_eq!(bounded_square(x), Fixed32::from_f64(9.0));
        assert_eq!(
            bounded_square(Fixed32::from_f64(181.0)),
            Fixed32::from_f64(32761.0)
        );
        let largest = Fixed32::from_f64(1e30);
        for x in [200.0, -200.0, 1e30, -1e30] {
            assert_eq!(bounded_square(Fixed32::from_f64(x)), largest, "{x}");
        }
    }

    /// The per-parameter adaptive law of the tests: Olsson's model, its
    /// default box factor 5, rate 16 1/s, speed the reference's peak
    /// (0.5 pi rad/s).
    fn adaptive_law() -> crate::ParameterAdaptiveParams {
        crate::ParameterAdaptiveParams {
            speed: 0.5 * core::f64::consts::PI,
            rate: 16.0,
            ..crate::ParameterAdaptiveParams::new(crate::LuGreParams::OLSSON_1998, 20.0)
        }
    }

    /// The supervised per-parameter adaptive servo in `S`, its fallback the
    /// map of Coulomb level `fallback`.
    fn adaptive_servo<S: Scalar>(fallback: f64) -> crate::ParameterAdaptiveServo<S> {
        let adaptive = adaptive_law().build_fixed_step::<S>(&servo()).unwrap();
        let map = CoulombViscousParams {
            fc: fallback,
            sigma2: 0.0176,
        }
        .build::<S>()
        .unwrap();
        let sup = SupervisorParams::DEFAULT
            .build::<S, _, _>(adaptive, map, &servo())
            .unwrap();
        servo().build(sup).unwrap()
    }

    /// [`simulate`]'s plant (friction `scale(t) F_cv(v)`) under any
    /// compensator `ctl` from state `s` for `ticks` ticks: the tracking
    /// error `x - x_ref` after each tick; `each` sees the tick's index and
    /// the state after it.
    fn track<C: Compensation<f64>>(
        ctl: &crate::Compensator<f64, C>,
        s: &mut CompensatorState<f64, C::State>,
        scale: impl Fn(f64) -> f64,
        ticks: usize,
        mut each: impl FnMut(usize, &CompensatorState<f64, C::State>),
    ) -> std::vec::Vec<f64> {
        let (mut x, mut v) = (0.0f64, 0.0f64);
        let w = 2.0 * core::f64::consts::PI * 0.5;
        let mut out = std::vec::Vec::with_capacity(ticks);
        for k in 0..ticks {
            let t = k as f64 * 1e-3;
            let r = Setpoint {
                x: 0.5 * libm::sin(w * t),
                v: 0.5 * w * libm::cos(w * t),
                a: -0.5 * w * w * libm::sin(w * t),
            };
            let u = ctl.tick(s, x, r).command;
            for _ in 0..100 {
                let f = scale(t) * (0.28 * libm::tanh(v / 1e-3) + 0.0176 * v);
                v += 1e-5 * (1.02 * u - f) / 0.0023;
                x += 1e-5 * v;
            }
            out.push(x - r.x);
            each(k, s);
        }
        out
    }

    fn rms(x: &[f64]) -> f64 {
        libm::sqrt(x.iter().map(|e| e * e).sum::<f64>() / x.len() as f64)
    }

    /// 1e6 ticks of the supervised per-parameter adaptive servo on hostile
    /// finite positions and setpoints of every size up to the scalar's
    /// largest, with a hostile external torque every 97 ticks: the command
    /// finite and within the limit, the friction estimate, the elastic
    /// force, every error and tracking figure finite, every estimate in its
    /// box.
    fn supervised_bounds_hold<S: Scalar>(max: f64, ticks: usize) {
        let ctl = adaptive_servo::<S>(0.28);
        let boxes = adaptive_law().boxes();
        let limit = servo().limit;
        let mut s = CompensatorState::default();
        let mut pick = crate::test_rng::hostile(21, max);
        for k in 0..ticks {
            if k % 97 == 0 {
                ctl.set_external_torque(&mut s, S::from_f64(pick()));
            }
            let r = Setpoint {
                x: S::from_f64(pick()),
                v: S::from_f64(pick()),
                a: S::from_f64(pick()),
            };
            let t = ctl.tick(&mut s, S::from_f64(pick()), r);
            assert!(t.accepted, "{k}");
            assert!(
                t.command.is_finite() && t.command.to_f64().abs() <= limit,
                "{k}: {:?}",
                t.command
            );
            assert!(t.friction.is_finite(), "{k}");
            let sup = ctl.compensation();
            let status = sup.status(s.friction());
            assert!(
                status
                    .errors
                    .iter()
                    .chain(&status.tracking)
                    .all(|e| e.is_finite()),
                "{k}: {status:?}"
            );
            let primary = sup.primary();
            let state = &s.friction().primary;
            assert!(primary.elastic_force(state).is_finite(), "{k}");
            for (x, (lo, hi)) in primary.estimates(state).iter().zip(boxes) {
                let x = x.to_f64();
                assert!(
                    x.is_finite() && x >= lo * 0.9999 && x <= hi * 1.0001,
                    "{k}: {x} not in [{lo}, {hi}]"
                );
            }
        }
    }

    /// [`supervised_bounds_hold`] over 1e6 ticks in `f64` and in `f32`.
    #[test]
    fn hostile_finite_inputs_keep_the_supervised_adaptive_servo_in_its_bounds() {
        supervised_bounds_hold::<f64>(f64::MAX, 1_000_000);
        supervised_bounds_hold::<f32>(f64::from(f32::MAX), 1_000_000);
    }

    /// A NaN or infinite position or setpoint, mid-window past the warm-up,
    /// gives the safe output (all zero, not accepted) and leaves the state
    /// as it was but for what [`Compensation::skipped`] restarts: the
    /// window's sums, its count and its measuring flag; the primary's
    /// estimates and bristle, the mode, the errors, the tracking and the
    /// closed window's pending evidence are untouched, as are the integral
    /// and the last position. A NaN or infinite external torque changes
    /// nothing at all.
    #[test]
    fn non_finite_inputs_leave_the_supervised_adaptive_servo_as_it_was() {
        let ctl = adaptive_servo::<f64>(0.28);
        let mut s = CompensatorState::default();
        // 2.55 s: 25 windows closed, half-way through the next
        track(&ctl, &mut s, |_| 1.0, 2_550, |_, _| {});
        let before = s;
        let state = before.friction();
        let status = ctl.compensation().status(state);
        assert!(status.windows > 20, "{status:?}");
        assert!(status.tracking[status.mode.index()] > 0.0, "{status:?}");
        assert!(state.count > 0 && state.measuring.get(), "{state:?}");
        assert_ne!(state.sums, [0.0; 3]);
        let r = Setpoint {
            x: 0.1,
            v: 0.2,
            a: 0.0,
        };
        let nan = f64::NAN;
        let inf = f64::INFINITY;
        for (x, r) in [
            (nan, r),
            (inf, r),
            (-inf, r),
            (0.1, Setpoint { x: nan, ..r }),
            (0.1, Setpoint { v: -inf, ..r }),
            (0.1, Setpoint { a: nan, ..r }),
            (
                nan,
                Setpoint {
                    x: nan,
                    v: nan,
                    a: inf,
                },
            ),
        ] {
            let t = ctl.tick(&mut s, x, r);
            assert_eq!(t, crate::CompensatorTick::default(), "{x} {r:?}");
        }
        let expected = SupervisedState {
            sums: [0.0; 3],
            count: 0,
            measuring: Flag::new(false),
            ..*state
        };
        assert_eq!(*s.friction(), expected);
        assert_eq!(s.friction().primary, state.primary);
        assert_eq!(ctl.compensation().status(s.friction()), status);
        assert_eq!(s.integral(), before.integral());
        assert_eq!(s.last_position(), before.last_position());
        // a non-finite external torque is ignored: nothing changes
        let gap = s;
        for torque in [nan, inf, -inf] {
            ctl.set_external_torque(&mut s, torque);
            assert_eq!(s, gap, "{torque}");
        }
    }

    /// The real per-parameter adaptive law as the primary, on a plant built
    /// to mislead it: for 30 s its friction is `-0.5` times the map, pushing
    /// along the motion, so the adaptation runs every level to its box's
    /// low end and the unsupervised adaptive servo tracks worse than no
    /// compensation over 2-30 s; the supervisor leaves the primary within
    /// 2 s (for no compensation) and tracks as no compensation does. Then
    /// the plant's friction is the ordinary map again: the primary is
    /// back within 5 s and stays, and tracks as the unsupervised adaptive
    /// servo does over 50-60 s (the figures: the changelog).
    #[test]
    fn falls_back_from_a_misled_adaptive_primary_and_returns_when_the_plant_is_ordinary() {
        let scale = |t: f64| if t < 30.0 { -0.5 } else { 1.0 };
        let ticks = 60_000;
        let adaptive = adaptive_law().build_fixed_step::<f64>(&servo()).unwrap();
        let none = servo().build(crate::NoCompensation).unwrap();
        let unsupervised = servo().build(adaptive).unwrap();
        let ctl = adaptive_servo::<f64>(0.14);
        let e_none = track(
            &none,
            &mut CompensatorState::default(),
            scale,
            ticks,
            |_, _| {},
        );
        let mut misled = [0.0; 5];
        let e_unsupervised = track(
            &unsupervised,
            &mut CompensatorState::default(),
            scale,
            ticks,
            |k, s| {
                if k == 29_999 {
                    misled = adaptive.estimates(s.friction());
                }
            },
        );
        let mut modes = std::vec::Vec::with_capacity(ticks);
        let e_supervised = track(
            &ctl,
            &mut CompensatorState::default(),
            scale,
            ticks,
            |_, s| modes.push(ctl.compensation().status(s.friction()).mode),
        );
        let [low, ..] = adaptive_law().boxes();
        // misled: both Coulomb levels near the box's low end
        assert!(
            misled[0] < 1.05 * low.0 && misled[1] < 1.05 * low.0,
            "{misled:?}"
        );
        let misled_phase = |e: &[f64]| rms(&e[2_000..30_000]);
        let ordinary_phase = |e: &[f64]| rms(&e[50_000..]);
        let (none_rms, unsupervised_rms, supervised_rms) = (
            misled_phase(&e_none),
            misled_phase(&e_unsupervised),
            misled_phase(&e_supervised),
        );
        // the unsupervised adaptation is clearly worse than nothing
        assert!(
            unsupervised_rms > 1.15 * none_rms,
            "{unsupervised_rms} vs {none_rms}"
        );
        // the supervisor leaves it within 2 s and stays out until the flip
        let left = modes.iter().position(|m| *m != SupervisorMode::Primary);
        assert!(left.is_some_and(|k| k < 2_000), "{left:?}");
        assert!(
            modes[2_000..30_000]
                .iter()
                .all(|m| *m != SupervisorMode::Primary),
            "{left:?}"
        );
        assert!(
            supervised_rms <= 1.01 * none_rms,
            "{supervised_rms} vs {none_rms}"
        );
        // back to the primary within 5 s of the flip, for good
        let back = modes[30_000..]
            .iter()
            .position(|m| *m == SupervisorMode::Primary);
        assert!(back.is_some_and(|k| k < 5_000), "{back:?}");
        assert!(
            modes[35_000..]
                .iter()
                .all(|m| *m == SupervisorMode::Primary),
            "{:?}",
            modes[35_000..]
                .iter()
                .find(|m| **m != SupervisorMode::Primary)
        );
        let (none_rms, unsupervised_rms, supervised_rms) = (
            ordinary_phase(&e_none),
            ordinary_phase(&e_unsupervised),
            ordinary_phase(&e_supervised),
        );
        assert!(
            supervised_rms <= 1.01 * unsupervised_rms && supervised_rms < 0.5 * none_rms,
            "{supervised_rms} vs {unsupervised_rms}, none {none_rms}"
        );
    }
}
