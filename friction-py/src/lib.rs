//! The Python package `friction`: the host's models (as the command line
//! reads them), `simulate`, observers, compensators, the servo benchmark
//! and identification, on numpy arrays. Every call is the same code as the
//! `friction` command line: `Model.simulate` steps through
//! `friction_host::sim::Simulation`, `servo` runs `servo::benchmark`,
//! `identify` runs `identify::identify`.

use friction_core::{
    AdaptiveParams, CompensatorParams, ParameterAdaptive, ParameterAdaptiveParams,
    ParameterAdaptiveState, Setpoint, Supervised, SupervisedState, SupervisorMode,
    SupervisorParams,
};
use friction_host::checks::{self, Refusal, SignalError};
use friction_host::control::{controller_reading, Controller, Loop, ObserverRequest};
use friction_host::identify as fit;
use friction_host::params::ParamFile;
use friction_host::sim::{PeriodRefused, SimScalar, Simulation};
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::exceptions::{PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString};
use std::path::PathBuf;

/// A Python `ValueError` carrying an error's whole chain; an argument the
/// shared checks refused is named as Python spells it (`order=17`), not as
/// the command line does.
fn value_error(e: anyhow::Error) -> PyErr {
    match e.chain().find_map(|c| c.downcast_ref::<Refusal>()) {
        Some(r) => PyValueError::new_err(r.python()),
        None => PyValueError::new_err(format!("{e:#}")),
    }
}

/// A signal refused by the shared checks, as a `ValueError` naming the
/// array and the index.
fn signal_error(e: SignalError) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// Whether a parameter file's reader refused an unknown key (serde's
/// `deny_unknown_fields` message, the only typed trace it leaves): in
/// Python an unknown keyword argument, a `TypeError`.
fn is_unknown_key(e: &anyhow::Error) -> bool {
    e.chain().any(|c| c.to_string().contains("unknown field `"))
}

/// A Python value as TOML: numbers, booleans, strings, lists and dicts
/// (element tables are lists of dicts).
fn toml_value(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    if obj.is_instance_of::<PyBool>() {
        Ok(toml::Value::Boolean(obj.extract()?))
    } else if obj.is_instance_of::<PyInt>() {
        match obj.extract::<i64>() {
            Ok(i) => Ok(toml::Value::Integer(i)),
            Err(_) => Ok(toml::Value::Float(obj.extract()?)),
        }
    } else if obj.is_instance_of::<PyFloat>() {
        Ok(toml::Value::Float(obj.extract()?))
    } else if obj.is_instance_of::<PyString>() {
        Ok(toml::Value::String(obj.extract()?))
    } else if let Ok(list) = obj.downcast::<PyList>() {
        list.iter()
            .map(|x| toml_value(name, &x))
            .collect::<PyResult<Vec<_>>>()
            .map(toml::Value::Array)
    } else if let Ok(dict) = obj.downcast::<PyDict>() {
        Ok(toml::Value::Table(toml_table(dict)?))
    } else if let Ok(x) = obj.extract::<f64>() {
        // numpy scalars and anything else with __float__
        Ok(toml::Value::Float(x))
    } else {
        Err(PyValueError::new_err(format!(
            "parameter `{name}`: expected a number, string, list or dict, got {}",
            obj.get_type().name()?
        )))
    }
}

fn toml_table(dict: &Bound<'_, PyDict>) -> PyResult<toml::Table> {
    let mut table = toml::Table::new();
    for (k, v) in dict.iter() {
        let key: String = k.extract()?;
        let value = toml_value(&key, &v)?;
        table.insert(key, value);
    }
    Ok(table)
}

/// A friction model with its parameters (and the file's `[rig]`,
/// `[plant]` and `[servo]` tables), as the `friction` command line reads it.
#[pyclass(module = "friction", frozen)]
struct Model {
    file: ParamFile,
    origin: String,
}

/// A numpy array's values (copied once; non-contiguous arrays too).
fn array(a: &PyReadonlyArray1<'_, f64>) -> Vec<f64> {
    a.as_slice()
        .map_or_else(|_| a.as_array().to_vec(), <[f64]>::to_vec)
}

#[pymethods]
impl Model {
    /// Model(name, **params): builds a model from keywords, the keys of a
    /// parameter file (`fc`, `fs`, `vs`, `stribeck_exponent`, `sigma0`, ...;
    /// `elements=[{"k": ..., "alpha": ..., "sigma1": ...}, ...]` for GMS and
    /// Xiong). Invalid parameters raise ValueError naming the parameter.
    #[new]
    #[pyo3(signature = (name, **params))]
    fn new(name: &str, params: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut table = match params {
            Some(p) => toml_table(p)?,
            None => toml::Table::new(),
        };
        let origin = format!("Model({name:?})");
        // the model is the first argument; a `model` keyword would silently
        // replace it (as a file cannot name its model twice)
        if table.contains_key("model") {
            return Err(PyTypeError::new_err(format!(
                "{origin}: unexpected keyword argument `model` (the model is the first argument)"
            )));
        }
        table.insert("model".into(), toml::Value::String(name.into()));
        let text = toml::to_string(&table).map_err(|e| PyValueError::new_err(e.to_string()))?;
        let file = ParamFile::parse(&text, &origin).map_err(|e| {
            if is_unknown_key(&e) {
                PyTypeError::new_err(format!("{e:#}"))
            } else {
                value_error(e)
            }
        })?;
        Ok(Self { file, origin })
    }

