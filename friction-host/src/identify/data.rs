//! Reading a measured trajectory: named columns of a delimited text file
//! (comma, tab or semicolon, detected from the header line).

use anyhow::{bail, Context, Result};
use std::path::Path;

/// The named columns of a file, in the order they were asked for.
#[derive(Clone, Debug)]
pub struct Columns {
    /// The values, one vector per requested name.
    pub data: Vec<Vec<f64>>,
}

fn delimiter(header: &str) -> u8 {
    [b',', b'\t', b';']
        .into_iter()
        .max_by_key(|d| header.bytes().filter(|b| b == d).count())
        .unwrap_or(b',')
}

/// Reads the columns `names` of the file at `path`; see [`parse_columns`].
pub fn read_columns(path: &Path, names: &[&str]) -> Result<Columns> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    parse_columns(&text, &path.display().to_string(), names)
}

/// Parses delimited text with a header row and returns the columns `names`.
/// Errors name the file, the line and the column: a missing column (with
/// the header's names), a field that is not a finite number, a short row.
pub fn parse_columns(text: &str, origin: &str, names: &[&str]) -> Result<Columns> {
    let first = text.lines().next().unwrap_or("");
    let mut r = csv::ReaderBuilder::new()
        .delimiter(delimiter(first))
        .trim(csv::Trim::All)
        .flexible(true)
        .from_reader(text.as_bytes());
    let headers = r
        .headers()
        .with_context(|| format!("{origin}: cannot read the header"))?
        .clone();
    crate::io::check_header(&headers, origin)?;
    let mut index = Vec::with_capacity(names.len());
    for name in names {
        match headers.iter().position(|h| h == *name) {
            Some(i) => index.push(i),
            None => bail!(
                "{origin}:1: no column `{name}` (the header names: {})",
                headers
                    .iter()
                    .map(|h| format!("`{h}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        }
    }
    let mut data = vec![Vec::new(); names.len()];
    for rec in r.records() {
        let rec = rec.map_err(|e| {
            let line = e.position().map_or(0, |p| p.line());
            anyhow::anyhow!("{origin}:{line}: {e}")
        })?;
        let line = rec.position().map_or(0, |p| p.line());
        for ((&i, name), col) in index.iter().zip(names).zip(data.iter_mut()) {
            let Some(s) = rec.get(i) else {
                bail!(
                    "{origin}:{line}: the row has {} fields, column {} (`{name}`) is missing",
                    rec.len(),
                    i + 1
                );
            };
            col.push(crate::io::parse_cell(s, origin, line, i, name)?);
        }
    }
    Ok(Columns { data })
}

/// Checks that `t` increases strictly; the error names the data line
/// (header = line 1).
pub fn check_time(t: &[f64], origin: &str, name: &str) -> Result<()> {
    for k in 1..t.len() {
        crate::checks::increasing(Some(t[k - 1]), t[k])
            .map_err(|e| anyhow::anyhow!("{origin}:{}: column `{name}`: {e}", k + 2))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_comma_and_tab_files_by_name() {
        let c = parse_columns("t,x,f\n0,1,2\n1,3,4\n", "a.csv", &["f", "t"]).unwrap();
        assert_eq!(c.data, vec![vec![2.0, 4.0], vec![0.0, 1.0]]);
        let c = parse_columns(
            "Time [s]\tFriction [uN]\n0\t1.5\n0.005\t-2\n",
            "b.txt",
            &["Friction [uN]"],
        )
        .unwrap();
        assert_eq!(c.data, vec![vec![1.5, -2.0]]);
    }

    #[test]
    fn errors_name_file_line_and_column() {
        let e = parse_columns("t,x\n0,1\n", "a.csv", &["t", "f"])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("a.csv:1: no column `f`") && e.contains("`x`"),
            "{e}"
        );
        let e = parse_columns("t,x\n0,1\n1,a\n", "a.csv", &["t", "x"])
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("a.csv:3: column 2 (`x`)"), "{e}");
        let e = parse_columns("t,x\n0,1\n1\n", "a.csv", &["t", "x"])
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("a.csv:3:"), "{e}");
        let e = check_time(&[0.0, 1.0, 1.0], "a.csv", "t")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("a.csv:4: column `t`"), "{e}");
    }
}
