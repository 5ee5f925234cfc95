//! The galvo driver's points: a pattern's points, goto and marked paths, its configuration.

use crate::domain::{Pattern, Target};
use crate::galvo::{GalvoEvent, GalvoRequest};
use crate::log;
use crate::sequencer::drivers::galvo::{HOLD_US, config_from};
use crate::sequencer::drivers::stage::{stop_galvo, try_send_galvo};
use crate::sequencer::machine::{Action, ActionSink, Core, GalvoReadout};
use crate::sequencer::run::RunKind;
use crate::settings::LaserMode;
use crate::status::Phase;
use crate::text::Shortest;

impl Core {
    /// Tells the galvo loop to stop ([`stop_galvo`]).
    pub(in crate::sequencer) fn stop_galvo(&mut self, out: &mut dyn ActionSink) {
        stop_galvo(&mut self.inputs, out);
    }

    /// Queues a job for the galvo loop; `false` (with an error notice,
    /// everything stopped) when the loop does not keep up.
    pub(in crate::sequencer) fn send_galvo(
        &mut self,
        request: GalvoRequest,
        out: &mut dyn ActionSink,
    ) -> bool {
        let sent = try_send_galvo(&mut self.inputs, request, out);
        if !sent {
            self.galvo_stalled(out);
        }
        sent
    }

    /// The galvo loop does not keep up (a job found no room): an error
    /// notice, everything stopped.
    pub(in crate::sequencer) fn galvo_stalled(&mut self, out: &mut dyn ActionSink) {
        self.notify(out, format_args!("error: galvo not responding; stopped"));
        self.stop("galvo not responding", out);
    }

    /// Sends the galvo job built for the next request number and makes
    /// it the run's job in flight.
    fn send_galvo_job(
        &mut self,
        job: impl FnOnce(u32) -> GalvoRequest,
        out: &mut dyn ActionSink,
    ) -> bool {
        self.next_seq = self.next_seq.wrapping_add(1);
        let seq = self.next_seq;
        if !self.send_galvo(job(seq), out) {
            return false;
        }
        if let Some(run) = self.run.as_mut() {
            run.galvo_seq = seq;
        }
        true
    }

    /// Sends the current grid or goto point to the galvo (board cm →
    /// galvo mm). Paths go whole, through [`Self::begin_galvo_path`].
    pub(in crate::sequencer) fn begin_galvo_point(
        &mut self,
        target: Target,
        out: &mut dyn ActionSink,
    ) -> bool {
        self.allow_galvo_laser(out);
        let Some(run) = self.run else { return false };
        let dwell_us = match run.kind {
            RunKind::Goto(_) => HOLD_US,
            _ => (self.settings.dwell_ms * 1000.0) as u32,
        };
        let [x_mm, y_mm] = target.point.galvo_mm();
        let job = |seq| GalvoRequest::Point {
            seq,
            x_mm,
            y_mm,
            dwell_us,
        };
        if !self.send_galvo_job(job, out) {
            return false;
        }
        log::info!(
            "galvo target ({}, {}) cm",
            target.point.x_cm,
            target.point.y_cm
        );
        true
    }

    /// Sends path `pattern` of the run to the galvo as one job.
    pub(in crate::sequencer) fn begin_galvo_path(
        &mut self,
        pattern: Pattern,
        out: &mut dyn ActionSink,
    ) {
        self.allow_galvo_laser(out);
        let Some(path) = pattern.figure() else {
            self.stop("not a path", out);
            return;
        };
        if !self.send_galvo_job(
            |seq| GalvoRequest::Path {
                seq,
                path,
                mark_speed_mm_s: None,
            },
            out,
        ) {
            return;
        }
        if let Some(run) = self.run.as_mut() {
            run.galvo_busy = true;
            run.gimbal_busy = false;
            run.phase = Phase::Moving;
            run.dwell_until = None;
        }
        log::info!("galvo marks the path");
    }