    /// The model's name in parameter files (`lugre`, `gms`, ...).
    #[getter]
    fn name(&self) -> &'static str {
        self.file.model.name()
    }

    /// Whether the model has an observer (every model with a state).
    #[getter]
    fn observable(&self) -> bool {
        self.file.model.host().has_state()
    }

    fn __repr__(&self) -> String {
        format!("<friction.Model {} from {}>", self.name(), self.origin)
    }

    /// simulate(t, v, scalar="f64") -> numpy array of forces.
    ///
    /// Row k steps the model from t[k-1] to t[k] with v[k] held; row 0 is
    /// the force at rest; velocities beyond the limit are clamped. The same
    /// numbers as the `f` column of `friction simulate` on the same input.
    /// `scalar`: "f64", "f32" or "fixed" (Q16.16 fixed-step form, uniform t).
    #[pyo3(signature = (t, v, scalar = "f64"))]
    fn simulate<'py>(
        &self,
        py: Python<'py>,
        t: PyReadonlyArray1<'py, f64>,
        v: PyReadonlyArray1<'py, f64>,
        scalar: &str,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        // contiguous arrays are read in place, others copied once
        let (t, v) = (t.as_array(), v.as_array());
        // the command line's checks of its CSV rows, by array index
        checks::same_length(&[("t", t.len()), ("v", v.len())]).map_err(signal_error)?;
        checks::time_signal("t", t.iter()).map_err(signal_error)?;
        checks::finite_signal("v", v.iter()).map_err(signal_error)?;
        let kind = match scalar {
            "f64" => SimScalar::F64,
            "f32" => SimScalar::F32,
            "fixed" => SimScalar::Fixed,
            other => {
                return Err(PyValueError::new_err(format!(
                    "scalar={other:?}: one of \"f64\", \"f32\", \"fixed\""
                )))
            }
        };
        let period = match (kind, t.get(1), t.first()) {
            (SimScalar::Fixed, Some(t1), Some(t0)) => Some(t1 - t0),
            _ => None,
        };
        let mut sim = Simulation::new(&self.file.model, kind, period).map_err(|e| {
            if e.is::<PeriodRefused>() {
                PyValueError::new_err(format!("`t`[1]: {e}"))
            } else {
                value_error(e)
            }
        })?;
        let mut f = Vec::with_capacity(t.len());
        for (k, (&tk, &vk)) in t.iter().zip(v.iter()).enumerate() {
            let (_, force) = sim
                .row(tk, vk)
                .map_err(|e| PyValueError::new_err(format!("`t`[{k}]: {e:#}")))?;
            f.push(force);
        }
        Ok(f.into_pyarray(py))
    }

    /// observer(gain, h, damping=True) -> Observer: the model's observer
    /// (correction gain `gain` in 1/s) run at period `h` from measured
    /// positions, as in a drive.
    #[pyo3(signature = (gain, h, damping = true))]
    fn observer(&self, gain: f64, h: f64, damping: bool) -> PyResult<Observer> {
        // the compensator with every loop gain zero leaves the estimate alone
        let setup = Loop {
            params: CompensatorParams {
                h,
                kp: 0.0,
                ki: 0.0,
                kd: 0.0,
                inertia: 0.0,
                torque_constant: 1.0,
                limit: 1e15,
            },
            velocity_filter: None,
            velocity_observer: None,
        };
        let axis = self.controller(&setup, gain, damping, None)?;
        Ok(Observer { axis })
    }

    /// compensator(h, kp, kd, inertia, ki=0, torque_constant=1, limit=1e3,
    /// gain=200, adaptive=None, velocity_filter=None, parameter_adaptive=None,
    /// supervisor=None, velocity_observer=None) -> Compensator.
    ///
    /// The servo tick of `friction servo`: PID with acceleration
    /// feed-forward around the model's observer (gain `gain`, 1/s), or the
    /// theta-adaptive observer when `adaptive` is a dict of its parameters
    /// (`gamma`, `gamma_derivative`, `leakage`, `theta0`, `theta_min`,
    /// `theta_max`; missing keys take the defaults), or the per-parameter
    /// adaptive observer (the `adaptive` rows of `friction servo`) when
    /// `parameter_adaptive` is True or a dict of its settings (`rate`,
    /// `derivative_weight`, `leakage`, `box_factor`, `dead_zone`,
    /// `min_speed`, `speed`, `load`, `load_max`, and `exact_step`: True for
    /// the exact step the rows take, False, the core's default, for the
    /// implicit one). The per-parameter observer
    /// runs under its supervisor (fallback: the Coulomb + viscous
    /// feed-forward of the model's levels) unless `supervisor=False`; a dict
    /// sets the supervisor's `window`, `memory`, `ratio`, `warm_up`, `retry`,
    /// `tolerance` (default 1 % of the Coulomb level). `velocity_observer`
    /// (Hz, below half the rate `1/h`; not with `velocity_filter`) estimates
    /// the velocity with an observer driven by the command and the friction
    /// estimate instead of the backward difference: for an encoder that
    /// moves less than one count per period (`friction servo` takes a
    /// twentieth of the rate there by default).
    #[pyo3(signature = (h, kp, kd, inertia, ki = 0.0, torque_constant = 1.0, limit = 1e3, gain = 200.0, adaptive = None, velocity_filter = None, parameter_adaptive = None, supervisor = None, velocity_observer = None))]
    #[allow(clippy::too_many_arguments)]
    fn compensator(
        &self,
        h: f64,
        kp: f64,
        kd: f64,
        inertia: f64,
        ki: f64,
        torque_constant: f64,
        limit: f64,
        gain: f64,
        adaptive: Option<&Bound<'_, PyDict>>,
        velocity_filter: Option<f64>,
        parameter_adaptive: Option<&Bound<'_, PyAny>>,
        supervisor: Option<&Bound<'_, PyAny>>,
        velocity_observer: Option<f64>,
    ) -> PyResult<Compensator> {
        let params = CompensatorParams {
            h,
            kp,
            ki,
            kd,
            inertia,
            torque_constant,
            limit,
        };
        // the loop first (the filter's rule needs a valid rate 1/h), then
        // the filter by the rule the command line's `[servo]` table uses
        params
            .validate()
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        if let Some(cutoff) = velocity_filter {
            if let Some(rule) = checks::velocity_filter_rule(cutoff, 1.0 / h) {
                return Err(PyValueError::new_err(format!(
                    "velocity_filter={}: must be {rule} (1/h = {} Hz; None for no filter)",
                    friction_host::checks::num(cutoff),
                    friction_host::checks::num(1.0 / h)
                )));
            }
        }
        if velocity_observer.is_some() && velocity_filter.is_some() {
            return Err(PyValueError::new_err(
                "velocity_observer: not with velocity_filter (one velocity estimate)",
            ));
        }
        let setup = Loop {
            params,
            velocity_filter,
            velocity_observer,
        };
        let axis = self.axis(&setup, gain, adaptive, parameter_adaptive, supervisor)?;
        Ok(Compensator { axis, setup })
    }
}

