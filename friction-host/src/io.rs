//! CSV input and output.

use anyhow::{bail, Context, Result};
use std::path::Path;

/// Writes equal-length columns with a header row.
pub fn write_columns(path: &Path, headers: &[&str], columns: &[&[f64]]) -> Result<()> {
    let mut w =
        csv::Writer::from_path(path).with_context(|| format!("cannot write {}", path.display()))?;
    w.write_record(headers)?;
    let n = columns.iter().map(|c| c.len()).min().unwrap_or(0);
    for k in 0..n {
        w.write_record(columns.iter().map(|c| format!("{:.12e}", c[k])))?;
    }
    w.flush()?;
    Ok(())
}

/// Reads the `t` and `v` columns of a CSV file with a header. Errors name
/// the file, the line and the column.
pub fn read_tv(path: &Path) -> Result<(Vec<f64>, Vec<f64>)> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    parse_tv(&text, &path.display().to_string())
}

/// Parses `t,v` CSV text; see [`read_tv`].
pub fn parse_tv(text: &str, origin: &str) -> Result<(Vec<f64>, Vec<f64>)> {
    let mut r = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let headers = r
        .headers()
        .with_context(|| format!("{origin}: cannot read the header"))?
        .clone();
    let col = |name: &str| headers.iter().position(|h| h == name);
    let (Some(it), Some(iv)) = (col("t"), col("v")) else {
        bail!(
            "{origin}:1: the header must name columns `t` and `v` (found: {})",
            headers.iter().collect::<Vec<_>>().join(",")
        );
    };
    let (mut t, mut v) = (Vec::new(), Vec::new());
    for rec in r.records() {
        let rec = rec.map_err(|e| {
            let line = e.position().map_or(0, |p| p.line());
            anyhow::anyhow!("{origin}:{line}: {e}")
        })?;
        let line = rec.position().map_or(0, |p| p.line());
        let field = |i: usize, name: &str| -> Result<f64> {
            let s = rec.get(i).unwrap_or("");
            let x: f64 = s.parse().map_err(|_| {
                anyhow::anyhow!(
                    "{origin}:{line}: column {} (`{name}`): `{s}` is not a number",
                    i + 1
                )
            })?;
            if !x.is_finite() {
                bail!(
                    "{origin}:{line}: column {} (`{name}`): `{s}` is not finite",
                    i + 1
                );
            }
            Ok(x)
        };
        let (tk, vk) = (field(it, "t")?, field(iv, "v")?);
        if let Some(&prev) = t.last() {
            if tk <= prev {
                bail!("{origin}:{line}: column {} (`t`): time {tk} does not increase (previous {prev})", it + 1);
            }
        }
        t.push(tk);
        v.push(vk);
    }
    if t.is_empty() {
        bail!("{origin}: no data rows");
    }
    Ok((t, v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_names_bad_lines() {
        let (t, v) = parse_tv("t,v\n0,0\n0.001, 0.5\n", "in.csv").unwrap();
        assert_eq!(t, vec![0.0, 0.001]);
        assert_eq!(v, vec![0.0, 0.5]);
        let e = parse_tv("t,v\n0,0\n0.001,abc\n", "in.csv")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("in.csv:3: column 2 (`v`)"), "{e}");
        let e = parse_tv("t,v\n0,0\n0,1\n", "in.csv")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("in.csv:3") && e.contains("does not increase"),
            "{e}"
        );
        let e = parse_tv("time,v\n0,0\n", "in.csv").unwrap_err().to_string();
        assert!(e.contains("in.csv:1"), "{e}");
        let e = parse_tv("t,v\n0,0\n1\n", "in.csv").unwrap_err().to_string();
        assert!(e.contains("in.csv:3"), "{e}");
        let e = parse_tv("t,v\n0,NaN\n", "in.csv").unwrap_err().to_string();
        assert!(e.contains("not finite"), "{e}");
    }
}
