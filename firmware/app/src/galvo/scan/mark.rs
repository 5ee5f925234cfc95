//! Marking a stroke: the look-ahead path planner's positions through the
//! galvo kinematics to DAC codes, the end of a stroke, and braking along
//! the path when stopped mid-stroke.

use kinematics_core::PointMm;

use super::runs::{BLOCK, write_codes};
use super::state::Motion;
use super::{GalvoError, GalvoLoop, ScanPhase};
use crate::domain::{Figure, Unit};
use crate::galvo::dac::DacSample;
use crate::galvo::link::GalvoEvent;

impl GalvoLoop {
    /// DAC codes of a board position (mm).
    fn codes_at(&self, position_mm: [f32; 2]) -> Option<(u16, u16)> {
        let [x_mm, y_mm] = position_mm;
        self.sample_map
            .board_to_codes(x_mm, y_mm)
            .map(|c| (c.x.code, c.y.code))
    }

    /// Marking, laser on: the running stroke's samples through the galvo
    /// IK to DAC codes until `out` is full or the stroke ends. The end
    /// (mirrors held there, laser off) is the laser-off delay's first
    /// sample. Returns how many samples it wrote.
    pub(super) fn mark_run(
        &mut self,
        out: &mut [DacSample],
        on_event: &mut impl FnMut(GalvoEvent),
    ) -> usize {
        let mut points = [[0.0f32; 2]; BLOCK];
        let mut codes = [[0u16; 2]; BLOCK];
        let mut last = [self.last.x_code, self.last.y_code];
        let [mut prev, mut position] = [self.motion.position_mm; 2];
        let mut n = 0;
        // Planner blocks left after these samples.
        let mut left = 0;
        if let Some(stroke) = self
            .steps
            .get_mut(0)
            .filter(|_| self.running)
            .and_then(|step| step.marker.as_mut())
            .and_then(|m| m.as_mut().ok())
        {
            for chunk in out.chunks_mut(BLOCK) {
                let points = points.get_mut(..chunk.len()).unwrap_or_default();
                let got = galvo_planner::blocks::fill_marks(stroke, points);
                let points = points.get(..got).unwrap_or_default();
                // Marked positions stay inside the checked range; on a
                // conversion error the last codes hold.
                last = self.sample_map.board_block(points, &mut codes, last);
                write_codes(chunk, &codes[..got.min(BLOCK)], true);
                if let [.., before, end] = points {
                    (prev, position) = (*before, *end);
                } else if let [end] = points {
                    (prev, position) = (position, *end);
                }
                n += got;
                if got < chunk.len() {
                    break;
                }
            }
            left = stroke.len();
        }
        self.reach_joined(left, on_event);
        self.last = DacSample {
            x_code: last[0],
            y_code: last[1],
            laser: n > 0 || self.last.laser,
        };
        self.motion.position_mm = position;
        if n > 0 {
            self.motion.step_mm = [position[0] - prev[0], position[1] - prev[1]];
        }
        let n = match out.get_mut(n..) {
            Some(rest) if !rest.is_empty() => n + self.end_stroke(rest, on_event),
            _ => n,
        };
        self.work.marked += n as u32;
        n
    }

    /// The stroke is done (planner idle): the mirrors hold at its end,
    /// laser off, and the laser-off delay starts with this sample. The
    /// sampler landed exactly on the stroke's end (in f32), whose angles
    /// the prep stage computed: no f64 IK here.
    fn end_stroke(
        &mut self,
        out: &mut [DacSample],
        on_event: &mut impl FnMut(GalvoEvent),
    ) -> usize {
        let seated = self.mirrors.hold_at(self.active_end_rad);
        if let (Err(_), Some(a)) = (seated, self.active) {
            on_event(GalvoEvent::Refused {
                seq: a.seq,
                error: GalvoError::Planner,
            });
        }
        if let Some(a) = self.active.as_mut() {
            // This sample is the delay's first.
            a.enter(
                ScanPhase::LaserOffDelay,
                self.off_delay_samples.saturating_sub(1),
            );
        }
        let codes = self.codes_at(self.motion.position_mm);
        self.emit(out, codes, false)
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
                self.hold_at_motion();
                self.active = None;
                self.codes_at(self.motion.position_mm)
            }
        }
    }

    /// Re-seats the (idle) jump integrator at rest where braking left the
    /// spot, so the next jump starts there.
    /// Braking ended off the planned path: the angles come from the
    /// galvo IK (f64, once per stop). Left as it was when they cannot be
    /// computed (the spot stayed inside the checked range).
    fn hold_at_motion(&mut self) {
        let [x, y] = self.motion.position_mm;
        if let Ok(angles) = self.angles_for(PointMm {
            x_mm: f64::from(x),
            y_mm: f64::from(y),
        }) {
            let _ = self.mirrors.hold_at(angles);
        }
    }

    /// Starts marking stroke `stroke` of `path` with the path planner the
    /// prep stage loaded for it; `false` (with `Refused`) when the planner
    /// refused the stroke.
    pub(super) fn start_marking(
        &mut self,
        path: Figure,
        stroke: usize,
        on_event: &mut impl FnMut(GalvoEvent),
    ) -> bool {
        let Some(a) = self.active else { return false };
        let Some(stroke) = path.stroke(stroke, Unit::GalvoMm) else {
            return false;
        };
        let start = stroke.start;
        // Every path step is prepared with its stroke; none would be a
        // lost plan: refused, never marked without one.
        let loaded = match self.steps.get(0).filter(|_| self.running) {
            Some(step) => match &step.marker {
                Some(Ok(_)) => Ok(()),
                Some(Err(error)) => Err(*error),
                None => Err(GalvoError::Planner),
            },
            None => Err(GalvoError::Planner),
        };
        match loaded {
            Ok(()) => {
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
            Err(error) => {
                on_event(GalvoEvent::Refused { seq: a.seq, error });
                false
            }
        }
    }
}