impl Model {
    /// The axis `compensator` builds around the loop `setup` (see its
    /// options): what a re-tune builds too.
    fn axis(
        &self,
        setup: &Loop,
        gain: f64,
        adaptive: Option<&Bound<'_, PyDict>>,
        parameter_adaptive: Option<&Bound<'_, PyAny>>,
        supervisor: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Axis> {
        let setup = *setup;
        let parameter = parameter_adaptive
            .map(|p| option_dict("parameter_adaptive", p))
            .transpose()?
            .flatten();
        let supervisor = supervisor
            .map(|p| option_dict("supervisor", p))
            .transpose()?;
        if parameter.is_some() && adaptive.is_some() {
            return Err(PyValueError::new_err(
                "adaptive= and parameter_adaptive= are two laws: give one",
            ));
        }
        if let Some(table) = parameter {
            return self.parameter_controller(&setup, gain, &table, supervisor);
        }
        if supervisor.is_some() {
            return Err(PyValueError::new_err(
                "supervisor= guards the per-parameter law: give parameter_adaptive= too",
            ));
        }
        let adaptive = adaptive.map(adaptive_params).transpose()?;
        self.controller(&setup, gain, true, adaptive)
    }
}

/// `True` (the defaults: an empty table), `False` or `None` (off: `None`),
/// or a dict of numbers.
fn option_dict(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<Option<Vec<(String, f64)>>> {
    if obj.is_none() {
        return Ok(None);
    }
    if obj.is_instance_of::<PyBool>() {
        return Ok(obj.extract::<bool>()?.then(Vec::new));
    }
    let Ok(d) = obj.downcast::<PyDict>() else {
        return Err(PyTypeError::new_err(format!(
            "{name}: expected True, False or a dict, got {}",
            obj.get_type()
                .name()
                .map_or_else(|_| "?".into(), |n| n.to_string())
        )));
    };
    let mut out = Vec::new();
    for (k, v) in d.iter() {
        let key: String = k
            .extract()
            .map_err(|_| PyTypeError::new_err(format!("{name}: keys are strings")))?;
        let x: f64 = v.extract().map_err(|_| {
            PyTypeError::new_err(format!(
                "{name}[{key:?}]: expected a number, got {}",
                v.get_type()
                    .name()
                    .map_or_else(|_| "?".into(), |n| n.to_string())
            ))
        })?;
        out.push((key, x));
    }
    Ok(Some(out))
}

/// The per-parameter adaptation around `model` with observer gain `gain`,
/// from a table of `(key, value)`.
fn parameter_params(
    model: friction_core::LuGreParams,
    gain: f64,
    table: &[(String, f64)],
) -> PyResult<ParameterAdaptiveParams> {
    const KEYS: &str = "rate, derivative_weight, leakage, box_factor, dead_zone, min_speed, \
                        speed, load, load_max, stiffness_rate, stiffness_box, exact_step";
    let mut p = ParameterAdaptiveParams::new(model, gain);
    for (key, x) in table {
        if key == "exact_step" {
            // a flag: 0 (False) or 1 (True), nothing else
            p.exact_step = match *x {
                0.0 => false,
                1.0 => true,
                _ => {
                    return Err(PyValueError::new_err(format!(
                        "parameter_adaptive[\"exact_step\"]: expected True or False, got {x}"
                    )))
                }
            };
            continue;
        }
        let slot = match key.as_str() {
            "rate" => &mut p.rate,
            "derivative_weight" => &mut p.derivative_weight,
            "leakage" => &mut p.leakage,
            "box_factor" => &mut p.box_factor,
            "dead_zone" => &mut p.dead_zone,
            "min_speed" => &mut p.min_speed,
            "speed" => &mut p.speed,
            "load" => &mut p.load,
            "load_max" => &mut p.load_max,
            "stiffness_rate" => &mut p.stiffness_rate,
            "stiffness_box" => &mut p.stiffness_box,
            _ => {
                return Err(PyTypeError::new_err(format!(
                    "parameter_adaptive: unknown key {key:?} (one of {KEYS})"
                )))
            }
        };
        *slot = *x;
    }
    p.validate()
        .map_err(|e| PyValueError::new_err(format!("parameter_adaptive: {e}")))?;
    Ok(p)
}

/// The supervisor from a table of `(key, value)`, its tolerance defaulting
/// to 1 % of the Coulomb level `fc`.
fn supervisor_params(table: &[(String, f64)], fc: f64) -> PyResult<SupervisorParams> {
    const KEYS: &str = "window, memory, ratio, warm_up, retry, tolerance";
    let mut p = SupervisorParams {
        tolerance: 0.01 * fc,
        ..SupervisorParams::DEFAULT
    };
    for (key, x) in table {
        let slot = match key.as_str() {
            "window" => &mut p.window,
            "memory" => &mut p.memory,
            "ratio" => &mut p.ratio,
            "warm_up" => &mut p.warm_up,
            "retry" => &mut p.retry,
            "tolerance" => &mut p.tolerance,
            _ => {
                return Err(PyTypeError::new_err(format!(
                    "supervisor: unknown key {key:?} (one of {KEYS})"
                )))
            }
        };
        *slot = *x;
    }
    p.validate()
        .map_err(|e| PyValueError::new_err(format!("supervisor: {e}")))?;
    Ok(p)
}

/// The per-parameter law's estimates and its stiffness factor, without a
/// supervisor: the host's names less the last, `mode`.
const ESTIMATE_NAMES: &[&str] = match friction_host::servo::PARAMETER_NAMES.split_last() {
    Some((_, estimates)) => estimates,
    None => &[],
};

/// The estimates of a per-parameter state, then its stiffness factor: the
/// nominal values (and 1) before its first tick (a `Default` state reads 0
/// until then).
fn estimates(law: &ParameterAdaptive<f64>, s: &ParameterAdaptiveState<f64>) -> Vec<f64> {
    let s = if *s == ParameterAdaptiveState::default() {
        law.initial()
    } else {
        *s
    };
    let mut v = s.estimates().to_vec();
    v.push(s.stiffness());
    v
}

/// [`estimates`], then the supervisor's mode code.
fn estimates_and_mode(
    law: &ParameterAdaptive<f64>,
    s: &ParameterAdaptiveState<f64>,
    mode: SupervisorMode,
) -> Vec<f64> {
    let mut v = estimates(law, s);
    v.push(f64::from(mode.code()));
    v
}

fn adaptive_params(d: &Bound<'_, PyDict>) -> PyResult<AdaptiveParams> {
    const KEYS: &str = "gamma, gamma_derivative, leakage, theta0, theta_min, theta_max";
    let mut p = AdaptiveParams::DEFAULT;
    let mut theta0_given = false;
    for (k, v) in d.iter() {
        let key: String = k
            .extract()
            .map_err(|_| PyTypeError::new_err(format!("adaptive: keys are strings ({KEYS})")))?;
        let x: f64 = v.extract().map_err(|_| {
            PyTypeError::new_err(format!(
                "adaptive[{key:?}]: expected a number, got {}",
                v.get_type()
                    .name()
                    .map_or_else(|_| "?".into(), |n| n.to_string())
            ))
        })?;
        match key.as_str() {
            "gamma" => p.gamma = x,
            "gamma_derivative" => p.gamma_derivative = x,
            "leakage" => p.leakage = x,
            "theta0" => {
                p.theta0 = x;
                theta0_given = true;
            }
            "theta_min" => p.theta_min = x,
            "theta_max" => p.theta_max = x,
            _ => {
                return Err(PyTypeError::new_err(format!(
                    "adaptive: unknown key {key:?} (one of {KEYS})"
                )))
            }
        }
    }
    // the bounds by the rule the command line's `[servo]` table uses
    checks::theta_bounds(p.theta_min, p.theta_max, p.theta0, theta0_given).map_err(|e| {
        PyValueError::new_err(format!(
            "adaptive[{:?}] = {}: must be {}",
            e.key,
            friction_host::checks::num(e.value),
            e.rule
        ))
    })?;
    Ok(p)
}

type SupervisedLaw = Supervised<ParameterAdaptive<f64>, friction_core::CoulombViscous<f64>, f64>;

impl Model {
    /// The per-parameter adaptive observer on the model's LuGre form (as
    /// the `adaptive` rows of `friction servo` build it), supervised unless
    /// `supervisor` is `Some(None)` (`supervisor=False`).
    fn parameter_controller(
        &self,
        setup: &Loop,
        gain: f64,
        table: &[(String, f64)],
        supervisor: Option<Option<Vec<(String, f64)>>>,
    ) -> PyResult<Axis> {
        let spec = &self.file.model;
        if !spec.host().has_state() {
            return Err(PyValueError::new_err(format!(
                "model `{}` has no observer (it has no state)",
                self.name()
            )));
        }
        let nominal = friction_host::servo::lugre_nominal(spec, 1.0, 1.0);
        let p = parameter_params(nominal, gain, table)?;
        let value = |e: friction_core::ParamError| PyValueError::new_err(e.to_string());
        let law = p.build::<f64>(&setup.params).map_err(value)?;
        let built = match supervisor {
            Some(None) => controller_reading(setup, law, ESTIMATE_NAMES, estimates),
            Some(Some(table)) => self.supervised(setup, law, &table)?,
            None => self.supervised(setup, law, &[])?,
        };
        built
            .map(std::sync::Mutex::new)
            .map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// `law` under its supervisor (settings from `table`), falling back to
    /// the static map of the model's levels.
    fn supervised(
        &self,
        setup: &Loop,
        law: ParameterAdaptive<f64>,
        table: &[(String, f64)],
    ) -> PyResult<Result<Box<dyn Controller>, friction_core::ParamError>> {
        let map = friction_host::servo::static_map(&self.file.model, 1.0);
        let sp = supervisor_params(table, map.fc)?;
        let value = |e: friction_core::ParamError| PyValueError::new_err(e.to_string());
        let fallback = map.build::<f64>().map_err(value)?;
        let supervised: SupervisedLaw = sp.build(law, fallback, &setup.params).map_err(value)?;
        Ok(controller_reading(
            setup,
            supervised,
            &friction_host::servo::PARAMETER_NAMES,
            |c, s: &SupervisedState<ParameterAdaptiveState<f64>, f64>| {
                estimates_and_mode(c.primary(), &s.primary, c.status(s).mode)
            },
        ))
    }

    fn controller(
        &self,
        setup: &Loop,
        gain: f64,
        damping: bool,
        adaptive: Option<AdaptiveParams>,
    ) -> PyResult<std::sync::Mutex<Box<dyn Controller>>> {
        let request = ObserverRequest {
            scale: 1.0,
            stiffness: 1.0,
            gain,
            damping,
            adaptive,
            supervisor: None,
        };
        match self.file.model.host().observer_controller(setup, &request) {
            Some(Ok(c)) => Ok(std::sync::Mutex::new(c)),
            Some(Err(e)) => Err(PyValueError::new_err(e.to_string())),
            None => Err(PyValueError::new_err(format!(
                "model `{}` has no observer (it has no state)",
                self.name()
            ))),
        }
    }
}

type Axis = std::sync::Mutex<Box<dyn Controller>>;

fn lock(axis: &Axis) -> std::sync::MutexGuard<'_, Box<dyn Controller>> {
    axis.lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// A model's observer at a fixed period: positions in, friction estimate out.
#[pyclass(module = "friction")]
struct Observer {
    axis: Axis,
}

#[pymethods]
impl Observer {
    /// run(x, x_ref) -> numpy array: the estimate F^ at each sample from the
    /// measured positions `x` and the references `x_ref` (error e = x - x_ref;
    /// velocity from position differences). The state carries over calls.
    fn run<'py>(
        &self,
        py: Python<'py>,
        x: PyReadonlyArray1<'py, f64>,
        x_ref: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (x, r) = (array(&x), array(&x_ref));
        checks::same_length(&[("x", x.len()), ("x_ref", r.len())]).map_err(signal_error)?;
        let mut axis = lock(&self.axis);
        let out: Vec<f64> = x
            .iter()
            .zip(&r)
            .map(|(&xk, &rk)| {
                axis.tick(
                    xk,
                    Setpoint {
                        x: rk,
                        v: 0.0,
                        a: 0.0,
                    },
                )
                .friction
            })
            .collect();
        Ok(out.into_pyarray(py))
    }
}

/// Two numpy arrays (commands and frictions).
type ArrayPair<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

/// A compensated servo axis: one tick per control period.
#[pyclass(module = "friction")]
struct Compensator {
    axis: Axis,
    /// The loop it was built with: a re-tune builds the new compensation
    /// around it.
    setup: Loop,
}

#[pymethods]
impl Compensator {
    /// tick(x, x_ref, v_ref=0, a_ref=0) -> (command, friction): one period.
    #[pyo3(signature = (x, x_ref, v_ref = 0.0, a_ref = 0.0))]
    fn tick(&self, x: f64, x_ref: f64, v_ref: f64, a_ref: f64) -> (f64, f64) {
        let t = lock(&self.axis).tick(
            x,
            Setpoint {
                x: x_ref,
                v: v_ref,
                a: a_ref,
            },
        );
        (t.command, t.friction)
    }

    /// set_external_torque(torque): the external torque on the axis (force
    /// units) that a per-parameter law's load input reads as
    /// `torque_constant * u - torque` from the next tick on: the load's
    /// torque on the axis (a pendulum's -T sin x) less any torque the drive
    /// adds beside this axis's command (a gravity feed-forward). It holds
    /// until set again; compensations without a load input ignore it. NaN or
    /// infinite: ValueError, the axis unchanged.
    fn set_external_torque(&self, torque: f64) -> PyResult<()> {
        if !torque.is_finite() {
            return Err(PyValueError::new_err(format!(
                "set_external_torque: torque must be finite, not {torque}"
            )));
        }
        lock(&self.axis).set_external_torque(torque);
        Ok(())
    }

    /// run(x, x_ref, v_ref, a_ref) -> (commands, frictions): one tick per
    /// sample of recorded positions (open loop: the commands do not move x).
    fn run<'py>(
        &self,
        py: Python<'py>,
        x: PyReadonlyArray1<'py, f64>,
        x_ref: PyReadonlyArray1<'py, f64>,
        v_ref: PyReadonlyArray1<'py, f64>,
        a_ref: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<ArrayPair<'py>> {
        let (x, r, v, a) = (array(&x), array(&x_ref), array(&v_ref), array(&a_ref));
        checks::same_length(&[
            ("x", x.len()),
            ("x_ref", r.len()),
            ("v_ref", v.len()),
            ("a_ref", a.len()),
        ])
        .map_err(signal_error)?;
        let mut axis = lock(&self.axis);
        let (mut u, mut f) = (Vec::with_capacity(x.len()), Vec::with_capacity(x.len()));
        for k in 0..x.len() {
            let t = axis.tick(
                x[k],
                Setpoint {
                    x: r[k],
                    v: v[k],
                    a: a[k],
                },
            );
            u.push(t.command);
            f.push(t.friction);
        }
        Ok((u.into_pyarray(py), f.into_pyarray(py)))
    }

    /// retune(model, gain=200, adaptive=None, parameter_adaptive=None,
    /// supervisor=None): re-tunes the running axis between two ticks. The
    /// compensation becomes the one `model.compensator(...)` would build with
    /// these options around this axis's loop; it must be of the same kind
    /// (the same model family and law, else ValueError, the axis untouched).
    /// The integral, the last position and the velocity estimate are kept;
    /// the observer keeps the friction force its state holds (LuGre, Dahl;
    /// other models restart at rest); adaptive estimates (`theta`, the
    /// per-parameter levels) restart at the new model's values; a
    /// supervisor keeps its mode and restarts its evidence. So the next
    /// command differs from the old compensation's by at most the change of
    /// the friction estimate over `torque_constant`.
    #[pyo3(signature = (model, gain = 200.0, adaptive = None, parameter_adaptive = None, supervisor = None))]
    fn retune(
        &self,
        model: &Model,
        gain: f64,
        adaptive: Option<&Bound<'_, PyDict>>,
        parameter_adaptive: Option<&Bound<'_, PyAny>>,
        supervisor: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let next = model.axis(&self.setup, gain, adaptive, parameter_adaptive, supervisor)?;
        let next = next
            .into_inner()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        lock(&self.axis)
            .retune(next)
            .map_err(|e| PyValueError::new_err(format!("retune: {e}")))
    }

    /// The supervisor's mode after the last tick: "primary" (the adaptive
    /// observer applied), "fallback" (the static feed-forward) or "off" (no
    /// compensation); None without a supervisor.
    #[getter]
    fn mode(&self) -> Option<&'static str> {
        let axis = lock(&self.axis);
        let at = axis.adapted_names().iter().position(|n| *n == "mode")?;
        match axis.adapted().get(at).copied() {
            Some(0.0) => Some("primary"),
            Some(1.0) => Some("fallback"),
            Some(2.0) => Some("off"),
            _ => None,
        }
    }

