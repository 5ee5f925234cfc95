//! What a driver is handed when it works ([`Stage`]): the session's
//! state its G-code stage reads and moves on (motion queue, overrides,
//! grbl values), the run its points belong to, the settings and
//! geometry, the event's inputs and the request numbers. The drivers'
//! G-code stages are methods of their own state (the galvo's
//! `GalvoStroke`, the gimbal's `Stream`, the stepper's `StepperJob`), their
//! point runs functions of their modules, all taking a `Stage`; what only
//! the session or the core does after them (answer a line waiting for
//! room, raise an alarm, stop) they return or note in it, and the core
//! does it.

use crate::domain::{Aim, Aimer, Target};
use crate::galvo::{GALVO_REQUEST_DEPTH, GalvoRequest};
use crate::grbl::{Alarm, Block};
use crate::log;
use crate::sequencer::drivers::Drivers;
use crate::sequencer::gcode::GcodeSession;
use crate::sequencer::io::{Action, ActionSink, Inputs};
use crate::sequencer::run::Run;
use crate::settings::Settings;
use crate::text::{ReplyText, reply_text};

/// A driver's view of the sequencer for one call of its G-code stage.
pub(in crate::sequencer) struct Stage<'a> {
    /// The G-code session: parser, motion queue, overrides, grbl values.
    pub(in crate::sequencer) gcode: &'a mut GcodeSession,
    /// The product's settings.
    pub(in crate::sequencer) settings: &'a Settings,
    /// Their geometry (aiming the gimbal and the stepper).
    pub(in crate::sequencer) aimer: &'a Aimer,
    /// The event's inputs (the galvo room counts down as jobs are sent).
    pub(in crate::sequencer) inputs: &'a mut Inputs,
    /// Request number of the last servo move or galvo job.
    pub(in crate::sequencer) next_seq: &'a mut u32,
    /// The driver(s) that draw.
    pub(in crate::sequencer) drivers: Drivers,
    /// The active pattern or goto.
    pub(in crate::sequencer) run: &'a mut Option<Run>,
    /// Last aim sent to the servos.
    pub(in crate::sequencer) last_aim: &'a mut Option<(Target, Aim)>,
    /// Last measured servo angles, 0.1°.
    pub(in crate::sequencer) measured: Option<(i16, i16)>,
    /// An alarm the stage raised (a point out of reach): the core raises
    /// it once the stage returns.
    pub(in crate::sequencer) alarm: Option<Alarm>,
    /// A stop the stage asks for, done once it returns (everything stops
    /// when a galvo job found no room: the loop does not keep up).
    pub(in crate::sequencer) stop: Option<StopAsked>,
}

/// A stop a driver's stage asks for: its notice line (if any), then
/// everything stops for `why`.
#[derive(Debug, Clone)]
pub(in crate::sequencer) struct StopAsked {
    /// The notice line that says why, sent before the stop.
    pub(in crate::sequencer) notice: Option<ReplyText>,
    /// The stop's cause (the laser event's and the log's).
    pub(in crate::sequencer) why: &'static str,
}

impl Stage<'_> {
    /// The next request number.
    pub(in crate::sequencer) fn take_seq(&mut self) -> u32 {
        *self.next_seq = self.next_seq.wrapping_add(1);
        *self.next_seq
    }

    /// Where the servos are, 0.1° (yaw, pitch): as last measured, else as
    /// last aimed.
    pub(in crate::sequencer) fn servo_at(&self) -> Option<(i16, i16)> {
        (self.measured).or(self.last_aim.map(|(_, a)| (a.yaw_wire, a.pitch_wire)))
    }

    /// Whether `block` lights the laser (a lit G1/G2/G3).
    pub(in crate::sequencer) fn lights(&self, block: &Block) -> bool {
        match *block {
            Block::Line { laser, .. } | Block::Arc { laser, .. } => {
                self.gcode.lit(laser.mode, laser.power, self.settings)
            }
            _ => false,
        }
    }

    /// Tells the galvo loop to stop ([`stop_galvo`]).
    pub(in crate::sequencer) fn stop_galvo(&mut self, out: &mut dyn ActionSink) {
        stop_galvo(self.inputs, out);
    }

    /// Queues a job for the galvo loop; `false` when the loop does not
    /// keep up (then everything stops, with an error notice: [`Self::stop`]).
    pub(in crate::sequencer) fn send_galvo(
        &mut self,
        request: GalvoRequest,
        out: &mut dyn ActionSink,
    ) -> bool {
        let sent = try_send_galvo(self.inputs, request, out);
        if !sent {
            let notice = reply_text(format_args!("error: galvo not responding; stopped"));
            self.stop = Some(StopAsked {
                notice: Some(notice),
                why: "galvo not responding",
            });
        }
        sent
    }
}

/// Tells the galvo loop to stop (drop its jobs, laser off, clear an
/// underrun latch). Never lost: the requests it has not taken yet are
/// dropped first, so there is room.
pub(in crate::sequencer) fn stop_galvo(inputs: &mut Inputs, out: &mut dyn ActionSink) {
    out.act(Action::Galvo(GalvoRequest::Stop));
    if inputs.galvo_room.is_some() {
        inputs.galvo_room = Some(GALVO_REQUEST_DEPTH - 1);
    }
}

/// Queues a job for the galvo loop when its queue has room; `false`
/// (logged) when the loop does not keep up.
pub(in crate::sequencer) fn try_send_galvo(
    inputs: &mut Inputs,
    request: GalvoRequest,
    out: &mut dyn ActionSink,
) -> bool {
    let Some(room) = inputs.galvo_room.filter(|room| *room > 0) else {
        log::warning!("galvo: request queue full");
        return false;
    };
    inputs.galvo_room = Some(room - 1);
    out.act(Action::Galvo(request));
    true
}
