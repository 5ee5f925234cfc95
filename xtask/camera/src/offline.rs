//! Offline measurement: a directory of frames and a CSV naming the
//! commanded board point of each (`image,x,y`, x and y in mm), plus one
//! laser-off frame of the same view (`background.png` by default).

use std::path::{Path, PathBuf};

use crate::camera::Intrinsics;
use crate::image::GrayImage;
use crate::markers::MarkerDetector;
use crate::measure::{BoardView, SpotOnBoard, locate_board};
use crate::target::TargetLayout;

/// Column names of the frame list, in order.
pub const FRAME_LIST_HEADER: &str = "image,x,y";

/// One row of the frame list.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameRow {
    /// Image file, relative to the frame directory.
    pub image: String,
    /// Commanded board point, mm.
    pub commanded_mm: [f64; 2],
    /// 1-based CSV line.
    pub line: usize,
}

/// A measured frame.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredFrame {
    /// The frame list row.
    pub row: FrameRow,
    /// Where the spot was on the board.
    pub spot: SpotOnBoard,
}

/// Parses the frame list (header exactly `image,x,y`; `#` comments and
/// blank lines skipped). Errors name the line.
pub fn read_frame_list(text: &str) -> Result<Vec<FrameRow>, String> {
    let mut rows = Vec::new();
    let mut header = false;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let t = raw.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = t.split(',').map(str::trim).collect();
        if !header {
            if fields.join(",") != FRAME_LIST_HEADER {
                return Err(format!(
                    "line {line}: header must be exactly `{FRAME_LIST_HEADER}`, found `{t}`"
                ));
            }
            header = true;
            continue;
        }
        let [image, x, y] = fields[..] else {
            return Err(format!(
                "line {line}: expected 3 fields ({FRAME_LIST_HEADER}), found {}",
                fields.len()
            ));
        };
        if image.is_empty() {
            return Err(format!("line {line}: no image named"));
        }
        let num = |s: &str, name: &str| match s.parse::<f64>() {
            Ok(v) if v.is_finite() && v.abs() <= 10_000.0 => Ok(v),
            _ => Err(format!(
                "line {line}: column {name}: `{s}` is not a board coordinate in mm"
            )),
        };
        rows.push(FrameRow {
            image: image.to_owned(),
            commanded_mm: [num(x, "x")?, num(y, "y")?],
            line,
        });
    }
    if !header {
        return Err(format!(
            "line 1: empty frame list, expected the header `{FRAME_LIST_HEADER}`"
        ));
    }
    if rows.is_empty() {
        return Err("the frame list names no frames".into());
    }
    Ok(rows)
}

fn load(path: &Path) -> Result<GrayImage, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    GrayImage::read_png(&bytes).map_err(|e| format!("{}: {e}", path.display()))
}

/// Measures every frame of `rows` in `dir` against `background`.
/// Any bad frame refuses the whole set, naming the frame and its CSV line.
pub fn measure_frames(
    dir: &Path,
    rows: &[FrameRow],
    background: &Path,
    layout: &TargetLayout,
    intrinsics: Option<Intrinsics>,
) -> Result<(BoardView, Vec<MeasuredFrame>), String> {
    let bg = load(background)?;
    let mut detector = MarkerDetector::new(bg.width, bg.height)?;
    let view = locate_board(&mut detector, &bg, layout, intrinsics)
        .map_err(|e| format!("{}: {e}", background.display()))?;
    let mut out = Vec::with_capacity(rows.len());
    for row in rows {
        let path: PathBuf = dir.join(&row.image);
        if !path.is_file() {
            return Err(format!(
                "line {}: image {} not found",
                row.line,
                path.display()
            ));
        }
        let frame = load(&path)?;
        let spot = view
            .measure(&bg, &frame)
            .map_err(|e| format!("{} (line {}): {e}", path.display(), row.line))?;
        out.push(MeasuredFrame {
            row: row.clone(),
            spot,
        });
    }
    Ok((view, out))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_list_errors_name_the_line() {
        let ok = read_frame_list("# frames\nimage,x,y\nf1.png, 1.5, -2\n\nf2.png,0,0\n").unwrap();
        assert_eq!(ok.len(), 2);
        assert_eq!(
            ok[0],
            FrameRow {
                image: "f1.png".into(),
                commanded_mm: [1.5, -2.0],
                line: 3
            }
        );
        assert_eq!(ok[1].line, 5);
        for (text, err) in [
            (
                "x,y\n",
                "line 1: header must be exactly `image,x,y`, found `x,y`",
            ),
            (
                "image,x,y\nf.png,1\n",
                "line 2: expected 3 fields (image,x,y), found 2",
            ),
            ("image,x,y\n,1,2\n", "line 2: no image named"),
            (
                "image,x,y\nf.png,1,nan\n",
                "line 2: column y: `nan` is not a board coordinate in mm",
            ),
            (
                "",
                "line 1: empty frame list, expected the header `image,x,y`",
            ),
            ("image,x,y\n", "the frame list names no frames"),
        ] {
            assert_eq!(read_frame_list(text).unwrap_err(), err);
        }
    }
}