    /// The adapted quantities after the last tick (`theta` for the
    /// adaptive observer; `fc_pos`, `fc_neg`, `stribeck`, `sigma2`, `load`
    /// and, supervised, the `mode` code 0 / 1 / 2 for the per-parameter
    /// one), as a dict.
    fn adapted<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let axis = lock(&self.axis);
        let d = PyDict::new(py);
        for (name, value) in axis.adapted_names().iter().zip(axis.adapted()) {
            d.set_item(*name, value)?;
        }
        Ok(d)
    }
}

/// The routine and its state in the scalar the notebook chose.
// one per Python object, built once and never moved in a loop: the f32
// variant's unused 440 bytes cost nothing a box would save
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy)]
enum Routine {
    F64(
        friction_core::Commissioning<f64>,
        friction_core::CommissioningState<f64>,
    ),
    F32(
        friction_core::Commissioning<f32>,
        friction_core::CommissioningState<f32>,
    ),
}

/// Commissioning(h, kp, kd, inertia, travel, max_speed, ki=0,
/// torque_constant=1, limit=1e3, scalar="f64", **settings): the core's
/// commissioning routine (`friction_core::commissioning`) for a notebook's
/// own plant. Each `tick(x)` takes the measured position and returns the
/// command, one call per period `h`, until `phase` is "done" (then
/// `result()` fits the LuGre parameters) or "aborted" (`abort` says why;
/// the command is 0 from then on). `settings` override the defaults of
/// `CommissioningParams::new`: duration, min_speed, speeds, plateau,
/// settle, acceleration, ramp_rate, breakaway_travel, resolution.
/// `scalar="f32"` runs the routine in `float`, as firmware does. Invalid
/// settings raise ValueError naming the setting.
#[pyclass(module = "friction")]
struct Commissioning {
    routine: Routine,
}

