"""Dynamic friction models (LuGre, GMS, ...) for simulation, observation and
compensation: the Rust library `friction` from Python, on numpy arrays.

Every call runs the same code as the `friction` command line: `load` reads a
parameter file as `friction simulate` does, `Model.simulate` gives the `f`
column of `friction simulate`, `servo` the lines of `friction servo`,
`identify` the fit of `friction identify`.
"""

from os import PathLike
from typing import Literal, Optional, Union

import numpy as np
import numpy.typing as npt

__version__: str

ArrayLike = npt.ArrayLike
Scalar = Literal["f64", "f32", "fixed"]

class Model:
    """A friction model with its parameters, as the command line reads it."""

    def __init__(self, name: str, **params: Union[float, int, bool, str, list, dict]) -> None:
        """Builds a model from the keys of a parameter file.

        `name` is the file's `model` (`"lugre"`, `"gms"`, ...); element tables
        are lists of dicts (`elements=[{"k": 2e4, "alpha": 0.4, "sigma1": 0.05}, ...]`).
        Raises ValueError naming the parameter when one is invalid.
        """
    @property
    def name(self) -> str:
        """The model's name in parameter files."""
    @property
    def observable(self) -> bool:
        """Whether the model has an observer (every model with a state)."""
    def simulate(self, t: npt.NDArray[np.float64], v: npt.NDArray[np.float64], scalar: Scalar = "f64") -> npt.NDArray[np.float64]:
        """The friction force at each time `t[k]`, the model stepped from
        `t[k-1]` with `v[k]` held (row 0: at rest). `scalar="fixed"` runs the
        Q16.16 fixed-step form (uniform `t`). Raises ValueError on
        mismatched lengths or a bad time step."""
    def observer(self, gain: float, h: float, damping: bool = True) -> "Observer":
        """The model's observer (correction gain in 1/s) at period `h` (s)."""
    def compensator(
        self,
        h: float,
        kp: float,
        kd: float,
        inertia: float,
        ki: float = 0.0,
        torque_constant: float = 1.0,
        limit: float = 1e3,
        gain: float = 200.0,
        adaptive: Optional[dict] = None,
        velocity_filter: Optional[float] = None,
        parameter_adaptive: Union[bool, dict, None] = None,
        supervisor: Union[bool, dict, None] = None,
        velocity_observer: Optional[float] = None,
    ) -> "Compensator":
        """The compensated servo tick around the model's observer (or the
        theta-adaptive observer when `adaptive` is a dict of its parameters,
        or the per-parameter adaptive observer under its supervisor when
        `parameter_adaptive` is True or a dict of its settings, among them
        `exact_step`, True for the exact step `friction servo` takes, and
        `stiffness_rate` (1/s, default 0: off; `friction servo` takes a
        tenth of the rate) and `stiffness_box` for the stiffness law; a
        `supervisor` dict sets the supervisor, False turns it off).
        `velocity_observer` (Hz, below half of 1/h, not with
        `velocity_filter`) estimates the velocity with an observer driven
        by the command and the friction estimate instead of the backward
        difference, for an encoder that moves less than one count per
        period."""

