//! Both axes of the pan/tilt: the drivers, the edges they saw, and the
//! spot of their counted steps.

use kinematics_core::frames::BoardPoint;
use kinematics_core::gimbal::{Gimbal, GimbalGeometry, GimbalModel, JointAngles};
use kinematics_core::stepper::StepperAxis;

use super::axis::{AxisDriver, DriverTiming, MotorLimits};

/// Pan and tilt geometry for the spot: the exact gimbal model with its OL
/// and the two axes' microstep mappings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepperGeometry {
    /// The gimbal (exact model, OL = 0 for the seed's pan/tilt).
    pub gimbal: Gimbal,
    /// Pan (yaw) and tilt (pitch) microstep mappings.
    pub axes: [StepperAxis; 2],
    /// Joint angles at step position 0, degrees (the zero offsets).
    pub zero: JointAngles,
}

impl Default for StepperGeometry {
    /// The seed's pan/tilt: OL = 0, 0.05625° per microstep, zero at the
    /// board centre.
    fn default() -> Self {
        Self {
            gimbal: Gimbal {
                model: GimbalModel::Exact,
                geometry: GimbalGeometry {
                    ol_cm: 0.0,
                    ..GimbalGeometry::default()
                },
            },
            axes: [StepperAxis::default(); 2],
            zero: JointAngles::default(),
        }
    }
}

impl StepperGeometry {
    /// Joint angles of the step positions `[pan, tilt]`, degrees.
    pub fn joints(&self, steps: [i64; 2]) -> Option<JointAngles> {
        let angle = |i: usize| {
            let s = i32::try_from(steps[i]).ok()?;
            self.axes[i].steps_to_angle(s).ok()
        };
        Some(JointAngles {
            yaw_deg: self.zero.yaw_deg + angle(0)?,
            pitch_deg: self.zero.pitch_deg + angle(1)?,
        })
    }

    /// Where the spot of the step positions `[pan, tilt]` is on the board,
    /// cm; `None` when the beam misses the board.
    pub fn spot_cm(&self, steps: [i64; 2]) -> Option<BoardPoint> {
        self.gimbal.fk(self.joints(steps)?).ok()
    }
}

/// One pin edge, for `--steps FILE.csv`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StepEdge {
    /// When, ns.
    pub t_ns: u64,
    /// 0 = pan, 1 = tilt.
    pub axis: u8,
    /// Which pin.
    pub pin: StepPin,
    /// The new level.
    pub high: bool,
}

/// A stepper driver input.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepPin {
    /// STEP.
    Step,
    /// DIR (high = negative).
    Dir,
}

/// Both axes' drivers and every edge they saw.
#[derive(Debug, Clone)]
pub struct PanTiltDrivers {
    /// Pan (yaw) and tilt (pitch).
    pub axes: [AxisDriver; 2],
    /// Every edge, in order.
    pub edges: Vec<StepEdge>,
    /// ENABLE changes: (ns, enabled).
    pub enable: Vec<(u64, bool)>,
}

impl PanTiltDrivers {
    /// Two drivers with the same timing and motor.
    pub fn new(timing: DriverTiming, limits: MotorLimits) -> Self {
        Self {
            axes: [
                AxisDriver::new(timing, limits),
                AxisDriver::new(timing, limits),
            ],
            edges: Vec::new(),
            enable: Vec::new(),
        }
    }

    /// Applies and records an edge (`axis` 0 or 1; others are ignored).
    pub fn edge(&mut self, e: StepEdge) {
        let Some(axis) = self.axes.get_mut(usize::from(e.axis)) else {
            return;
        };
        match e.pin {
            StepPin::Step => axis.set_step(e.high, e.t_ns),
            StepPin::Dir => axis.set_dir(e.high, e.t_ns),
        }
        self.edges.push(e);
    }

    /// Counted positions `[pan, tilt]`, microsteps.
    pub fn counted_steps(&self) -> [i64; 2] {
        [self.axes[0].counted_steps(), self.axes[1].counted_steps()]
    }

    /// Whether any axis stalled.
    pub fn stalled(&self) -> bool {
        self.axes.iter().any(|a| !a.stalls().is_empty())
    }

    /// The edges as CSV `t_ns,axis,pin,level` (axis `pan`/`tilt`, pin
    /// `step`/`dir`, level 0/1).
    pub fn edges_csv(&self) -> String {
        let mut out = String::from("t_ns,axis,pin,level\n");
        for e in &self.edges {
            let axis = if e.axis == 0 { "pan" } else { "tilt" };
            let pin = match e.pin {
                StepPin::Step => "step",
                StepPin::Dir => "dir",
            };
            out.push_str(&format!("{},{axis},{pin},{}\n", e.t_ns, u8::from(e.high)));
        }
        out
    }

    /// A one-paragraph report: counts, timing, stalls.
    pub fn report(&self) -> String {
        let mut out = String::new();
        for (name, a) in ["pan", "tilt"].iter().zip(&self.axes) {
            let v = a.violations();
            out.push_str(&format!(
                "stepper {name}: {} steps counted, peak {:.0} steps/s, timing violations {} \
                 (short high {}, short low {}, DIR setup {}, DIR while high {})",
                a.counted_steps(),
                a.peak_rate_steps_per_s(),
                v.total(),
                v.short_high,
                v.short_low,
                v.dir_setup,
                v.dir_while_high,
            ));
            match a.stalls().first() {
                Some(s) => out.push_str(&format!(
                    "; STALL at {:.3} ms (step {}, lag {:.1} steps, {:.0} steps/s), \
                     {} pole slips, {} steps lost\n",
                    s.at_ns as f64 * 1e-6,
                    s.commanded_steps,
                    s.lag_steps,
                    s.commanded_rate_steps_per_s,
                    a.stalls().len(),
                    a.lost_steps(),
                )),
                None => out.push_str("; no stall\n"),
            }
        }
        out
    }
}