/// The phase's name.
fn phase_name(phase: friction_core::CommissioningPhase) -> &'static str {
    use friction_core::CommissioningPhase;
    match phase {
        CommissioningPhase::Breakaway => "breakaway",
        CommissioningPhase::Presliding => "presliding",
        CommissioningPhase::Plateaus => "plateaus",
        CommissioningPhase::Done => "done",
        CommissioningPhase::Aborted => "aborted",
    }
}

/// The abort reason's name.
fn abort_name(abort: friction_core::CommissioningAbort) -> &'static str {
    use friction_core::CommissioningAbort;
    match abort {
        CommissioningAbort::NonFiniteMeasurement => "non_finite",
        CommissioningAbort::Travel => "travel",
        CommissioningAbort::Timeout => "timeout",
        CommissioningAbort::Stall => "stall",
        CommissioningAbort::NoBreakaway => "no_breakaway",
        CommissioningAbort::ReversedSign => "reversed_sign",
    }
}

/// `(speed, force, steady)` of every plateau measured so far.
type Points = Vec<(f64, f64, bool)>;

impl Routine {
    fn phase(&self) -> friction_core::CommissioningPhase {
        match self {
            Self::F64(_, s) => s.phase(),
            Self::F32(_, s) => s.phase(),
        }
    }