class Observer:
    """A model's observer at a fixed period: positions in, friction estimate out."""

    def run(self, x: npt.NDArray[np.float64], x_ref: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        """The estimate at each sample from measured and reference positions
        (the state carries over calls)."""

class Compensator:
    """A compensated servo axis: PID, acceleration feed-forward, friction estimate."""

    def tick(self, x: float, x_ref: float, v_ref: float = 0.0, a_ref: float = 0.0) -> tuple[float, float]:
        """One control period: returns (command, friction estimate)."""
    def run(
        self,
        x: npt.NDArray[np.float64],
        x_ref: npt.NDArray[np.float64],
        v_ref: npt.NDArray[np.float64],
        a_ref: npt.NDArray[np.float64],
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """One tick per recorded sample (open loop): (commands, frictions)."""
    def set_external_torque(self, torque: float) -> None:
        """The external torque on the axis that a per-parameter law's load
        input reads as `torque_constant * u - torque` from the next tick on
        (the load's torque less any torque fed beside this axis's command);
        ValueError if not finite."""
    def adapted(self) -> dict[str, float]:
        """The adapted quantities after the last tick (`theta` when adaptive;
        `fc_pos`, `fc_neg`, `stribeck`, `sigma2`, `load`, the `stiffness`
        factor and, supervised, the `mode` code for the per-parameter law)."""
    @property
    def mode(self) -> Optional[str]:
        """The supervisor's mode after the last tick: "primary", "fallback"
        or "off"; None without a supervisor."""

Phase = Literal["breakaway", "presliding", "plateaus", "done", "aborted"]
AbortReason = Literal["travel", "timeout", "stall", "no_breakaway", "reversed_sign", "non_finite"]

class Commissioning:
    """The core's commissioning routine for a notebook's own plant: break-away
    ramps, a presliding reversal and velocity plateaus through the loop's
    PID, then a LuGre fit."""

    def __init__(
        self,
        h: float,
        kp: float,
        kd: float,
        inertia: float,
        travel: float,
        max_speed: float,
        ki: float = 0.0,
        torque_constant: float = 1.0,
        limit: float = 1e3,
        scalar: Literal["f64", "f32"] = "f64",
        **settings: float,
    ) -> None:
        """The routine for the loop (`h`, gains, inertia, torque constant,
        command limit), a travel window and a top speed. `settings` override
        the defaults: duration, min_speed, speeds, plateau, settle,
        acceleration, ramp_rate, breakaway_travel, resolution. ValueError
        naming an invalid setting, TypeError for an unknown one."""
    def tick(self, x: float) -> float:
        """One period with measured position `x`: the command (within the
        limit; 0 once done or aborted; a NaN `x` aborts)."""
    @property
    def phase(self) -> Phase:
        """Where the routine is."""
    @property
    def abort(self) -> Optional[AbortReason]:
        """Why it stopped; None unless aborted."""
    @property
    def ticks(self) -> int:
        """Periods run so far."""
    def plateau_points(self) -> list[tuple[float, float, bool]]:
        """(speed, force, steady) of every plateau measured so far."""
    def result(self) -> dict:
        """The fit of a finished run: "model" (a lugre Model), fc, fs, vs,
        stribeck_exponent, sigma0, sigma1, sigma2, the levels per direction
        (fc_pos, fc_neg, fs_pos, fs_neg, sigma2_pos, sigma2_neg,
        breakaway_pos, breakaway_neg), "identified" (dict of bools:
        coulomb, stribeck, viscous, stiffness, damping), "residual",
        "speed_range" and "plateaus". RuntimeError with the reason when the
        run gives none (not finished, aborted, too few plateaus, poor fit)."""

def load(path: Union[str, PathLike]) -> Model:
    """A parameter file exactly as the command line reads it (ValueError
    with the file, line and key when it is invalid)."""

def servo(path: Optional[Union[str, PathLike]] = None) -> dict[str, dict[str, Union[float, bool]]]:
    """The compensation benchmark of `friction servo` (the built-in
    olsson1998-servo set by default): for each compensation its RMS and
    maximum tracking error (rad) and whether the loop stayed stable."""

def identify(
    t: npt.NDArray[np.float64],
    x: npt.NDArray[np.float64],
    force: npt.NDArray[np.float64],
    model: Literal["coulomb", "coulomb-viscous", "stribeck", "lugre"] = "lugre",
    inertia: bool = True,
    cutoff: Optional[float] = None,
    order: int = 4,
    decimate: Optional[int] = None,
    stribeck_exponent: float = 2.0,
) -> dict[str, tuple[float, float]]:
    """Fits a model to a measured trajectory, the pipeline of `friction
    identify`: {parameter: (value, standard deviation)}. ValueError on bad
    input, RuntimeError when the fit's checks reject it."""
