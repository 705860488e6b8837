//! Friction that grows with the torque a transmission carries, in the forms
//! identified for real servo actuators by BAM (Duclusaud, Passault et al.
//! 2024, "Extended Friction Models for the Physics Simulation of Servo
//! Actuators", arXiv:2410.08650): the models `m1` to `m6`: see
//! [`LoadFriction`].

use crate::model::{non_negative, positive, ParamError};
use crate::Scalar;

/// Which of BAM's forms a parameter set is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LoadForm {
    /// Coulomb and viscous.
    M1,
    /// + Stribeck.
    M2,
    /// + load-dependent (no Stribeck).
    M3,
    /// Stribeck and load-dependent.
    M4,
    /// Stribeck, directional load dependence.
    M5,
    /// `M5` with the quadratic terms.
    M6,
}

impl LoadForm {
    /// The form called `m1` .. `m6`.
    pub fn named(name: &str) -> Option<Self> {
        Some(match name {
            "m1" => Self::M1,
            "m2" => Self::M2,
            "m3" => Self::M3,
            "m4" => Self::M4,
            "m5" => Self::M5,
            "m6" => Self::M6,
            _ => return None,
        })
    }

    fn stribeck(self) -> bool {
        !matches!(self, Self::M1 | Self::M3)
    }
}

/// A BAM friction budget's parameters (torques in N m at the joint,
/// speeds in rad/s); the terms a form does not use are ignored (0 is fine).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LoadFrictionParams {
    /// The form.
    pub form: LoadForm,
    /// `friction_base` `Fb >= 0`.
    pub friction_base: f64,
    /// `friction_stribeck` `Fs >= 0`.
    pub friction_stribeck: f64,
    /// `friction_viscous` `Fv >= 0`.
    pub friction_viscous: f64,
    /// `dtheta_stribeck` `vs > 0`.
    pub dtheta_stribeck: f64,
    /// `alpha > 0`.
    pub alpha: f64,
    /// `load_friction_base` `kb >= 0` (m3, m4).
    pub load_friction_base: f64,
    /// `load_friction_stribeck` `ks >= 0` (m4).
    pub load_friction_stribeck: f64,
    /// `load_friction_motor` `km >= 0` (m5, m6).
    pub load_friction_motor: f64,
    /// `load_friction_external` `ke >= 0` (m5, m6).
    pub load_friction_external: f64,
    /// `load_friction_motor_stribeck` `kms >= 0` (m5, m6).
    pub load_friction_motor_stribeck: f64,
    /// `load_friction_external_stribeck` `kes >= 0` (m5, m6).
    pub load_friction_external_stribeck: f64,
    /// `load_friction_motor_quad` `qm >= 0` (m6).
    pub load_friction_motor_quad: f64,
    /// `load_friction_external_quad` `qe >= 0` (m6).
    pub load_friction_external_quad: f64,
}

impl LoadFrictionParams {
    /// Every coefficient 0, `vs = 1`, `alpha = 1`, of form `form`.
    pub const fn zero(form: LoadForm) -> Self {
        Self {
            form,
            friction_base: 0.0,
            friction_stribeck: 0.0,
            friction_viscous: 0.0,
            dtheta_stribeck: 1.0,
            alpha: 1.0,
            load_friction_base: 0.0,
            load_friction_stribeck: 0.0,
            load_friction_motor: 0.0,
            load_friction_external: 0.0,
            load_friction_motor_stribeck: 0.0,
            load_friction_external_stribeck: 0.0,
            load_friction_motor_quad: 0.0,
            load_friction_external_quad: 0.0,
        }
    }

