//! The G-code session at work ([`Session`]): its own state
//! ([`GcodeSession`]) with what it moves on, borrowed from the core for one
//! event — the drivers' G-code state, the settings and geometry, the run it
//! replaces when a job starts, the laser gate it closes, the request
//! numbers. The core hands it lines, realtime commands and the drivers'
//! reports ([`crate::sequencer::machine::Core::session`]); the session
//! answers them and drives the drivers, and does the few things every stop
//! shares with the core's own commands (stop, close the gate, home) here,
//! once, for both.

use crate::domain::{Aim, Aimer, Target};
use crate::grbl::Block;
use crate::log;
use crate::sequencer::drivers::stage::{Stage, StopAsked, stop_galvo};
use crate::sequencer::drivers::{DriverJobs, Drivers, galvo, stepper};
use crate::sequencer::gcode::GcodeSession;
use crate::sequencer::gcode::power::Seen;
use crate::sequencer::gcode::proven::ProvenReach;
use crate::sequencer::gcode::reach::ReachCheck;
use crate::sequencer::io::{Action, ActionSink, Inputs, Line};
use crate::sequencer::laser::{LaserEvent, LaserPower};
use crate::sequencer::run::Run;
use crate::settings::Settings;
use crate::stepper::StepperRequest;

/// The G-code session with what it works on during one event.
pub(in crate::sequencer) struct Session<'a> {
    /// The session's own state: parser, mode, motion queue, overrides.
    pub(in crate::sequencer) gcode: &'a mut GcodeSession,
    /// What each driver keeps of the G-code job.
    pub(in crate::sequencer) jobs: &'a mut DriverJobs,
    /// The product's settings (`$` settings write some of them).
    pub(in crate::sequencer) settings: &'a mut Settings,
    /// Their geometry.
    pub(in crate::sequencer) aimer: &'a Aimer,
    /// The part of the board proven reachable per driver.
    pub(in crate::sequencer) reach: ProvenReach,
    /// The event's inputs (the galvo room counts down as jobs are sent).
    pub(in crate::sequencer) inputs: &'a mut Inputs,
    /// Request number of the last servo move or galvo job.
    pub(in crate::sequencer) next_seq: &'a mut u32,
    /// The product's run (a pattern or goto): a G-code job replaces it,
    /// a stop ends it.
    pub(in crate::sequencer) run: &'a mut Option<Run>,
    /// Last aim sent to the servos.
    pub(in crate::sequencer) last_aim: &'a mut Option<(Target, Aim)>,
    /// Last measured servo angles, 0.1°.
    pub(in crate::sequencer) measured: Option<(i16, i16)>,
    /// The driver(s) that draw.
    pub(in crate::sequencer) drivers: Drivers,
    /// The gate was closed by someone else since it was last closed here.
    pub(in crate::sequencer) gate_lost: &'a mut bool,
    /// The stepper task homes (`home` or `$H` sent, its end not reported).
    pub(in crate::sequencer) stepper_homing: &'a mut bool,
    /// The gimbal laser's power when it is on (status reports).
    pub(in crate::sequencer) laser: Option<LaserPower>,
    /// The laser controls' door substate (`None`: not held by them).
    pub(in crate::sequencer) door: Option<u8>,
}

impl Session<'_> {
    /// The driver(s) that draw.
    pub(in crate::sequencer) fn drivers(&self) -> Drivers {
        self.drivers
    }

    /// Whether `block` is within grbl's soft limits for the drivers that
    /// draw ([`ReachCheck::block`]).
    pub(in crate::sequencer) fn block_reachable(&self, block: &Block) -> bool {
        ReachCheck::new(self.settings, self.aimer).block(block, self.drivers, self.reach)
    }

    /// What the session's reports see of the rest.
    pub(in crate::sequencer) fn seen(&self) -> Seen<'_> {
        Seen {
            settings: self.settings,
            jobs: self.jobs,
            drivers: self.drivers,
            laser: self.laser,
            stepper_homing: *self.stepper_homing,
            door: self.door,
        }
    }

    /// Runs `stage` on the drivers' state with a [`Stage`] of what they
    /// may move on; then a stop it asked for is done ([`Stage::stop`]:
    /// a galvo job found no room, a point out of reach, …), and an alarm
    /// it raised is raised.
    pub(in crate::sequencer) fn with_stage<R>(
        &mut self,
        out: &mut dyn ActionSink,
        stage: impl FnOnce(&mut Stage, &mut DriverJobs, &mut dyn ActionSink) -> R,
    ) -> R {
        let mut st = Stage {
            gcode: self.gcode,
            settings: self.settings,
            aimer: self.aimer,
            inputs: self.inputs,
            next_seq: self.next_seq,
            run: self.run,
            last_aim: self.last_aim,
            measured: self.measured,
            drivers: self.drivers,
            alarm: None,
            stop: None,
        };
        let result = stage(&mut st, self.jobs, out);
        let (alarm, stop) = (st.alarm, st.stop);
        if let Some(StopAsked { notice, why }) = stop {
            if let Some(text) = notice {
                out.act(Action::Line(Line::Notice(text)));
            }
            self.stop(why, out);
        }
        if let Some(alarm) = alarm {
            self.alarm(alarm, out);
        }
        result
    }

    /// Stops whatever runs — and, whatever is thought to run, the laser
    /// and the galvo loop: the gate closes at once and the loop gets
    /// `Stop`; the product's run ends, the G-code queue is dropped.
    pub(in crate::sequencer) fn stop(&mut self, why: &'static str, out: &mut dyn ActionSink) {
        out.act(Action::Note(LaserEvent::Stopped { why }));
        self.close_gate(out);
        stepper::points::stop(self.drivers, out);
        if let Some(run) = self.run.take() {
            log::info!("stop {} ({})", run.kind.name(), why);
        }
        self.abort(out);
    }

    /// Closes the master laser gate (laser dark from now on, also samples
    /// the galvo DAC already holds) and stops the galvo loop.
    pub(in crate::sequencer) fn close_gate(&mut self, out: &mut dyn ActionSink) {
        out.act(Action::CloseGate);
        *self.gate_lost = false;
        stop_galvo(self.inputs, out);
    }

    /// `home` / `$H` on the stepper: any run stops (laser dark), then the
    /// stepper task homes the axes with switches; `homed: …` or `error:
    /// home failed: …` follows. Errors: [`stepper::points::can_home`].
    pub(in crate::sequencer) fn start_homing(
        &mut self,
        out: &mut dyn ActionSink,
    ) -> Result<(), &'static str> {
        stepper::points::can_home(self.drivers, self.settings)?;
        self.stop("home", out);
        out.act(Action::Stepper(StepperRequest::Home));
        *self.stepper_homing = true;
        Ok(())
    }

    /// Sends the galvo loop the parameters of the settings.
    pub(in crate::sequencer) fn configure_galvo(&mut self, out: &mut dyn ActionSink) {
        galvo::points::configure(self.settings, *self.run, self.inputs, out);
    }
}