    /// Handles an event of the galvo loop.
    pub(in crate::sequencer) fn galvo_event(
        &mut self,
        event: GalvoEvent,
        out: &mut dyn ActionSink,
    ) {
        match event {
            GalvoEvent::Done { seq } if self.gcode_galvo_done(seq, out) => {}
            GalvoEvent::Refused { seq, error } if self.gcode_awaits_galvo(seq) => {
                self.notify(out, format_args!("MSG:galvo: {error}"));
                self.grbl_alarm(crate::grbl::Alarm::SoftLimit, out);
            }
            GalvoEvent::Done { seq } => {
                if let Some(run) = self.run.as_mut().filter(|r| r.galvo_seq == seq) {
                    run.galvo_busy = false;
                    self.point_finished_if_done(out);
                }
            }
            GalvoEvent::Refused { seq, error } => {
                if self.run.is_some_and(|r| r.galvo_seq == seq) {
                    self.notify(out, format_args!("error: galvo: {error}; stopped"));
                    self.stop("galvo refused the point", out);
                }
            }
            GalvoEvent::Underrun(underrun) => {
                // Told only when it stops something: an underrun of a loop
                // already parked (after the stop an earlier underrun made,
                // or a `stop`) would say "stopped" of a run that had
                // stopped before it (counted in `status` all the same).
                if self.run.is_some() || !self.gcode.motion.is_idle() {
                    self.notify(
                        out,
                        format_args!(
                            "error: galvo underrun ({} half buffers late); stopped, laser off",
                            underrun.halves
                        ),
                    );
                }
                self.stop("galvo underrun", out);
            }
            GalvoEvent::Stopped(at) => self.gcode_galvo_stopped(at, out),
            GalvoEvent::ConfigRefused(error) => {
                self.notify(
                    out,
                    format_args!("error: galvo parameters refused: {error}; previous ones kept"),
                );
            }
        }
    }

    /// Sends the galvo parameters to the loop (applied between points).
    pub(in crate::sequencer) fn configure_galvo(&mut self, out: &mut dyn ActionSink) {
        let settings = &self.settings;
        let config = config_from(&settings.galvo, settings.gcode_junction_mm);
        out.act(Action::ConfigureGalvo(config));
        self.allow_galvo_laser(out);
    }

    /// Tells the galvo loop whether the laser mode lets it light (`laser
    /// off`: it still moves, dark). `laser off` also shuts the gate (where
    /// a galvo loop runs), so
    /// the halves the loop computed before it (up to three, 384 ms at
    /// 1 ms per sample) go dark at once too; the run goes on and lights
    /// again after `laser auto`.
    /// `laser dwell` lights only dwells: a marked path (which has none)
    /// stays dark, like the gimbal's.
    pub(in crate::sequencer) fn allow_galvo_laser(&self, out: &mut dyn ActionSink) {
        let marking = self
            .run
            .is_some_and(|r| r.kind.pattern().is_some_and(|p| p.is_path()));
        let allowed = match self.settings.laser_mode {
            LaserMode::Off => false,
            LaserMode::Dwell => !marking,
            LaserMode::Auto => true,
        };
        out.act(Action::AllowGalvoLaser(allowed));
        // Only a galvo loop computes halves ahead.
        if !allowed && self.inputs.galvo_room.is_some() {
            out.act(Action::ShutGate);
        }
    }

    /// `galvo status` lines.
    pub(in crate::sequencer) fn report_galvo_status(
        &self,
        galvo: &GalvoReadout,
        out: &mut dyn ActionSink,
    ) {
        let g = &self.settings.galvo;
        let (phase, queued) = (galvo.phase, galvo.queued);
        self.data(
            out,
            format_args!("galvo: {phase:?}, {queued} points queued"),
        );
        self.data(
            out,
            format_args!(
                "planner: {}, sample period {} us",
                g.planner.name(),
                Shortest(g.sample_period_us)
            ),
        );
        self.data(
            out,
            format_args!(
                "underruns: {}, half buffers: {}",
                galvo.underruns, galvo.halves
            ),
        );
        if let Some(t) = galvo.refill {
            let us = |cycles: u32| u64::from(cycles) * 1_000_000 / u64::from(t.cpu_hz.max(1));
            let percent = u64::from(t.cycles) * 100 / u64::from(t.window_cycles.max(1));
            self.data(
                out,
                format_args!(
                    "worst refill: {} cycles = {} us, {} % of the {} us half",
                    t.cycles,
                    us(t.cycles),
                    percent,
                    us(t.window_cycles)
                ),
            );
        }
    }
}
