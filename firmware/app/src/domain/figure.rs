//! Patterns and figures (SPEC §4.6): what a run draws, described once in
//! board centimetres. A path figure is a few strokes of lines and arcs
//! ([`Figure::stroke`]); each actuator takes them in its own unit at its
//! boundary — the gimbal interpolates them point by point in board cm
//! ([`PathCursor`](super::path::PathCursor)), the galvo's path planner
//! marks them in mm.

use core::fmt;

pub use kinematics_core::{Pattern as GridPattern, Rotation};

pub use self::stroke::{Segment, Segments, Stroke};
pub use self::stroke_cm::StrokeCm;
use super::point::PointCm;
use super::units::Unit;
use crate::text::Shortest;

mod stroke;
mod stroke_cm;

/// A figure drawn as a path, board cm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Figure {
    /// Straight line A → B.
    Line {
        /// Start, cm.
        from: PointCm,
        /// End, cm.
        to: PointCm,
    },
    /// Full circle from its top point.
    Circle {
        /// Centre, cm.
        centre: PointCm,
        /// Radius, cm.
        radius_cm: f64,
        /// Direction.
        rotation: Rotation,
    },
    /// Rectangle border through two opposite corners, from `a`.
    Rect {
        /// One corner, cm.
        a: PointCm,
        /// The opposite corner, cm.
        b: PointCm,
    },
    /// Galvo tuning figure in the spirit of the ILDA test pattern: a
    /// square, its inscribed circle and a cross through the centre, each a
    /// separate stroke (so every stroke starts after a jump).
    Tuning {
        /// Centre, cm.
        centre: PointCm,
        /// Side of the square, cm.
        size_cm: f64,
    },
    /// One stroke of up to [`StrokeCm::MAX_SEGMENTS`] lines (the galvo
    /// marks consecutive G-code feed moves as one: corners at the path
    /// planner's junction speed, the laser on through them), or a piece
    /// continuing the stroke sent before it
    /// ([`StrokeCm::continuing`]).
    Stroke(StrokeCm),
}

/// A test pattern or path (SPEC §4.6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Pattern {
    /// A grid pattern: home, corner, horizontal, vertical, visit-all, full
    /// grid raster or serpentine.
    Grid(GridPattern),
    /// A drawn path: no dwell between its points.
    Path(Figure),
}

impl Figure {
    /// Name used on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            Figure::Line { .. } => "line",
            Figure::Circle { .. } => "circle",
            Figure::Rect { .. } => "rect",
            Figure::Tuning { .. } => "tuning",
            Figure::Stroke(_) => "stroke",
        }
    }

    /// Stroke `index` (from 0) laid out in `unit`: every length of the
    /// figure is converted to `unit` first, then the stroke is built from
    /// the converted lengths. `None` past the last stroke.
    pub fn stroke(&self, index: usize, unit: Unit) -> Option<Stroke> {
        let at = |p: PointCm| [unit.from_cm(p.x_cm), unit.from_cm(p.y_cm)];
        match (*self, index) {
            (Figure::Line { from, to }, 0) => Some(Stroke::lines(at(from), [at(to)])),
            (
                Figure::Circle {
                    centre,
                    radius_cm,
                    rotation,
                },
                0,
            ) => Some(Stroke::circle(
                at(centre),
                unit.from_cm(radius_cm),
                rotation,
            )),
            (Figure::Rect { a, b }, 0) => Some(Stroke::rect(at(a), at(b))),
            (Figure::Stroke(stroke), 0) => Some(stroke.in_unit(unit)),
            (Figure::Tuning { centre, size_cm }, stroke) => {
                let [cx, cy] = at(centre);
                let h = unit.from_cm(size_cm) / 2.0;
                match stroke {
                    0 => Some(Stroke::rect([cx - h, cy + h], [cx + h, cy - h])),
                    1 => Some(Stroke::circle([cx, cy], h, Rotation::Cw)),
                    2 => Some(Stroke::lines([cx - h, cy], [[cx + h, cy]])),
                    3 => Some(Stroke::lines([cx, cy + h], [[cx, cy - h]])),
                    _ => None,
                }
            }
            _ => None,
        }
    }

    /// Corners `[x, y]` of the figure's bounding box in `unit` (built from
    /// the lengths converted to `unit`, like [`Self::stroke`]).
    pub fn bounds(&self, unit: Unit) -> [[f64; 2]; 4] {
        let at = |p: PointCm| [unit.from_cm(p.x_cm), unit.from_cm(p.y_cm)];
        let (lo, hi) = match *self {
            Figure::Line { from: a, to: b } | Figure::Rect { a, b } => {
                let (a, b) = (at(a), at(b));
                (
                    [a[0].min(b[0]), a[1].min(b[1])],
                    [a[0].max(b[0]), a[1].max(b[1])],
                )
            }
            Figure::Circle {
                centre, radius_cm, ..
            } => {
                let (c, h) = (at(centre), unit.from_cm(radius_cm).abs());
                ([c[0] - h, c[1] - h], [c[0] + h, c[1] + h])
            }
            Figure::Tuning { centre, size_cm } => {
                let (c, h) = (at(centre), (unit.from_cm(size_cm) / 2.0).abs());
                ([c[0] - h, c[1] - h], [c[0] + h, c[1] + h])
            }
            Figure::Stroke(stroke) => stroke.bounds(unit),
        };
        [lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]]
    }
}

