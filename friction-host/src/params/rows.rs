//! Keys whose value is a list of fixed-length rows of numbers, such as
//! `[servo] friction_drift = [[t, scale], ...]` and `ripple`, or one such
//! row (`gravity = [T, x0]`). Serde reads `[f64; N]`
//! from a row's first `N` elements and ignores the rest (`[1, 2.0,
//! "junk"]` passed as `[1, 2]`), so each row is read whole here and one of
//! another length, or with an element that is not a number, is refused
//! naming the key and the row (the TOML reader adds the line and column).

use serde::de::{Deserialize, Deserializer, Error};

/// One row of exactly `N` numbers; `what` names it in messages (`` `key`
/// point 2``, `` `key` ``), `shape` its elements (`[t, scale]`).
fn row<E: Error, const N: usize>(
    value: &toml::Value,
    what: &str,
    shape: &str,
) -> Result<[f64; N], E> {
    let refuse =
        |problem: String| E::custom(format!("{what}: {problem}; each is {shape}, {N} numbers"));
    let toml::Value::Array(cells) = value else {
        return Err(refuse(format!("{} is not a list", value.type_str())));
    };
    if cells.len() != N {
        return Err(refuse(format!("{} elements", cells.len())));
    }
    let mut parsed = [0.0; N];
    for (k, (cell, slot)) in cells.iter().zip(parsed.iter_mut()).enumerate() {
        *slot = match cell {
            toml::Value::Float(x) => *x,
            toml::Value::Integer(x) => *x as f64,
            other => {
                return Err(refuse(format!(
                    "element {} is a {}, not a number",
                    k + 1,
                    other.type_str()
                )))
            }
        };
    }
    Ok(parsed)
}

/// Reads `key`'s rows of exactly `N` numbers; `shape` names their elements
/// in messages (`[t, scale]`).
fn rows<'de, D: Deserializer<'de>, const N: usize>(
    d: D,
    key: &str,
    shape: &str,
) -> Result<Vec<[f64; N]>, D::Error> {
    let values = Vec::<toml::Value>::deserialize(d)?;
    values
        .iter()
        .enumerate()
        .map(|(i, value)| row(value, &format!("`{key}` point {}", i + 1), shape))
        .collect()
}

/// `[servo] gravity`: one row `[T, x0]`.
pub fn gravity<'de, D: Deserializer<'de>>(d: D) -> Result<Option<[f64; 2]>, D::Error> {
    let value = toml::Value::deserialize(d)?;
    row(&value, "`gravity`", "[T, x0]").map(Some)
}

/// `[servo] gravity_feedforward`: one row `[T, x0]`.
pub fn gravity_feedforward<'de, D: Deserializer<'de>>(d: D) -> Result<Option<[f64; 2]>, D::Error> {
    let value = toml::Value::deserialize(d)?;
    row(&value, "`gravity_feedforward`", "[T, x0]").map(Some)
}

/// `[servo] ripple`: rows `[amplitude, cycles_per_rad]`.
pub fn ripple<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Vec<[f64; 2]>>, D::Error> {
    rows(d, "ripple", "[amplitude, cycles_per_rad]").map(Some)
}

/// `[servo] friction_drift`: points `[t, scale]`.
pub fn friction_drift<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Vec<[f64; 2]>>, D::Error> {
    rows(d, "friction_drift", "[t, scale]").map(Some)
}

#[cfg(test)]
mod tests {
    use crate::params::ParamFile;

    fn error(servo: &str) -> String {
        let text = format!("model = \"coulomb\"\nfc = 1\n[servo]\n{servo}\n");
        format!("{:#}", ParamFile::parse(&text, "p.toml").unwrap_err())
    }

    #[test]
    fn malformed_rows_are_refused_by_key_and_row() {
        let e = error("friction_drift = [[0, 1.0, 999], [1, 2.0, \"junk\"]]");
        assert!(e.contains("`friction_drift` point 1: 3 elements"), "{e}");
        let e = error("friction_drift = [[0, 1.0], [1, \"junk\"]]");
        assert!(
            e.contains("`friction_drift` point 2: element 2 is a string, not a number"),
            "{e}"
        );
        let e = error("ripple = [[0.1, 4.0], [0.2, 8.0, 1]]");
        assert!(e.contains("`ripple` point 2: 3 elements"), "{e}");
        let e = error("gravity = [0.5, 0.1, 7]");
        assert!(e.contains("`gravity`: 3 elements"), "{e}");
        let e = error("gravity = [0.5, \"up\"]");
        assert!(e.contains("`gravity`: element 2 is a string"), "{e}");
        let e = error("gravity_feedforward = [0.5]");
        assert!(e.contains("`gravity_feedforward`: 1 elements"), "{e}");
        let e = error("friction_drift = [[0, 1.0], [1]]");
        assert!(e.contains("point 2: 1 elements"), "{e}");
        let e = error("friction_drift = [[0, 1.0], 3]");
        assert!(e.contains("point 2: integer is not a list"), "{e}");
        assert!(e.contains("line 4"), "{e}");
        let text = "model = \"coulomb\"\nfc = 1\n[servo]\nfriction_drift = [[0, 1], [2.5, 1.5]]\n";
        let f = ParamFile::parse(text, "p.toml").unwrap();
        assert_eq!(f.servo.friction_drift, Some(vec![[0.0, 1.0], [2.5, 1.5]]));
        let f = ParamFile::parse("model = \"coulomb\"\nfc = 1\n[servo]\n", "p.toml").unwrap();
        assert_eq!(f.servo.friction_drift, None);
        assert_eq!((f.servo.ripple, f.servo.gravity), (None, None));
        let text =
            "model = \"coulomb\"\nfc = 1\n[servo]\nripple = [[0.1, 4]]\ngravity = [0.5, 0]\n";
        let f = ParamFile::parse(text, "p.toml").unwrap();
        assert_eq!(f.servo.ripple, Some(vec![[0.1, 4.0]]));
        assert_eq!(f.servo.gravity, Some([0.5, 0.0]));
    }
}
