//! Marking a stroke: the look-ahead path planner's positions through the
//! galvo kinematics to DAC codes, the end of a stroke, and braking along
//! the path when stopped mid-stroke.

use galvo_planner::{MarkLimits, MarkSample, PathPlanner};
use kinematics_core::PointMm;

use super::{GalvoError, GalvoLoop, JUNCTION_DEVIATION_MM, ScanPhase};
use crate::galvo::GalvoEvent;
use crate::galvo::path::{GalvoPath, Segment};

/// The spot while marking or braking: position (mm) and its change over
/// the last sample (mm per sample).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Motion {
    pub(super) position_mm: [f32; 2],
    pub(super) step_mm: [f32; 2],
    /// Speed lost per braking sample, mm per sample (accel · Ts²).
    pub(super) brake_mm: f32,
}

impl GalvoLoop {
    /// DAC codes of a board position (mm).
    fn codes_at(&self, position_mm: [f32; 2]) -> Option<(u16, u16)> {
        let [x_mm, y_mm] = position_mm;
        self.sample_map
            .board_to_codes(x_mm, y_mm)
            .map(|c| (c.x.code, c.y.code))
    }

    /// The next marking sample; at the end of the stroke the mirrors hold
    /// there and the laser-off delay starts.
    pub(super) fn mark_sample(
        &mut self,
        on_event: &mut impl FnMut(GalvoEvent),
    ) -> Option<(u16, u16)> {
        let sample = self.marker.as_mut().map(|m| m.next_sample());
        if let Some(MarkSample::Mark { x_mm, y_mm, .. }) = sample {
            let [px, py] = self.motion.position_mm;
            self.motion = Motion {
                position_mm: [x_mm, y_mm],
                step_mm: [x_mm - px, y_mm - py],
                ..self.motion
            };
            return self.codes_at([x_mm, y_mm]);
        }
        // Stroke done (planner idle): hold at its end, laser off.
        self.marker = None;
        self.hold_at_motion(on_event);
        if let Some(a) = self.active.as_mut() {
            a.enter(ScanPhase::LaserOffDelay, self.off_delay_samples);
        }
        self.codes_at(self.motion.position_mm)
    }

    /// One braking sample: along the last direction, slowing at the
    /// marking acceleration; at rest the mirrors hold and the job ends.
    pub(super) fn brake_sample(&mut self) -> Option<(u16, u16)> {
        let [sx, sy] = self.motion.step_mm;
        // libm's hypotf computes in f64: √ on the FPU instead.
        let speed = kinematics_core::sqrt_f32(sx * sx + sy * sy);
        let slow_by = self.motion.brake_mm;
        let scale = if speed > slow_by {
            (speed - slow_by) / speed
        } else {
            0.0
        };
        let step = [sx * scale, sy * scale];
        let [px, py] = self.motion.position_mm;
        let next = [px + step[0], py + step[1]];
        match self.codes_at(next) {
            Some(codes) if scale > 0.0 => {
                self.motion = Motion {
                    position_mm: next,
                    step_mm: step,
                    ..self.motion
                };
                Some(codes)
            }
            // At rest, or the next step would leave the DAC range: hold.
            _ => {
                self.hold_at_motion(&mut |_| {});
                self.active = None;
                self.codes_at(self.motion.position_mm)
            }
        }
    }

    /// Re-seats the (idle) jump integrator at rest where marking left the
    /// spot, so the next jump starts there.
    fn hold_at_motion(&mut self, on_event: &mut impl FnMut(GalvoEvent)) {
        let [x, y] = self.motion.position_mm;
        let seated = self
            .angles_for(PointMm {
                x_mm: f64::from(x),
                y_mm: f64::from(y),
            })
            .and_then(|angles| {
                self.mirrors
                    .hold_at(angles)
                    .map_err(|_| GalvoError::Planner)
            });
        if let (Err(error), Some(a)) = (seated, self.active) {
            on_event(GalvoEvent::Refused { seq: a.seq, error });
        }
    }

    /// Loads stroke `stroke` of `path` into the path planner and starts
    /// marking; `false` (with `Refused`) when the planner refuses it.
    pub(super) fn start_marking(
        &mut self,
        path: GalvoPath,
        stroke: usize,
        on_event: &mut impl FnMut(GalvoEvent),
    ) -> bool {
        let Some(a) = self.active else { return false };
        let Some((start, segments)) = path.stroke(stroke) else {
            return false;
        };
        let limits = MarkLimits {
            speed_mm_s: self.config.mark_speed_mm_s,
            accel_mm_s2: self.config.mark_accel_mm_s2,
            junction_deviation_mm: JUNCTION_DEVIATION_MM,
            ts_s: self.config.sample_period_s,
        };
        let loaded = PathPlanner::new(limits, start).and_then(|mut planner| {
            for segment in &segments {
                match *segment {
                    Segment::Line(to) => planner.line_to(to)?,
                    Segment::Arc { end, centre, ccw } => planner.arc_to(end, centre, ccw)?,
                }
            }
            Ok(planner)
        });
        match loaded {
            Ok(planner) => {
                self.marker = Some(planner);
                let ts = self.config.sample_period_s;
                self.motion = Motion {
                    position_mm: [start[0] as f32, start[1] as f32],
                    step_mm: [0.0, 0.0],
                    brake_mm: (self.config.mark_accel_mm_s2 * ts * ts) as f32,
                };
                if let Some(a) = self.active.as_mut() {
                    a.enter(ScanPhase::Marking, 0);
                }
                true
            }
            Err(_) => {
                on_event(GalvoEvent::Refused {
                    seq: a.seq,
                    error: GalvoError::Planner,
                });
                false
            }
        }
    }
}
