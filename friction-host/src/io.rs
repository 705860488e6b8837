//! Files in and out, safely: outputs are written to a temporary file in the
//! same folder and renamed into place only when complete (a failed run
//! leaves the old file or none, never half a file), no output may overwrite
//! an input, and CSV input is read as a stream with errors that name the
//! file, the line and the column.

use anyhow::{bail, Context, Result};
use std::fs::File;
use std::io::{BufWriter, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// Standard output was closed by its reader (`friction servo | head -c1`):
/// later writes are skipped, and the run finishes its files.
static STDOUT_CLOSED: AtomicBool = AtomicBool::new(false);
/// Writing standard output failed otherwise (a full disk): the run's exit
/// code says so ([`stdout_failed`]).
static STDOUT_FAILED: AtomicBool = AtomicBool::new(false);

/// Writes to standard output without ever panicking (`println!` panics on
/// a closed pipe): a reader that stopped reading ends the output quietly,
/// and any other error is reported once on standard error. Used through
/// [`out!`](crate::out) and [`outln!`](crate::outln).
pub fn print(args: std::fmt::Arguments<'_>) {
    if STDOUT_CLOSED.load(Ordering::Relaxed) {
        return;
    }
    if let Err(e) = std::io::stdout().lock().write_fmt(args) {
        STDOUT_CLOSED.store(true, Ordering::Relaxed);
        if e.kind() != std::io::ErrorKind::BrokenPipe {
            STDOUT_FAILED.store(true, Ordering::Relaxed);
            eprintln!("error: cannot write to standard output: {e}");
        }
    }
}

/// Whether writing standard output failed for a reason other than its
/// reader closing it.
pub fn stdout_failed() -> bool {
    STDOUT_FAILED.load(Ordering::Relaxed)
}

/// `print!` that never panics: see [`io::print`](crate::io::print).
#[macro_export]
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::io::print(format_args!($($arg)*))
    };
}

/// `println!` that never panics: see [`io::print`](crate::io::print).
#[macro_export]
macro_rules! outln {
    () => {
        $crate::io::print(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::io::print(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// Writes `path` atomically: `fill` writes into a temporary file next to it,
/// which is flushed, synced and renamed onto `path` only if `fill` succeeds.
/// On any error the temporary file is removed and `path` is left as it was.
/// A device or a pipe (`/dev/null`, `/dev/stdout` on a terminal or pipe) is
/// written directly; a symbolic link is written through, next to its target.
pub fn write_atomic<T>(
    path: &Path,
    fill: impl FnOnce(&mut BufWriter<File>) -> Result<T>,
) -> Result<T> {
    // a device or pipe (e.g. /dev/null) is written in place: renaming onto
    // it would replace it
    if std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir()) {
        let file = File::options()
            .write(true)
            .open(path)
            .with_context(|| format!("cannot write {}", path.display()))?;
        let mut w = BufWriter::new(file);
        let value = fill(&mut w)?;
        w.flush()
            .with_context(|| format!("cannot write {}", path.display()))?;
        return Ok(value);
    }
    // through a symbolic link: write (and rename) next to its target, so the
    // link stays a link and e.g. /dev/stdout is never replaced
    let resolved;
    let path = if std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink()) {
        resolved = path
            .canonicalize()
            .with_context(|| format!("cannot resolve the link {}", path.display()))?;
        resolved.as_path()
    } else {
        path
    };
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| anyhow::anyhow!("{}: not a file path", path.display()))?;
    let tmp = dir.join(format!(
        ".{}.tmp-{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| {
        let file =
            File::create(&tmp).with_context(|| format!("cannot write {}", path.display()))?;
        let mut w = BufWriter::new(file);
        let value = fill(&mut w)?;
        let file = w
            .into_inner()
            .map_err(|e| e.into_error())
            .with_context(|| format!("cannot write {}", path.display()))?;
        file.sync_all()
            .with_context(|| format!("cannot write {}", path.display()))?;
        std::fs::rename(&tmp, path)
            .with_context(|| format!("cannot move the finished output onto {}", path.display()))?;
        Ok(value)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Writes `bytes` to `path` atomically (see [`write_atomic`]).
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic(path, |w| {
        w.write_all(bytes)
            .with_context(|| format!("cannot write {}", path.display()))
    })
}

/// Whether two paths name the same existing file (through links too).
fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) {
            return ma.dev() == mb.dev() && ma.ino() == mb.ino();
        }
    }
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(ca), Ok(cb)) => ca == cb,
        _ => false,
    }
}

