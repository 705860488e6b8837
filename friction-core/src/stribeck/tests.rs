use super::*;
use crate::CoulombParams;

/// The curve of Canudas de Wit et al. (1995), shared with the maps' tests.
pub(crate) fn canudas() -> StribeckParams {
    StribeckParams {
        fc: 1.0,
        fs: 1.5,
        vs: 1e-3,
        exponent: 2.0,
    }
}

#[test]
fn curve_values() {
    let g = canudas().build::<f64>().unwrap();
    assert_eq!(g.eval(0.0), 1.5);
    assert!((g.eval(1e-3) - (1.0 + 0.5 * (-1.0f64).exp())).abs() < 1e-15);
    assert_eq!(g.eval(-1e-3), g.eval(1e-3));
    // general and special exponents agree
    let g1 = StribeckParams {
        exponent: 1.0,
        ..canudas()
    }
    .build::<f64>()
    .unwrap();
    let g1p = StribeckParams {
        exponent: 1.0 + 1e-15,
        ..canudas()
    }
    .build::<f64>()
    .unwrap();
    assert!((g1.eval(2e-3) - g1p.eval(2e-3)).abs() < 1e-12);
    let g3 = StribeckParams {
        exponent: 3.0,
        ..canudas()
    }
    .build::<f64>()
    .unwrap();
    assert!((g3.eval(2e-3) - (1.0 + 0.5 * (-8.0f64).exp())).abs() < 1e-14);
}

#[test]
fn invalid_curves_are_rejected() {
    assert_eq!(
        StribeckParams {
            fs: 0.5,
            ..canudas()
        }
        .validate(),
        Err(ParamError::StaticBelowCoulomb)
    );
    assert_eq!(
        StribeckParams {
            vs: -1.0,
            ..canudas()
        }
        .validate(),
        Err(ParamError::NotPositive("vs"))
    );
    assert_eq!(
        StribeckParams {
            exponent: f64::INFINITY,
            ..canudas()
        }
        .validate(),
        Err(ParamError::NotFinite("stribeck_exponent"))
    );
    assert_eq!(
        CoulombParams { fc: 0.0 }.build::<f32>(),
        Err(ParamError::NotPositive("fc"))
    );
}