impl Pattern {
    /// Name used on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            Pattern::Grid(grid) => grid.name(),
            Pattern::Path(figure) => figure.name(),
        }
    }

    /// Whether this is a drawn path (no dwell between its points) rather
    /// than a set of grid points.
    pub fn is_path(&self) -> bool {
        matches!(self, Pattern::Path(_))
    }

    /// The figure of a path; `None` for a grid pattern.
    pub fn figure(&self) -> Option<Figure> {
        match *self {
            Pattern::Path(figure) => Some(figure),
            Pattern::Grid(_) => None,
        }
    }

    /// The grid pattern; `None` for a path.
    pub fn grid(&self) -> Option<GridPattern> {
        match *self {
            Pattern::Grid(grid) => Some(grid),
            Pattern::Path(_) => None,
        }
    }
}

/// The pattern in command-line syntax (`circle 2 1 4 ccw`).
impl fmt::Display for Pattern {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let cm = |p: PointCm| (Shortest(p.x_cm), Shortest(p.y_cm));
        let Pattern::Path(figure) = *self else {
            return f.write_str(self.name());
        };
        match figure {
            Figure::Line { from, to } | Figure::Rect { a: from, b: to } => {
                let ((x0, y0), (x1, y1)) = (cm(from), cm(to));
                write!(f, "{} {x0} {y0} {x1} {y1}", self.name())
            }
            Figure::Circle {
                centre,
                radius_cm,
                rotation,
            } => {
                let (x, y) = cm(centre);
                let turn = match rotation {
                    Rotation::Cw => "cw",
                    Rotation::Ccw => "ccw",
                };
                write!(f, "circle {x} {y} {} {turn}", Shortest(radius_cm))
            }
            Figure::Tuning { centre, size_cm } => {
                let (x, y) = cm(centre);
                write!(f, "tuning {x} {y} {}", Shortest(size_cm))
            }
            Figure::Stroke(stroke) => {
                let (x, y) = cm(stroke.start());
                write!(f, "stroke {x} {y} ({} segments)", stroke.segments())
            }
        }
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for Pattern {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "{}", defmt::Display2Format(self))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(x_cm: f64, y_cm: f64) -> PointCm {
        PointCm::new(x_cm, y_cm)
    }

    #[test]
    fn strokes_close_where_they_should() {
        let rect = Figure::Rect {
            a: at(-1.0, 0.5),
            b: at(1.0, -0.5),
        };
        let stroke = rect.stroke(0, Unit::GalvoMm).unwrap();
        assert_eq!(stroke.start, [-10.0, 5.0]);
        assert_eq!(
            stroke.segments.last(),
            Some(&Segment::Line { to: [-10.0, 5.0] })
        );
        assert!(rect.stroke(1, Unit::GalvoMm).is_none());
        let tuning = Figure::Tuning {
            centre: at(0.0, 0.0),
            size_cm: 4.0,
        };
        let strokes: heapless::Vec<_, 8> = (0..)
            .map_while(|i| tuning.stroke(i, Unit::GalvoMm))
            .collect();
        assert_eq!(strokes.len(), 4, "square, circle, two cross lines");
        assert_eq!(
            strokes[1].start,
            [0.0, 20.0],
            "the circle starts at its top"
        );
        assert_eq!(
            tuning.bounds(Unit::GalvoMm),
            [[-20.0, -20.0], [20.0, -20.0], [20.0, 20.0], [-20.0, 20.0]]
        );
    }

    #[test]
    fn each_unit_converts_the_lengths_before_the_stroke_is_built() {
        // The galvo's lengths are rounded to f32 first, as its planner
        // takes them; the circle's top is their sum.
        let circle = Figure::Circle {
            centre: at(1.234_567_891, -2.345_678_912),
            radius_cm: 3.456_789_123,
            rotation: Rotation::Ccw,
        };
        let mm = |cm: f64| f64::from((cm * 10.0) as f32);
        let stroke = circle.stroke(0, Unit::GalvoMm).unwrap();
        assert_eq!(
            stroke.start,
            [mm(1.234_567_891), mm(-2.345_678_912) + mm(3.456_789_123)]
        );
        let stroke = circle.stroke(0, Unit::BoardCm).unwrap();
        assert_eq!(
            stroke.start,
            [1.234_567_891, -2.345_678_912 + 3.456_789_123]
        );
    }
}