    /// Checks every coefficient finite and `>= 0`, `vs` and `alpha` `> 0`;
    /// the error names it as BAM's files spell it.
    pub fn validate(&self) -> Result<(), ParamError> {
        for (name, x) in [
            ("friction_base", self.friction_base),
            ("friction_stribeck", self.friction_stribeck),
            ("friction_viscous", self.friction_viscous),
            ("load_friction_base", self.load_friction_base),
            ("load_friction_stribeck", self.load_friction_stribeck),
            ("load_friction_motor", self.load_friction_motor),
            ("load_friction_external", self.load_friction_external),
            (
                "load_friction_motor_stribeck",
                self.load_friction_motor_stribeck,
            ),
            (
                "load_friction_external_stribeck",
                self.load_friction_external_stribeck,
            ),
            ("load_friction_motor_quad", self.load_friction_motor_quad),
            (
                "load_friction_external_quad",
                self.load_friction_external_quad,
            ),
        ] {
            non_negative(name, x)?;
        }
        positive("dtheta_stribeck", self.dtheta_stribeck)?;
        positive("alpha", self.alpha)?;
        Ok(())
    }

    /// The budget at rest without load: `Fb + Fs` (with Stribeck), the
    /// break-away torque of the unloaded joint.
    pub fn breakaway(&self) -> f64 {
        self.friction_base
            + if self.form.stribeck() {
                self.friction_stribeck
            } else {
                0.0
            }
    }

    /// Validates and builds the run-time form. A coefficient, `alpha` or
    /// `1 / dtheta_stribeck` the scalar cannot hold is refused
    /// (`NotRepresentable`, named); one below its resolution rounds (to 0
    /// in Q16.16 below 1.5e-5: a term that small is no friction).
    pub fn build<S: Scalar>(&self) -> Result<LoadFriction<S>, ParamError> {
        self.validate()?;
        let f = |name: &'static str, x: f64| match S::try_from_f64(x) {
            Err(crate::scalar::ScalarConversion::Overflow) => {
                Err(ParamError::NotRepresentable(name))
            }
            _ if !x.is_finite() => Err(ParamError::NotRepresentable(name)),
            _ => Ok(S::from_f64(x)),
        };
        Ok(LoadFriction {
            form: self.form,
            base: f("friction_base", self.friction_base)?,
            stribeck: f("friction_stribeck", self.friction_stribeck)?,
            viscous: f("friction_viscous", self.friction_viscous)?,
            inv_vs: f("dtheta_stribeck", 1.0 / self.dtheta_stribeck)?,
            alpha: f("alpha", self.alpha)?,
            k: [
                f("load_friction_base", self.load_friction_base)?,
                f("load_friction_stribeck", self.load_friction_stribeck)?,
                f("load_friction_motor", self.load_friction_motor)?,
                f("load_friction_external", self.load_friction_external)?,
                f(
                    "load_friction_motor_stribeck",
                    self.load_friction_motor_stribeck,
                )?,
                f(
                    "load_friction_external_stribeck",
                    self.load_friction_external_stribeck,
                )?,
                f("load_friction_motor_quad", self.load_friction_motor_quad)?,
                f(
                    "load_friction_external_quad",
                    self.load_friction_external_quad,
                )?,
            ],
            params: *self,
        })
    }
}

/// The built budget.
///
/// Friction that grows with the torque a transmission carries, in the forms
/// identified for real servo actuators by BAM (Duclusaud, Passault et al.
/// 2024, "Extended Friction Models for the Physics Simulation of Servo
/// Actuators", arXiv:2410.08650): the models `m1` to `m6`.
///
/// Each is a friction **budget** `tau_fm >= 0`, the largest torque the
/// friction can oppose at joint speed `v`, motor torque `tau_m` and
/// external torque `tau_e` (gravity, a load):
///
/// ```text
/// s      = exp(-|v / vs|^alpha)                                   Stribeck factor
/// m1     tau_fm = Fb                          (+ the viscous Fv |v| in every form)
/// m2     + Fs s
/// m3     + kb |tau_e - tau_m|                                      load-dependent
/// m4     + Fs s + ks s |tau_e - tau_m|
/// m5     + |ke tau_e - km tau_m| + s |kes tau_e - kms tau_m| + Fs s   directional
/// m6     m5 + s (qe tau_e^2 [|tau_e| < |tau_m|] + qm tau_m^2 [|tau_e| > |tau_m|])
///           where tau_e and tau_m have opposite signs                 quadratic
/// ```
///
/// (`Fb` friction_base, `Fs` friction_stribeck, `Fv` friction_viscous, `vs`
/// dtheta_stribeck, `kb`/`ks` load_friction_base/_stribeck, `km`/`ke` and
/// `kms`/`kes` load_friction_motor/_external and their `_stribeck`, `qm`/`qe`
/// load_friction_motor_quad/_external_quad.) The viscous part
/// `Fv |v|` is returned apart ([`LoadFriction::budget`] gives both): a
/// simulator applies it as a damping force and the rest as a bounded
/// sticking force.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LoadFriction<S> {
    form: LoadForm,
    base: S,
    stribeck: S,
    viscous: S,
    inv_vs: S,
    alpha: S,
    /// `[kb, ks, km, ke, kms, kes, qm, qe]`.
    k: [S; 8],
    params: LoadFrictionParams,
}

