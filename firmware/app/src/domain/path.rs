//! The gimbal's side of a path: a figure's stroke (board cm) interpolated
//! point by point, each next point in O(1) (midpoint criterion: within
//! half a step per axis of the ideal path).

use kinematics_core as kc;
use kinematics_core::{ArcSteps, BoardPoint, Criterion, LineSteps};

use super::aim::{Aimer, Target};
use super::error::PatternError;
use super::figure::{Figure, Pattern, Segment};
use super::point::PointCm;
use super::units::Unit;

/// The interpolated points of one segment.
#[derive(Debug, Clone, Copy)]
enum SegmentSteps {
    Line(LineSteps),
    Arc(ArcSteps),
}

impl Iterator for SegmentSteps {
    type Item = BoardPoint;

    fn next(&mut self) -> Option<BoardPoint> {
        match self {
            SegmentSteps::Line(steps) => steps.next(),
            SegmentSteps::Arc(steps) => steps.next(),
        }
    }
}

fn board([x_cm, y_cm]: [f64; 2]) -> BoardPoint {
    BoardPoint::new(x_cm, y_cm)
}

/// The end point of `segment`, board cm.
fn segment_end(segment: &Segment) -> [f64; 2] {
    match *segment {
        Segment::Line { to } => to,
        Segment::Arc { end, .. } => end,
    }
}

/// The points of `segment` from `from` (board cm) in steps of `step_cm`.
fn segment_steps(
    from: [f64; 2],
    segment: &Segment,
    step_cm: f64,
) -> Result<SegmentSteps, kc::Error> {
    let criterion = Criterion::Midpoint;
    match *segment {
        Segment::Line { to } => {
            LineSteps::new(board(from), board(to), step_cm, criterion).map(SegmentSteps::Line)
        }
        Segment::Arc {
            end,
            centre,
            rotation,
        } => ArcSteps::arc(
            board(from),
            board(end),
            board(centre),
            rotation,
            step_cm,
            criterion,
        )
        .map(SegmentSteps::Arc),
    }
}

/// Where a run is in one pass of a path pattern: the interpolator of the
/// current segment and its current point. The next point costs O(1):
/// nothing walks the path from its start. The pass keeps the step it
/// started with (`path.step_cm` applies from the next pass).
#[derive(Debug, Clone, Copy)]
pub struct PathCursor {
    figure: Figure,
    step_cm: f64,
    /// Index of the current segment within the stroke.
    segment: usize,
    steps: SegmentSteps,
    current: BoardPoint,
}

impl PathCursor {
    /// At the first point of a pass of `pattern` on the gimbal; `None` for
    /// grid patterns and the tuning figure (galvo only).
    ///
    /// Errors: the path cannot be interpolated (radius below one step, too
    /// many steps, non-finite input).
    pub fn start(pattern: &Pattern, aimer: &Aimer) -> Option<Result<Self, kc::Error>> {
        let figure = match pattern {
            Pattern::Path(Figure::Tuning { .. }) | Pattern::Grid(_) => return None,
            Pattern::Path(figure) => *figure,
        };
        Some(Self::first(figure, aimer.path_step_cm()))
    }

    /// At the first point of `figure` (one stroke) in steps of `step_cm`.
    fn first(figure: Figure, step_cm: f64) -> Result<Self, kc::Error> {
        let stroke = figure
            .stroke(0, Unit::BoardCm)
            .ok_or(kc::Error::PathTooShort)?;
        // Every segment is checked now, so that a pass that starts also
        // ends.
        let mut from = stroke.start;
        for segment in &stroke.segments {
            segment_steps(from, segment, step_cm)?;
            from = segment_end(segment);
        }
        let first = stroke.segments.first().ok_or(kc::Error::PathTooShort)?;
        let mut steps = segment_steps(stroke.start, first, step_cm)?;
        // Every interpolator yields its start point first.
        let current = steps.next().ok_or(kc::Error::PathTooShort)?;
        Ok(Self {
            figure,
            step_cm,
            segment: 0,
            steps,
            current,
        })
    }

    /// The current point.
    pub fn target(&self) -> Target {
        Target {
            point: PointCm::from_board(self.current),
            grid: None,
        }
    }

    /// Moves to the next point; `false` (staying on the last point) at the
    /// end of the pass.
    pub fn advance(&mut self) -> bool {
        loop {
            if let Some(point) = self.steps.next() {
                self.current = point;
                return true;
            }
            if !self.next_segment() {
                return false;
            }
        }
    }

    /// Starts the interpolator of the next segment, past its start point
    /// (the end of the previous one); `false` after the last segment.
    fn next_segment(&mut self) -> bool {
        let Some(stroke) = self.figure.stroke(0, Unit::BoardCm) else {
            return false;
        };
        let (Some(done), Some(next)) = (
            stroke.segments.get(self.segment),
            stroke.segments.get(self.segment + 1),
        ) else {
            return false;
        };
        let Ok(mut steps) = segment_steps(segment_end(done), next, self.step_cm) else {
            return false;
        };
        steps.next();
        self.segment += 1;
        self.steps = steps;
        true
    }
}

/// Every point of one pass of `pattern` in order (grid points on the grid
/// of `aimer`), for checks and tools; a run itself steps through them
/// with [`Aimer::grid_target`] and [`PathCursor`].
///
/// Errors: the path cannot be interpolated; the tuning figure (galvo only).
pub fn pass_points(
    pattern: &Pattern,
    aimer: &Aimer,
) -> Result<impl Iterator<Item = Target>, PatternError> {
    let name = pattern.name();
    let mut path = match PathCursor::start(pattern, aimer) {
        Some(Ok(cursor)) => Some(cursor),
        Some(Err(error)) => {
            return Err(PatternError::Path {
                pattern: name,
                error,
            });
        }
        None if pattern.is_path() => {
            return Err(PatternError::PathActuator { pattern: name });
        }
        None => None,
    };
    let pattern = *pattern;
    let aimer = *aimer;
    let mut index = 0usize;
    let mut path_started = false;
    Ok(core::iter::from_fn(move || match path.as_mut() {
        Some(cursor) => {
            if path_started && !cursor.advance() {
                return None;
            }
            path_started = true;
            Some(cursor.target())
        }
        None => {
            let target = aimer.grid_target(&pattern, index)?;
            index += 1;
            Some(target)
        }
    }))
}
