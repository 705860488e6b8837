//! The unit tests' servo loop (tests only): Olsson et al. 1998's DC servo
//! at 1 kHz (`J = 0.0023`, `kc = 1.02`, PID 60 / 200 / 1.2, limit 10).

use crate::CompensatorParams;

/// Olsson et al. 1998's loop, as `friction servo`'s defaults.
pub(crate) fn olsson_servo() -> CompensatorParams {
    CompensatorParams {
        h: 1e-3,
        kp: 60.0,
        ki: 200.0,
        kd: 1.2,
        inertia: 0.0023,
        torque_constant: 1.02,
        limit: 10.0,
    }
}
