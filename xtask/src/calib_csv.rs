//! The calibration CSV reader of `cargo xtask calib fit` (SPEC §5): the
//! measured points, header exactly `x,y,dx,dy`, all mm.

use std::io::Read;

use kinematics_core::MeasuredPoint;
use kinematics_core::error_model::MAX_MEASURED_MM;

/// Column names, in order.
pub const HEADER: [&str; 4] = ["x", "y", "dx", "dy"];

/// Parses the measured points. The header must be `x,y,dx,dy`; fields may
/// be padded with spaces; lines end at LF, CRLF or CR; blank lines and
/// lines starting with `#` are skipped; every value must be finite and within ±[`MAX_MEASURED_MM`] (10 m).
/// Errors name the 1-based line.
pub fn read_points(mut input: impl Read) -> Result<Vec<MeasuredPoint>, String> {
    let mut bytes = Vec::new();
    input
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read: {e}"))?;
    lone_crs_to_lfs(&mut bytes);
    let record_line = |pos: &csv::Position| line_of(&bytes, pos);
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(bytes.as_slice());
    let mut points = Vec::new();
    let mut header_seen = false;
    for record in reader.records() {
        let record = record.map_err(|e| match e.position() {
            Some(pos) => format!("line {}: {e}", record_line(pos)),
            None => e.to_string(),
        })?;
        let line = record.position().map_or(0, record_line);
        if !header_seen {
            if record.iter().ne(HEADER) {
                let found: Vec<&str> = record.iter().collect();
                return Err(format!(
                    "line {line}: header must be exactly `x,y,dx,dy`, found `{}`",
                    found.join(",")
                ));
            }
            header_seen = true;
            continue;
        }
        points.push(point(&record, line)?);
    }
    if !header_seen {
        return Err("line 1: empty file, expected the header `x,y,dx,dy`".into());
    }
    Ok(points)
}

/// csv ends a comment at LF only, so with CR-only (old Mac) line ends a
/// comment line would swallow the rows after it: make lone CRs LFs
/// (same length, so positions stay) and lines read and count alike.
fn lone_crs_to_lfs(bytes: &mut [u8]) {
    let lone_crs: Vec<usize> = bytes
        .iter()
        .enumerate()
        .filter(|&(i, &b)| b == b'\r' && bytes.get(i + 1) != Some(&b'\n'))
        .map(|(i, _)| i)
        .collect();
    for i in lone_crs {
        if let Some(b) = bytes.get_mut(i) {
            *b = b'\n';
        }
    }
}

/// 1-based line where the record at `pos` starts. csv positions a record
/// at the blank or comment lines it skipped before it, so skip those too.
fn line_of(bytes: &[u8], pos: &csv::Position) -> usize {
    let mut at = usize::try_from(pos.byte()).unwrap_or(usize::MAX);
    loop {
        match bytes.get(at) {
            Some(b'\n' | b'\r') => at += 1,
            Some(b'#') => {
                let rest = bytes.get(at..).unwrap_or_default();
                at += rest
                    .iter()
                    .position(|&b| b == b'\n')
                    .map_or(rest.len(), |i| i + 1);
            }
            _ => break,
        }
    }
    1 + bytes.iter().take(at).filter(|&&b| b == b'\n').count()
}

/// The measured point of one data record on `line`.
fn point(record: &csv::StringRecord, line: usize) -> Result<MeasuredPoint, String> {
    if record.len() != HEADER.len() {
        return Err(format!(
            "line {line}: expected 4 fields (x,y,dx,dy), found {}",
            record.len()
        ));
    }
    let mut v = [0.0; 4];
    for ((slot, text), name) in v.iter_mut().zip(record.iter()).zip(HEADER) {
        *slot = text
            .parse::<f64>()
            .map_err(|_| format!("line {line}: column {name}: `{text}` is not a number"))?;
        if !slot.is_finite() {
            return Err(format!(
                "line {line}: column {name}: `{text}` is not a finite number"
            ));
        }
        if slot.abs() > MAX_MEASURED_MM {
            return Err(format!(
                "line {line}: column {name}: {text} mm is beyond +-{MAX_MEASURED_MM} mm (10 m); \
                 check the units (mm) of the CSV"
            ));
        }
    }
    let [x_mm, y_mm, dx_mm, dy_mm] = v;
    Ok(MeasuredPoint {
        x_mm,
        y_mm,
        dx_mm,
        dy_mm,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cr_only_line_ends_read_like_lf() {
        // Found by the calib_csv fuzz target (tests/fuzz/artifacts/
        // calib_csv/): with CR-only line ends every error named line 1,
        // and a comment line swallowed the rows after it.
        for csv in [
            "x,y,dx,dy\r1,2,3,4\r# note\r\r5,6,abc,8\r",
            "x,y,dx,dy\r\n1,2,3,4\n# note\r\r\n5,6,abc,8",
            "x,y,dx,dy\n1,2,3,4\n# note\n\n5,6,abc,8\n",
        ] {
            assert_eq!(
                read_points(csv.as_bytes()).unwrap_err(),
                "line 5: column dx: `abc` is not a number",
                "{csv:?}"
            );
        }
        let rows = read_points("x,y,dx,dy\r# c\r1,2,3,4\r# c2\r5,6,7,8\r".as_bytes()).unwrap();
        assert_eq!(rows.len(), 2);
        assert_eq!(rows[1].dy_mm, 8.0);
    }
}