impl<S: Scalar> LoadFriction<S> {
    /// The parameters it was built from.
    pub fn params(&self) -> &LoadFrictionParams {
        &self.params
    }

    /// `(sticking budget, viscous coefficient)` at speed `v`, motor torque
    /// `tau_m` and external torque `tau_e`: the friction is `Fv v` plus a
    /// force bounded by the sticking budget (BAM's `frictionloss`). Non-finite
    /// inputs count as 0.
    pub fn budget(&self, v: S, tau_m: S, tau_e: S) -> (S, S) {
        let finite = |x: S| if x.is_finite() { x } else { S::ZERO };
        let (v, tm, te) = (finite(v), finite(tau_m), finite(tau_e));
        let [kb, ks, km, ke, kms, kes, qm, qe] = self.k;
        let s = if self.form.stribeck() {
            (-(v * self.inv_vs).abs().powf(self.alpha)).exp()
        } else {
            S::ZERO
        };
        let mut b = self.base + self.stribeck * s;
        match self.form {
            LoadForm::M1 | LoadForm::M2 => {}
            LoadForm::M3 | LoadForm::M4 => {
                let load = (te - tm).abs();
                b = b + kb * load + ks * s * load;
            }
            LoadForm::M5 | LoadForm::M6 => {
                b = b + (ke * te - km * tm).abs() + s * (kes * te - kms * tm).abs();
                let opposed = (te > S::ZERO && tm < S::ZERO) || (te < S::ZERO && tm > S::ZERO);
                if self.form == LoadForm::M6 && opposed {
                    let (ae, am) = (te.abs(), tm.abs());
                    if ae < am {
                        b = b + s * qe * ae * ae;
                    } else if ae > am {
                        b = b + s * qm * am * am;
                    }
                }
            }
        }
        (b, self.viscous)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Every coefficient non-zero and distinct (the hand-computed cases').
    pub(crate) fn m6() -> LoadFrictionParams {
        LoadFrictionParams {
            friction_base: 0.1,
            friction_stribeck: 0.2,
            friction_viscous: 0.3,
            dtheta_stribeck: 2.0,
            alpha: 2.0,
            load_friction_motor: 0.05,
            load_friction_external: 0.02,
            load_friction_motor_stribeck: 0.04,
            load_friction_external_stribeck: 0.01,
            load_friction_motor_quad: 0.003,
            load_friction_external_quad: 0.007,
            load_friction_base: 0.11,
            load_friction_stribeck: 0.13,
            ..LoadFrictionParams::zero(LoadForm::M6)
        }
    }

    /// Each form against its budget computed by hand at `v = 1`
    /// (`s = e^-0.25 = 0.778800783`), `tau_m = 3`, `tau_e = -2`.
    #[test]
    fn budgets_match_hand_computed_values() {
        let s = 0.778_800_783_071_404_9_f64;
        let (tm, te) = (3.0, -2.0);
        let cases = [
            (LoadForm::M1, 0.1),
            (LoadForm::M2, 0.1 + 0.2 * s),
            // |te - tm| = 5
            (LoadForm::M3, 0.1 + 0.11 * 5.0),
            (LoadForm::M4, 0.1 + 0.2 * s + 0.11 * 5.0 + 0.13 * s * 5.0),
            // |0.02 (-2) - 0.05 (3)| = 0.19, |0.01 (-2) - 0.04 (3)| = 0.14
            (LoadForm::M5, 0.1 + 0.2 * s + 0.19 + s * 0.14),
            // opposite signs, |te| < |tm|: + s qe te^2 = s 0.007 4
            (
                LoadForm::M6,
                0.1 + 0.2 * s + 0.19 + s * 0.14 + s * 0.007 * 4.0,
            ),
        ];
        for (form, expected) in cases {
            let f = LoadFrictionParams { form, ..m6() }.build::<f64>().unwrap();
            let (b, viscous) = f.budget(1.0, tm, te);
            assert!((b - expected).abs() < 1e-12, "{form:?}: {b} vs {expected}");
            assert_eq!(viscous, 0.3);
            // symmetric in the speed's sign
            assert_eq!(f.budget(-1.0, tm, te).0, b);
        }
        // m6: the motor's quadratic term when the external torque is larger,
        // none when the torques share a sign
        let f = m6().build::<f64>().unwrap();
        let (b, _) = f.budget(1.0, 1.0, -4.0);
        // |0.02 (-4) - 0.05| = 0.13, |0.01 (-4) - 0.04| = 0.08, + s qm 1
        let expected = 0.1 + 0.2 * s + 0.13 + s * 0.08 + s * 0.003;
        assert!((b - expected).abs() < 1e-12, "{b} vs {expected}");
        let (b, _) = f.budget(1.0, 1.0, 4.0);
        let expected = 0.1 + 0.2 * s + (0.08f64 - 0.05).abs() + s * (0.04f64 - 0.04).abs();
        assert!((b - expected).abs() < 1e-12, "{b} vs {expected}");
        // f32 agrees
        let f32_form = m6().build::<f32>().unwrap();
        let (b32, _) = f32_form.budget(1.0, 3.0, -2.0);
        let (b64, _) = f.budget(1.0, 3.0, -2.0);
        assert!((f64::from(b32) - b64).abs() < 1e-6);
    }

    #[test]
    fn invalid_coefficients_are_named() {
        let bad = LoadFrictionParams {
            load_friction_motor: -1.0,
            ..m6()
        };
        assert_eq!(
            bad.validate(),
            Err(ParamError::Negative("load_friction_motor"))
        );
        let bad = LoadFrictionParams {
            dtheta_stribeck: 0.0,
            ..m6()
        };
        assert_eq!(
            bad.validate(),
            Err(ParamError::NotPositive("dtheta_stribeck"))
        );
        // a coefficient or 1 / dtheta_stribeck the scalar cannot hold is
        // refused (it turned the budget into NaN), even one the form
        // does not use
        let unused = LoadFrictionParams {
            friction_stribeck: 1e39,
            ..LoadFrictionParams {
                form: LoadForm::M1,
                ..m6()
            }
        };
        assert_eq!(
            unused.build::<f32>().err(),
            Some(ParamError::NotRepresentable("friction_stribeck"))
        );
        let narrow = LoadFrictionParams {
            dtheta_stribeck: 1e-310,
            ..m6()
        };
        assert_eq!(
            narrow.build::<f64>().err(),
            Some(ParamError::NotRepresentable("dtheta_stribeck"))
        );
        let f = LoadFrictionParams {
            dtheta_stribeck: 1e-300,
            ..m6()
        }
        .build::<f64>()
        .unwrap();
        assert!(f.budget(0.0, 1.0, -1.0).0.is_finite());
        // non-finite inputs count as 0
        let f = m6().build::<f64>().unwrap();
        assert_eq!(
            f.budget(f64::NAN, f64::INFINITY, 0.0),
            f.budget(0.0, 0.0, 0.0)
        );
    }
}