    fn abort(&self) -> Option<friction_core::CommissioningAbort> {
        match self {
            Self::F64(_, s) => s.abort(),
            Self::F32(_, s) => s.abort(),
        }
    }

    fn points(&self) -> Points {
        let points = match self {
            Self::F64(c, s) => c.plateau_points(s),
            Self::F32(c, s) => c.plateau_points(s),
        };
        points
            .iter()
            .flatten()
            .map(|p| (p.speed, p.force, p.steady))
            .collect()
    }
}

#[pymethods]
impl Commissioning {
    #[new]
    #[pyo3(signature = (h, kp, kd, inertia, travel, max_speed, ki = 0.0, torque_constant = 1.0, limit = 1e3, scalar = "f64", **settings))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        h: f64,
        kp: f64,
        kd: f64,
        inertia: f64,
        travel: f64,
        max_speed: f64,
        ki: f64,
        torque_constant: f64,
        limit: f64,
        scalar: &str,
        settings: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let servo = CompensatorParams {
            h,
            kp,
            ki,
            kd,
            inertia,
            torque_constant,
            limit,
        };
        let mut p = friction_core::CommissioningParams::new(servo, travel, max_speed);
        for (key, value) in settings.into_iter().flat_map(|d| d.iter()) {
            let key: String = key.extract()?;
            let number = |v: &Bound<'_, PyAny>| -> PyResult<f64> {
                v.extract::<f64>()
                    .map_err(|_| PyValueError::new_err(format!("`{key}`: expected a number")))
            };
            match key.as_str() {
                "duration" => p.duration = number(&value)?,
                "min_speed" => p.min_speed = number(&value)?,
                "plateau" => p.plateau = number(&value)?,
                "settle" => p.settle = number(&value)?,
                "acceleration" => p.acceleration = number(&value)?,
                "ramp_rate" => p.ramp_rate = number(&value)?,
                "breakaway_travel" => p.breakaway_travel = number(&value)?,
                "resolution" => p.resolution = number(&value)?,
                "speeds" => {
                    // a count beyond a byte is out of range as 255 is
                    let n: i64 = value
                        .extract()
                        .map_err(|_| PyValueError::new_err("`speeds`: expected a whole number"))?;
                    p.speeds = u8::try_from(n.clamp(0, 255)).unwrap_or(u8::MAX);
                }
                other => {
                    return Err(PyTypeError::new_err(format!(
                        "Commissioning: unexpected keyword argument `{other}`"
                    )))
                }
            }
        }
        let refused = |e: friction_core::ParamError| PyValueError::new_err(e.to_string());
        let routine = match scalar {
            "f64" => Routine::F64(p.build().map_err(refused)?, Default::default()),
            "f32" => Routine::F32(p.build().map_err(refused)?, Default::default()),
            other => {
                return Err(PyValueError::new_err(format!(
                    "scalar={other:?}: one of \"f64\", \"f32\""
                )))
            }
        };
        Ok(Self { routine })
    }

    /// tick(x) -> command: one period with measured position `x` (a NaN
    /// or infinite `x` aborts the run, as the core does: "non_finite").
    fn tick(&mut self, x: f64) -> f64 {
        match &mut self.routine {
            Routine::F64(c, s) => c.tick(s, x).command,
            // the position as the float firmware would read it
            Routine::F32(c, s) => f64::from(c.tick(s, x as f32).command),
        }
    }

    /// Where the routine is: "breakaway", "presliding", "plateaus", "done"
    /// or "aborted".
    #[getter]
    fn phase(&self) -> &'static str {
        phase_name(self.routine.phase())
    }

    /// Why it stopped ("travel", "timeout", "stall", "no_breakaway",
    /// "reversed_sign", "non_finite"); None unless aborted.
    #[getter]
    fn abort(&self) -> Option<&'static str> {
        self.routine.abort().map(abort_name)
    }

    /// Periods run so far.
    #[getter]
    fn ticks(&self) -> u32 {
        match &self.routine {
            Routine::F64(_, s) => s.ticks(),
            Routine::F32(_, s) => s.ticks(),
        }
    }

    /// plateau_points() -> [(speed, force, steady), ...]: every plateau
    /// measured so far (fastest first, forward first), for a plot of the
    /// friction curve; only steady ones are fitted.
    fn plateau_points(&self) -> Points {
        self.routine.points()
    }

    /// result() -> dict: the fit of a finished run (`Commissioning::result`):
    /// "model" (a `friction.Model("lugre", ...)` for `compensator` or
    /// `Compensator.retune`), its parameters ("fc", "fs", "vs",
    /// "stribeck_exponent", "sigma0", "sigma1", "sigma2"), the levels per
    /// direction ("fc_pos", "fc_neg", "fs_pos", "fs_neg", "sigma2_pos",
    /// "sigma2_neg", "breakaway_pos", "breakaway_neg"), "identified" (a
    /// dict of bools: coulomb, stribeck, viscous, stiffness, damping, load;
    /// the others are documented fallbacks), "load" (the load coefficient,
    /// friction per unit of transmitted torque; 0 where not identified),
    /// "load_torque" (the mean transmitted torque the levels are at),
    /// "residual" (relative RMS of the curve fit), "speed_range" (slowest,
    /// fastest) and "plateaus".
    /// RuntimeError when there is none: not finished, aborted (with the
    /// reason), too few plateaus, a poor fit (with the residual), no
    /// friction.
    fn result<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let r = match &self.routine {
            Routine::F64(c, s) => c.result(s),
            Routine::F32(c, s) => c.result(s),
        };
        let r = r.map_err(|e| {
            use friction_core::CommissionError as E;
            PyRuntimeError::new_err(match e {
                E::NotFinished => "commissioning not finished".to_string(),
                E::Aborted(why) => format!("commissioning aborted: {}", abort_name(why)),
                E::TooFewPlateaus => "too few steady plateaus in a direction".to_string(),
                E::PoorFit(residual) => {
                    format!("poor fit: residual {residual:.3} of the friction (at most 0.1)")
                }
                E::NoFriction => "no positive Coulomb level".to_string(),
                E::Invalid(e) => format!("the fitted model does not build: {e}"),
            })
        })?;
        let m = r.model;
        let out = PyDict::new(py);
        let params = PyDict::new(py);
        for (name, value) in [
            ("fc", m.curve.fc),
            ("fs", m.curve.fs),
            ("vs", m.curve.vs),
            ("stribeck_exponent", m.curve.exponent),
            ("sigma0", m.sigma0),
            ("sigma1", m.sigma1),
            ("sigma2", m.sigma2),
        ] {
            out.set_item(name, value)?;
            params.set_item(name, value)?;
        }
        out.set_item("model", Model::new("lugre", Some(&params))?)?;
        for (name, [pos, neg]) in [
            ("fc", r.fc),
            ("fs", r.fs),
            ("sigma2", r.sigma2),
            ("breakaway", r.breakaway),
        ] {
            out.set_item(format!("{name}_pos"), pos)?;
            out.set_item(format!("{name}_neg"), neg)?;
        }
        let i = r.identified;
        let identified = PyDict::new(py);
        for (name, flag) in [
            ("coulomb", i.coulomb),
            ("stribeck", i.stribeck),
            ("viscous", i.viscous),
            ("stiffness", i.stiffness),
            ("damping", i.damping),
            ("load", i.load),
        ] {
            identified.set_item(name, flag)?;
        }
        out.set_item("identified", identified)?;
        out.set_item("load", r.load)?;
        out.set_item("load_torque", r.load_torque)?;
        out.set_item("residual", r.residual)?;
        out.set_item("speed_range", (r.speed_range[0], r.speed_range[1]))?;
        out.set_item("plateaus", r.plateaus)?;
        Ok(out)
    }

    fn __repr__(&self) -> String {
        format!(
            "<friction.Commissioning {} after {} ticks>",
            self.phase(),
            self.ticks()
        )
    }
}

