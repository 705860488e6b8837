use super::*;
use crate::model::{FrictionModel, ParamError};
use crate::stribeck::tests::canudas;

#[test]
fn maps_oppose_motion() {
    let m = StribeckMapParams {
        curve: canudas(),
        sigma2: 0.4,
    }
    .build::<f32>()
    .unwrap();
    for v in [-1.0f32, -1e-4, 1e-6, 0.3] {
        assert_eq!(m.step(&mut (), v, 1e-3).sign(), v.sign());
    }
    assert_eq!(m.step(&mut (), f32::NAN, 1e-3), 0.0);
    let c = CoulombViscousParams {
        fc: 1.0,
        sigma2: 2.0,
    }
    .build::<f64>()
    .unwrap();
    assert_eq!(c.force(-0.5), -2.0);
}

#[test]
fn asymmetric_map_takes_each_sides_levels() {
    let p = AsymmetricCoulombViscousParams {
        fc_pos: 1.2,
        sigma2_pos: 0.5,
        fc_neg: 0.8,
        sigma2_neg: 0.25,
    };
    let m = p.build::<f64>().unwrap();
    assert_eq!(m.force(2.0), 1.2 + 0.5 * 2.0);
    assert_eq!(m.force(-2.0), -0.8 - 0.25 * 2.0);
    assert_eq!(m.force(0.0), 0.0);
    // a vanishing velocity keeps its side's Coulomb level
    assert_eq!(m.force(1e-12), 1.2 + 0.5 * 1e-12);
    assert_eq!(m.force(-1e-12), -0.8 - 0.25 * 1e-12);
    assert_eq!(m.step(&mut (), f64::NAN, 1e-3), 0.0);
    assert_eq!(m.step(&mut (), 1.0, -1.0), 0.0);
    // equal sides are the symmetric map
    let sym = CoulombViscousParams {
        fc: 0.8,
        sigma2: 0.25,
    }
    .build::<f32>()
    .unwrap();
    let same = AsymmetricCoulombViscousParams {
        fc_pos: 0.8,
        sigma2_pos: 0.25,
        ..p
    }
    .build::<f32>()
    .unwrap();
    for v in [-3.0f32, -1e-3, 0.0, 1e-3, 3.0] {
        assert_eq!(same.force(v), sym.force(v), "v = {v}");
    }
}

#[test]
fn asymmetric_map_names_the_invalid_side() {
    let p = AsymmetricCoulombViscousParams {
        fc_pos: 1.0,
        sigma2_pos: 0.1,
        fc_neg: 1.0,
        sigma2_neg: 0.1,
    };
    let err = |q: AsymmetricCoulombViscousParams| q.build::<f32>().unwrap_err();
    assert_eq!(
        err(AsymmetricCoulombViscousParams { fc_neg: 0.0, ..p }),
        ParamError::NotPositive("fc_neg")
    );
    assert_eq!(
        err(AsymmetricCoulombViscousParams {
            fc_pos: f64::NAN,
            ..p
        }),
        ParamError::NotFinite("fc_pos")
    );
    assert_eq!(
        err(AsymmetricCoulombViscousParams {
            sigma2_neg: -1.0,
            ..p
        }),
        ParamError::Negative("sigma2_neg")
    );
    assert_eq!(
        err(AsymmetricCoulombViscousParams {
            sigma2_pos: 1e40,
            ..p
        }),
        ParamError::OutOfRange("sigma2_pos")
    );
    assert!(p.build::<f32>().is_ok());
}

#[test]
fn karnopp_switches_on_the_band() {
    let map = StribeckMapParams {
        curve: canudas(),
        sigma2: 0.0,
    }
    .build::<f64>()
    .unwrap();
    let k = Karnopp::new(map, 1e-4).unwrap();
    assert_eq!(k.force(5e-5, -0.7), -0.7);
    assert_eq!(k.force(2e-4, -0.7), map.force(2e-4));
    assert_eq!(k.force(f64::NAN, 1.0), 0.0);
    assert_eq!(Karnopp::new(map, 0.0), Err(ParamError::NotPositive("dv")));
}
