//! Marked paths on the galvo: what the sequencer asks for, as strokes
//! (a start point and the lines and arcs drawn from it with the laser on)
//! that the loop feeds to the look-ahead path planner.

/// A path to mark, board mm (galvo frame).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GalvoPath {
    /// Straight line.
    Line {
        /// Start, mm.
        from_mm: [f32; 2],
        /// End, mm.
        to_mm: [f32; 2],
    },
    /// Full circle from its top point.
    Circle {
        /// Centre, mm.
        centre_mm: [f32; 2],
        /// Radius, mm.
        radius_mm: f32,
        /// Counter-clockwise.
        ccw: bool,
    },
    /// Rectangle border through two opposite corners.
    Rect {
        /// One corner, mm.
        a_mm: [f32; 2],
        /// The opposite corner, mm.
        b_mm: [f32; 2],
    },
    /// Galvo tuning figure in the spirit of the ILDA test pattern: a
    /// square, its inscribed circle and a cross through the centre, each a
    /// separate stroke (so every stroke starts after a jump).
    Tuning {
        /// Centre, mm.
        centre_mm: [f32; 2],
        /// Half the square's side, mm.
        half_size_mm: f32,
    },
}

/// One piece of a stroke.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Segment {
    /// Line to this point, mm.
    Line([f64; 2]),
    /// Arc to `end` about `centre`, mm.
    Arc {
        end: [f64; 2],
        centre: [f64; 2],
        ccw: bool,
    },
}

/// Segments of one stroke.
pub(super) type Segments = heapless::Vec<Segment, 4>;

fn mm(p: [f32; 2]) -> [f64; 2] {
    [f64::from(p[0]), f64::from(p[1])]
}

/// The rectangle through opposite corners `a`, `b`, from `a`.
fn rect(a: [f64; 2], b: [f64; 2]) -> Segments {
    [[b[0], a[1]], b, [a[0], b[1]], a]
        .into_iter()
        .map(Segment::Line)
        .collect()
}

impl GalvoPath {
    /// Stroke `index`: its start point (mm) and segments; `None` past the
    /// last stroke.
    pub(super) fn stroke(&self, index: usize) -> Option<([f64; 2], Segments)> {
        match (*self, index) {
            (GalvoPath::Line { from_mm, to_mm }, 0) => {
                Some((mm(from_mm), Segments::from_iter([Segment::Line(mm(to_mm))])))
            }
            (
                GalvoPath::Circle {
                    centre_mm,
                    radius_mm,
                    ccw,
                },
                0,
            ) => {
                let centre = mm(centre_mm);
                let top = [centre[0], centre[1] + f64::from(radius_mm)];
                Some((
                    top,
                    Segments::from_iter([Segment::Arc {
                        end: top,
                        centre,
                        ccw,
                    }]),
                ))
            }
            (GalvoPath::Rect { a_mm, b_mm }, 0) => Some((mm(a_mm), rect(mm(a_mm), mm(b_mm)))),
            (
                GalvoPath::Tuning {
                    centre_mm,
                    half_size_mm,
                },
                stroke,
            ) => {
                let [cx, cy] = mm(centre_mm);
                let h = f64::from(half_size_mm);
                match stroke {
                    0 => Some(([cx - h, cy + h], rect([cx - h, cy + h], [cx + h, cy - h]))),
                    1 => GalvoPath::Circle {
                        centre_mm,
                        radius_mm: half_size_mm,
                        ccw: false,
                    }
                    .stroke(0),
                    2 => Some((
                        [cx - h, cy],
                        Segments::from_iter([Segment::Line([cx + h, cy])]),
                    )),
                    3 => Some((
                        [cx, cy + h],
                        Segments::from_iter([Segment::Line([cx, cy - h])]),
                    )),
                    _ => None,
                }
            }
            _ => None,
        }
    }

    /// Corners of the path's bounding box, mm (to check the DAC range).
    pub fn bounds_mm(&self) -> [[f64; 2]; 4] {
        let (lo, hi) = match *self {
            GalvoPath::Line { from_mm, to_mm }
            | GalvoPath::Rect {
                a_mm: from_mm,
                b_mm: to_mm,
            } => {
                let (a, b) = (mm(from_mm), mm(to_mm));
                (
                    [a[0].min(b[0]), a[1].min(b[1])],
                    [a[0].max(b[0]), a[1].max(b[1])],
                )
            }
            GalvoPath::Circle {
                centre_mm,
                radius_mm: half,
                ..
            }
            | GalvoPath::Tuning {
                centre_mm,
                half_size_mm: half,
            } => {
                let (c, h) = (mm(centre_mm), f64::from(half).abs());
                ([c[0] - h, c[1] - h], [c[0] + h, c[1] + h])
            }
        };
        [lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strokes_close_where_they_should() {
        let rect = GalvoPath::Rect {
            a_mm: [-10.0, 5.0],
            b_mm: [10.0, -5.0],
        };
        let (start, segments) = rect.stroke(0).unwrap();
        assert_eq!(start, [-10.0, 5.0]);
        assert_eq!(segments.last(), Some(&Segment::Line([-10.0, 5.0])));
        assert!(rect.stroke(1).is_none());
        let tuning = GalvoPath::Tuning {
            centre_mm: [0.0, 0.0],
            half_size_mm: 20.0,
        };
        let strokes: heapless::Vec<_, 8> = (0..).map_while(|i| tuning.stroke(i)).collect();
        assert_eq!(strokes.len(), 4, "square, circle, two cross lines");
        assert_eq!(strokes[1].0, [0.0, 20.0], "the circle starts at its top");
        assert_eq!(
            tuning.bounds_mm(),
            [[-20.0, -20.0], [20.0, -20.0], [20.0, 20.0], [-20.0, 20.0]]
        );
    }
}