/// load(path) -> Model: a parameter file exactly as the command line reads it.
#[pyfunction]
fn load(path: PathBuf) -> PyResult<Model> {
    let file = ParamFile::load(&path).map_err(value_error)?;
    Ok(Model {
        file,
        origin: path.display().to_string(),
    })
}

/// servo(path=None) -> dict: the compensation benchmark of `friction servo`
/// (built-in olsson1998-servo set when `path` is None). For each
/// compensation: {"rms": rad, "max": rad, "stable": bool}, the same numbers
/// as the command line's `servo NAME RMS MAX` lines (in mrad there).
#[pyfunction]
#[pyo3(signature = (path = None))]
fn servo<'py>(py: Python<'py>, path: Option<PathBuf>) -> PyResult<Bound<'py, PyDict>> {
    let (file, origin) = match &path {
        Some(p) => (
            ParamFile::load(p).map_err(value_error)?,
            p.display().to_string(),
        ),
        None => (
            friction_host::params::param_set("olsson1998-servo").map_err(value_error)?,
            "params/olsson1998-servo.toml".to_string(),
        ),
    };
    let bench = friction_host::servo::benchmark(&file, &origin).map_err(value_error)?;
    let out = PyDict::new(py);
    for run in &bench.runs {
        let row = PyDict::new(py);
        row.set_item("rms", run.rms)?;
        row.set_item("max", run.max)?;
        row.set_item("stable", run.stable)?;
        out.set_item(run.name, row)?;
    }
    Ok(out)
}

