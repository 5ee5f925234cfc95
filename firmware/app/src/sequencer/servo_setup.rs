//! `servo scan|ping|id|zero`: the servo bus set-up commands. Refused
//! while anything runs; otherwise the servo task does the bus work
//! ([`BusJob`], `servo/task/setup.rs`) and reports lines and an end,
//! which become the command's data lines and its closing `ok` /
//! `error:`. `servo zero` writes the firmware's own `yaw.zero_deg` /
//! `pitch.zero_deg` (not the servo's flash): `save` keeps it.

use super::machine::{Action, ActionSink, Core, Pending};
use crate::command::ServoSetup;
use crate::servo::task::{BusEnd, BusJob, BusReport, ServoReading, ServoRequest};
use crate::settings::{ParamSpec, find_param};
use crate::text::Fixed;

/// The reply while a pattern, goto, G-code or homing runs.
const BUSY: &str = "stop the running pattern, goto or G-code before servo set-up";

impl Core {
    /// Starts a `servo …` command (its reply closes when the job ends).
    /// Not inlined, nor is the report handler: their reply lines stay out
    /// of the sequencer task's frame.
    #[inline(never)]
    pub(super) fn servo_setup(&mut self, setup: ServoSetup, out: &mut dyn ActionSink) {
        if self.run.is_some() || !self.gcode.motion.is_idle() || self.stepper_homing {
            return self.error(out, BUSY);
        }
        let job = match setup {
            ServoSetup::Scan => BusJob::Scan,
            ServoSetup::Ping(id) => BusJob::Ping { id },
            ServoSetup::SetId { id, new_id, .. } if id == new_id => {
                return self.error(out, format_args!("servo {id} has id {new_id} already"));
            }
            ServoSetup::SetId {
                id,
                new_id,
                confirmed: false,
            } => {
                self.data(
                    out,
                    format_args!(
                        "would give servo {id} the id {new_id}, only with it alone on the bus; \
                         nothing changed: repeat with confirm"
                    ),
                );
                return self.ok(out);
            }
            ServoSetup::SetId { id, new_id, .. } => BusJob::SetId { id, new_id },
            ServoSetup::Zero(id) => match self.zero_param(id) {
                Some(_) => BusJob::ReadAngle { id },
                None => {
                    return self.error(
                        out,
                        format_args!("servo {id} is neither yaw.id nor pitch.id"),
                    );
                }
            },
        };
        self.next_seq = self.next_seq.wrapping_add(1);
        let seq = self.next_seq;
        self.pending = Some(Pending::ServoBus { seq });
        out.act(Action::Servo(ServoRequest::Setup { seq, job }));
    }

    /// The zero parameter of the axis whose servo has bus id `id`.
    fn zero_param(&self, id: u8) -> Option<&'static ParamSpec> {
        if id == self.settings.yaw.id {
            find_param("yaw.zero_deg")
        } else if id == self.settings.pitch.id {
            find_param("pitch.zero_deg")
        } else {
            None
        }
    }

    /// A line or the end of set-up job `seq` (ignored unless it is the
    /// one pending).
    #[inline(never)]
    pub(super) fn servo_bus_report(
        &mut self,
        seq: u32,
        report: BusReport,
        out: &mut dyn ActionSink,
    ) {
        if !matches!(self.pending, Some(Pending::ServoBus { seq: s }) if s == seq) {
            return;
        }
        match report {
            BusReport::Servo(reading) => self.data(out, format_args!("{}", Reading(reading))),
            BusReport::Collision { id } => self.data(
                out,
                format_args!("servo {id}: garbled answers, more than one servo has this id"),
            ),
            BusReport::Done(end) => {
                self.pending = None;
                self.servo_bus_done(end, out);
            }
        }
    }

    /// Closes the reply of a set-up job that ended with `end`.
    fn servo_bus_done(&mut self, end: BusEnd, out: &mut dyn ActionSink) {
        match end {
            BusEnd::Scanned {
                answering,
                collisions,
            } => {
                self.data(
                    out,
                    format_args!("{answering} ids answering, {collisions} with colliding answers"),
                );
                self.ok(out);
            }
            BusEnd::Answered => self.ok(out),
            BusEnd::IdChanged { id, new_id } => {
                self.data(
                    out,
                    format_args!("servo {id} now answers as {new_id} (stored in the servo)"),
                );
                self.ok(out);
            }
            BusEnd::Angle { id, tenths } => self.set_zero(id, tenths, out),
            BusEnd::NoAnswer { id } => self.error(out, format_args!("servo {id} does not answer")),
            BusEnd::NotAlone {
                answering,
                collisions,
            } => self.error(
                out,
                format_args!(
                    "{answering} ids answer and {collisions} collide: connect only the servo \
                     to re-ID"
                ),
            ),
            BusEnd::WriteFailed { id } => self.error(
                out,
                format_args!("servo {id} did not take the new id (it does not answer as it)"),
            ),
            BusEnd::BusError => self.error(out, "servo bus write failed"),
        }
    }

    /// `servo zero`: servo `id` stands at `tenths` (0.1°); that becomes
    /// its axis's zero_deg (in the settings, range-checked).
    fn set_zero(&mut self, id: u8, tenths: i16, out: &mut dyn ActionSink) {
        let Some(param) = self.zero_param(id) else {
            return self.error(
                out,
                format_args!("servo {id} is neither yaw.id nor pitch.id"),
            );
        };
        let deg = f64::from(tenths) / 10.0;
        if let Err(e) = self.settings.set(param, deg) {
            return self.error(out, e);
        }
        self.geometry_changed();
        self.data(
            out,
            format_args!(
                "{} = {} (servo {id} stands there); save to keep it",
                param.name,
                Fixed::<1>(deg)
            ),
        );
        self.ok(out);
    }
}

/// A scan line: `servo 0: 12.3 deg, 7.40 V, 30 C`.
struct Reading(ServoReading);

impl core::fmt::Display for Reading {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let r = self.0;
        write!(
            f,
            "servo {}: {} deg, {} V, {} C",
            r.id,
            Fixed::<1>(f64::from(r.angle_tenths) / 10.0),
            Fixed::<2>(f64::from(r.voltage_mv) / 1000.0),
            Fixed::<0>(f64::from(celsius(r.temperature_raw))),
        )
    }
}

/// The SDK's conversion of the raw NTC reading (`uservo.py`
/// `response_query_servo_monitor`: B = 3435, 25 °C at half scale), °C.
fn celsius(raw: u16) -> f32 {
    let t = f32::from(raw.clamp(1, 4095));
    1.0 / (libm::logf(t / (4096.0 - t)) / 3435.0 + 1.0 / 298.15) - 273.15
}

#[cfg(test)]
mod tests;