/// Refuses to let `output` (named by `option`) overwrite any of `inputs`.
pub fn refuse_overwrite(option: &str, output: &Path, inputs: &[&Path]) -> Result<()> {
    for input in inputs {
        if same_file(output, input) {
            bail!(
                "{option} {} is an input of this run ({}): refusing to overwrite it; choose another output",
                output.display(),
                input.display()
            );
        }
    }
    Ok(())
}

/// Writes equal-length columns with a header row, atomically. A value
/// that is not finite (a diverged loop's) is written as an empty cell,
/// never as `NaN` or `inf`, which a reader would take for data.
pub fn write_columns(path: &Path, headers: &[&str], columns: &[&[f64]]) -> Result<()> {
    write_cells(path, headers, columns, |x| {
        if x.is_finite() {
            format!("{x:.12e}")
        } else {
            String::new()
        }
    })
}

/// [`write_columns`] with each value written by `cell`.
pub fn write_cells(
    path: &Path,
    headers: &[&str],
    columns: &[&[f64]],
    cell: impl Fn(f64) -> String,
) -> Result<()> {
    write_atomic(path, |w| {
        let mut w = csv::Writer::from_writer(w);
        let io = |e: csv::Error| anyhow::anyhow!("cannot write {}: {e}", path.display());
        w.write_record(headers).map_err(io)?;
        let n = columns.iter().map(|c| c.len()).min().unwrap_or(0);
        for k in 0..n {
            w.write_record(columns.iter().map(|c| cell(c[k])))
                .map_err(io)?;
        }
        w.flush()
            .with_context(|| format!("cannot write {}", path.display()))?;
        Ok(())
    })
}

/// Parses one CSV cell as a finite number; the error names the origin, the
/// line and the (0-based `index`) column with its header `name`.
pub fn parse_cell(s: &str, origin: &str, line: u64, index: usize, name: &str) -> Result<f64> {
    let x: f64 = s.parse().map_err(|_| {
        anyhow::anyhow!(
            "{origin}:{line}: column {} (`{name}`): `{s}` is not a number",
            index + 1
        )
    })?;
    crate::checks::finite(x)
        .map_err(|e| anyhow::anyhow!("{origin}:{line}: column {} (`{name}`): {e}", index + 1))
}

/// Refuses a header that names a column twice (which of the two would be
/// read is a guess): the error names both positions.
pub fn check_header(headers: &csv::StringRecord, origin: &str) -> Result<()> {
    for (i, a) in headers.iter().enumerate() {
        if let Some(j) = headers.iter().skip(i + 1).position(|b| b == a) {
            bail!(
                "{origin}:1: column `{a}` is named twice (columns {} and {})",
                i + 1,
                i + 2 + j
            );
        }
    }
    Ok(())
}

/// A stream of `(line, t, v)` rows from CSV text with a header naming `t`
/// and `v`: time strictly increasing, every value finite. Errors name the
/// origin, the line and the column.
pub struct TvRows<R: Read> {
    records: csv::StringRecordsIntoIter<R>,
    origin: String,
    it: usize,
    iv: usize,
    last_t: Option<f64>,
}

impl TvRows<File> {
    /// Opens a CSV file for streaming.
    pub fn open(path: &Path) -> Result<Self> {
        let file = File::open(path).with_context(|| format!("cannot read {}", path.display()))?;
        Self::new(file, &path.display().to_string())
    }
}

impl<R: Read> TvRows<R> {
    /// Reads the header from `reader`; `origin` names the source in errors.
    pub fn new(reader: R, origin: &str) -> Result<Self> {
        let mut r = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_reader(reader);
        let headers = r
            .headers()
            .with_context(|| format!("{origin}: cannot read the header"))?
            .clone();
        check_header(&headers, origin)?;
        let col = |name: &str| headers.iter().position(|h| h == name);
        let (Some(it), Some(iv)) = (col("t"), col("v")) else {
            bail!(
                "{origin}:1: the header must name columns `t` and `v` (found: {})",
                headers.iter().collect::<Vec<_>>().join(",")
            );
        };
        Ok(Self {
            records: r.into_records(),
            origin: origin.to_string(),
            it,
            iv,
            last_t: None,
        })
    }

    fn parse(&mut self, rec: &csv::StringRecord) -> Result<(u64, f64, f64)> {
        let origin = &self.origin;
        let line = rec.position().map_or(0, |p| p.line());
        let field =
            |i: usize, name: &str| parse_cell(rec.get(i).unwrap_or(""), origin, line, i, name);
        let (tk, vk) = (field(self.it, "t")?, field(self.iv, "v")?);
        crate::checks::increasing(self.last_t, tk)
            .map_err(|e| anyhow::anyhow!("{origin}:{line}: column {} (`t`): {e}", self.it + 1))?;
        self.last_t = Some(tk);
        Ok((line, tk, vk))
    }
}

