//! The calibration CSV reader of `cargo xtask calib fit`
//! (`xtask::calib_csv::read_points`).
//!
//! Properties:
//! * nothing panics, whatever the bytes;
//! * every accepted row is finite and within ±[`MAX_MEASURED_MM`] in every
//!   column; there are fewer rows than lines (CR, LF or CRLF), and without
//!   CSV quoting exactly one per line that is not the header, blank or a
//!   `#` comment;
//! * accepted rows, written back as CSV, read back bit for bit;
//! * a refused input gets an error that starts `line N: ` with N a line
//!   of the input, and an error quoting a field names a line holding it.

use kinematics_core::MeasuredPoint;
use kinematics_core::error_model::MAX_MEASURED_MM;
use xtask::calib_csv::read_points;

/// What one input exercised.
#[derive(Debug, Default)]
pub struct Summary {
    /// Rows accepted (0 when refused).
    pub rows: usize,
    /// The error, when refused.
    pub error: Option<String>,
}

/// Runs the CSV reader properties on `data`; panics when one fails.
pub fn check(data: &[u8]) -> Summary {
    let text = String::from_utf8_lossy(data);
    let lines = split_lines(&text);
    match read_points(data) {
        Ok(points) => {
            assert!(
                points.len() < lines.len(),
                "{} rows from {} lines",
                points.len(),
                lines.len()
            );
            if !text.contains('"') {
                // Without CSV quoting each line is a record, blank or a
                // comment: no row is dropped or invented.
                let mut records = lines
                    .iter()
                    .filter(|l| !l.is_empty() && !l.starts_with('#'));
                let _header = records.next();
                assert_eq!(points.len(), records.count(), "rows dropped or invented");
            }
            for p in &points {
                for v in columns(p) {
                    assert!(
                        v.is_finite() && v.abs() <= MAX_MEASURED_MM,
                        "accepted value {v} in {p:?}"
                    );
                }
            }
            let mut text = String::from("x,y,dx,dy\n");
            for p in &points {
                let [x, y, dx, dy] = columns(p);
                text.push_str(&format!("{x},{y},{dx},{dy}\n"));
            }
            let again = read_points(text.as_bytes())
                .unwrap_or_else(|e| panic!("accepted rows written back are refused: {e}"));
            let bits = |ps: &[MeasuredPoint]| -> Vec<[u64; 4]> {
                ps.iter().map(|p| columns(p).map(f64::to_bits)).collect()
            };
            assert_eq!(bits(&again), bits(&points), "rows do not read back");
            Summary {
                rows: points.len(),
                error: None,
            }
        }
        Err(error) => {
            let line = named_line(&error)
                .unwrap_or_else(|| panic!("error {error:?} does not start `line N: `"));
            assert!(
                (1..=lines.len()).contains(&line),
                "error {error:?} names line {line} of {}",
                lines.len()
            );
            if let Some(quoted) = quoted_field(&error) {
                let held = lines[line - 1];
                // CSV quoting changes a field's text; plain lines hold it.
                assert!(
                    held.contains('"') || held.contains(quoted),
                    "error {error:?}: line {line} is {held:?}"
                );
            }
            Summary {
                rows: 0,
                error: Some(error),
            }
        }
    }
}

/// The lines of `text`, ended by CR, LF or CRLF as in CSV.
fn split_lines(text: &str) -> Vec<&str> {
    let mut lines = Vec::new();
    let mut rest = text;
    while let Some(end) = rest.find(['\r', '\n']) {
        lines.push(&rest[..end]);
        let skip = if rest[end..].starts_with("\r\n") {
            2
        } else {
            1
        };
        rest = &rest[end + skip..];
    }
    lines.push(rest);
    lines
}

fn columns(p: &MeasuredPoint) -> [f64; 4] {
    [p.x_mm, p.y_mm, p.dx_mm, p.dy_mm]
}

/// N of an error `line N: …`.
fn named_line(error: &str) -> Option<usize> {
    let rest = error.strip_prefix("line ")?;
    let (number, _) = rest.split_once(": ")?;
    number.parse().ok()
}

/// The field an error quotes as `` `text` `` (when it is on one line).
fn quoted_field(error: &str) -> Option<&str> {
    // `line N: column NAME: `text` …`
    let (_, rest) = error.split_once(": ")?;
    let (_, rest) = rest.strip_prefix("column ")?.split_once(": `")?;
    let (field, _) = rest.split_once('`')?;
    (!field.contains(['\n', '\r'])).then_some(field)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accepted_and_refused_inputs_are_summarised() {
        let ok = check(b"x,y,dx,dy\n0,0,0.5,-0.25\n10,-10,1e-3,0\n");
        assert_eq!((ok.rows, ok.error), (2, None));
        let bad = check(b"x,y,dx,dy\n0,0,0,0\n\n1,2,zz,4\n");
        assert_eq!(
            bad.error.as_deref(),
            Some("line 4: column dx: `zz` is not a number")
        );
        assert_eq!(named_line("line 12: x"), Some(12));
        assert_eq!(split_lines("a\rb\r\nc\n\nd"), ["a", "b", "c", "", "d"]);
        assert_eq!(named_line("no line"), None);
        assert_eq!(
            quoted_field("line 2: column x: `1e400` is not"),
            Some("1e400")
        );
        assert_eq!(
            quoted_field("line 1: header must be exactly `x,y,dx,dy`, found `column x: `1``"),
            None
        );
    }
}