/// identify(t, x, force, model="lugre", inertia=True, cutoff=None,
/// order=4, decimate=None, stribeck_exponent=2.0) -> dict
///
/// Fits `model` ("coulomb", "coulomb-viscous", "stribeck", "lugre") to a
/// measured trajectory (time, position, force), the pipeline of `friction
/// identify`: returns {name: (value, standard deviation)} for every
/// estimated parameter (`mass` and `offset` too when `inertia`). Bad input
/// raises ValueError; a fit the checks reject raises RuntimeError with the
/// reason.
#[pyfunction]
#[pyo3(signature = (t, x, force, model = "lugre", inertia = true, cutoff = None, order = 4, decimate = None, stribeck_exponent = 2.0))]
#[allow(clippy::too_many_arguments)]
fn identify<'py>(
    py: Python<'py>,
    t: PyReadonlyArray1<'py, f64>,
    x: PyReadonlyArray1<'py, f64>,
    force: PyReadonlyArray1<'py, f64>,
    model: &str,
    inertia: bool,
    cutoff: Option<f64>,
    order: i64,
    decimate: Option<i64>,
    stribeck_exponent: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let (t, x, f) = (array(&t), array(&x), array(&force));
    // the command line's checks of its CSV rows, by array index; the
    // options are checked by the pipeline itself (the shared checks)
    checks::same_length(&[("t", t.len()), ("x", x.len()), ("force", f.len())])
        .map_err(signal_error)?;
    checks::time_signal("t", &t).map_err(signal_error)?;
    checks::finite_signal("x", &x).map_err(signal_error)?;
    checks::finite_signal("force", &f).map_err(signal_error)?;
    let order = checks::filter_order(order).map_err(|e| PyValueError::new_err(e.python()))?;
    let decimate = decimate
        .map(checks::decimate)
        .transpose()
        .map_err(|e| PyValueError::new_err(e.python()))?;
    // the outputs (report, plots) go to a folder removed afterwards
    let dir = tempfile::tempdir().map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    let columns = fit::Columns {
        force: "force".into(),
        ..fit::Columns::default()
    };
    let options = fit::Options {
        input: PathBuf::from("identify(t, x, force)"),
        model: model.to_string(),
        output: dir.path().join("out"),
        columns,
        inertia,
        conditioning: fit::Conditioning {
            cutoff,
            order,
            decimate,
        },
        stribeck_exponent,
        lugre_static: Default::default(),
        validate: None,
        progress: false,
    };
    // the columns in the pipeline's order: time, force, position
    let outcome = fit::identify_data(&options, vec![t, f, x]).map_err(value_error)?;
    if let Some(reason) = outcome.rejected {
        return Err(PyRuntimeError::new_err(format!("fit rejected: {reason}")));
    }
    let fit = outcome
        .fit
        .ok_or_else(|| PyRuntimeError::new_err("no fit"))?;
    let out = PyDict::new(py);
    for p in &fit.params {
        out.set_item(p.name, (p.value, p.std))?;
    }
    Ok(out)
}

/// Dynamic friction models for simulation, observation and compensation.
#[pymodule]
fn friction(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Model>()?;
    m.add_class::<Observer>()?;
    m.add_class::<Compensator>()?;
    m.add_class::<Commissioning>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(servo, m)?)?;
    m.add_function(wrap_pyfunction!(identify, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