impl<R: Read> Iterator for TvRows<R> {
    type Item = Result<(u64, f64, f64)>;
    fn next(&mut self) -> Option<Self::Item> {
        let rec = self.records.next()?;
        Some(match rec {
            Ok(rec) => self.parse(&rec),
            Err(e) => {
                let line = e.position().map_or(0, |p| p.line());
                Err(anyhow::anyhow!("{}:{line}: {e}", self.origin))
            }
        })
    }
}

/// Reads the `t` and `v` columns of a CSV file with a header (whole file
/// in memory; `friction simulate` streams with [`TvRows`] instead).
pub fn read_tv(path: &Path) -> Result<(Vec<f64>, Vec<f64>)> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    parse_tv(&text, &path.display().to_string())
}

/// Parses `t,v` CSV text; see [`TvRows`].
pub fn parse_tv(text: &str, origin: &str) -> Result<(Vec<f64>, Vec<f64>)> {
    let (mut t, mut v) = (Vec::new(), Vec::new());
    for row in TvRows::new(text.as_bytes(), origin)? {
        let (_, tk, vk) = row?;
        t.push(tk);
        v.push(vk);
    }
    if t.is_empty() {
        bail!("{origin}: no data rows");
    }
    Ok((t, v))
}

// the formatting of a value in a message lives with the checks that echo
// it (the lowest layer); the rest of the crate reaches it here

/// A fraction as a readable percentage: `2.5 %`, `0.031 %`, `1.0e-7 %`.
pub fn pct(x: f64) -> String {
    let p = 100.0 * x;
    if !p.is_finite() {
        "-".into()
    } else if p == 0.0 {
        "0 %".into()
    } else if p.abs() >= 0.01 {
        // three significant digits, no trailing noise
        let digits = (2 - p.abs().log10().floor() as i32).clamp(0, 4) as usize;
        format!("{p:.digits$} %")
    } else {
        format!("{p:.1e} %")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::checks::{num, short};

    #[test]
    fn numbers_stay_short() {
        assert_eq!(num(1e300), "1e300");
        assert_eq!(num(-2.5e-300), "-2.5e-300");
        assert_eq!(num(0.046154), "0.046154");
        assert_eq!(num(1e15), "1000000000000000");
        assert_eq!(short(0.7407407407), "0.7407");
        assert_eq!(short(25.0), "25");
        assert_eq!(short(1.5e-7), "1.5e-7");
        assert_eq!(short(-1.23456e300), "-1.235e300");
        assert_eq!(short(99999.0), "99999");
    }

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
        let e = parse_tv("t,v,t\n0,0,1\n", "in.csv")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("in.csv:1: column `t` is named twice (columns 1 and 3)"),
            "{e}"
        );
        let e = parse_tv("time,v\n0,0\n", "in.csv").unwrap_err().to_string();
        assert!(e.contains("in.csv:1"), "{e}");
        let e = parse_tv("t,v\n0,0\n1\n", "in.csv").unwrap_err().to_string();
        assert!(e.contains("in.csv:3"), "{e}");
        let e = parse_tv("t,v\n0,NaN\n", "in.csv").unwrap_err().to_string();
        assert!(e.contains("not finite"), "{e}");
    }

    #[test]
    fn a_failed_write_leaves_the_old_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.csv");
        std::fs::write(&path, "old").unwrap();
        let r: Result<()> = write_atomic(&path, |w| {
            w.write_all(b"half a row,")?;
            bail!("disk full")
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old");
        // and no temporary file is left behind
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        write_bytes(&path, b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
    }

    #[cfg(unix)]
    #[test]
    fn writes_go_through_links() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("target.csv");
        std::fs::write(&target, "old").unwrap();
        let link = dir.path().join("link.csv");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        write_bytes(&link, b"new").unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "new");
    }

    #[test]
    fn outputs_never_overwrite_inputs() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("in.csv");
        std::fs::write(&input, "t,v\n").unwrap();
        let alias = dir.path().join(".").join("in.csv");
        let e = refuse_overwrite("--output", &alias, &[&input])
            .unwrap_err()
            .to_string();
        assert!(e.contains("refusing to overwrite"), "{e}");
        #[cfg(unix)]
        {
            let link = dir.path().join("link.csv");
            std::os::unix::fs::symlink(&input, &link).unwrap();
            assert!(refuse_overwrite("--output", &link, &[&input]).is_err());
        }
        assert!(refuse_overwrite("--output", &dir.path().join("new.csv"), &[&input]).is_ok());
    }
}
