//! The sequencer's side of the galvo: points to the galvo loop, its
//! events back, and its status.

use core::sync::atomic::Ordering;

use super::targets::{self, Target};
use super::{LaserSwitch, Phase, Sequencer, SettingsStore};
use crate::galvo::{GALVO_OUTPUT, GalvoEvent, GalvoRequest, config_from};
use crate::log;
use crate::settings::LaserMode;
use crate::text::Shortest;

/// Dwell of a goto on the galvo: held until the next command, µs.
const HOLD_US: u32 = u32::MAX;

impl<L: LaserSwitch, S: SettingsStore> Sequencer<'_, L, S> {
    /// Tells the galvo loop to stop (drop its jobs, laser off, clear an
    /// underrun latch). Never lost: requests it has not taken yet are
    /// dropped first, so there is room.
    pub(super) fn stop_galvo(&mut self) {
        if let Some(galvo) = self.galvo.filter(|_| GALVO_OUTPUT) {
            while galvo.requests.try_receive().is_ok() {}
            let _ = galvo.requests.try_send(GalvoRequest::Stop);
        }
    }

    /// Queues a job for the galvo loop; `false` (with an error notice,
    /// everything stopped) when the loop does not keep up.
    fn send_galvo(&mut self, request: GalvoRequest) -> bool {
        let Some(galvo) = self.galvo else {
            return false;
        };
        if galvo.requests.try_send(request).is_ok() {
            return true;
        }
        log::warning!("galvo: request queue full");
        self.link
            .notify(format_args!("error: galvo not responding; stopped"));
        self.stop("galvo not responding");
        false
    }

    /// Sends the galvo job built for the next request number and makes
    /// it the run's job in flight.
    fn send_galvo_job(&mut self, job: impl FnOnce(u32) -> GalvoRequest) -> bool {
        self.next_seq = self.next_seq.wrapping_add(1);
        let seq = self.next_seq;
        if !self.send_galvo(job(seq)) {
            return false;
        }
        if let Some(run) = self.run.as_mut() {
            run.galvo_seq = seq;
        }
        true
    }

    /// Sends the current grid or goto point to the galvo (board cm →
    /// galvo mm). Paths go whole, through [`Self::begin_galvo_path`].
    pub(super) fn begin_galvo_point(&mut self, target: Target) -> bool {
        self.allow_galvo_laser();
        let Some(run) = self.run else { return false };
        let dwell_us = match run.pattern {
            None => HOLD_US,
            Some(_) => (self.settings.dwell_ms * 1000.0) as u32,
        };
        let sent = self.send_galvo_job(|seq| GalvoRequest::Point {
            seq,
            x_mm: (target.point.x_cm * 10.0) as f32,
            y_mm: (target.point.y_cm * 10.0) as f32,
            dwell_us,
        });
        if !sent {
            return false;
        }
        log::info!(
            "galvo target ({}, {}) cm",
            target.point.x_cm,
            target.point.y_cm
        );
        true
    }

    /// Sends the running path pattern to the galvo as one job.
    pub(super) fn begin_galvo_path(&mut self) {
        self.allow_galvo_laser();
        let path = self
            .run
            .and_then(|r| r.pattern)
            .and_then(|p| targets::galvo_path(&p));
        let Some(path) = path else {
            self.stop("not a path");
            return;
        };
        if !self.send_galvo_job(|seq| GalvoRequest::Path { seq, path }) {
            return;
        }
        if let Some(run) = self.run.as_mut() {
            run.galvo_busy = true;
            run.gimbal_busy = false;
            run.phase = Phase::Moving;
            run.dwell_until = None;
        }
        log::info!("galvo marks the path");
        self.publish();
    }

    /// Handles an event of the galvo loop.
    pub(super) fn handle_galvo_event(&mut self, event: GalvoEvent) {
        match event {
            GalvoEvent::Done { seq } => {
                if let Some(run) = self.run.as_mut().filter(|r| r.galvo_seq == seq) {
                    run.galvo_busy = false;
                    self.point_finished_if_done();
                }
            }
            GalvoEvent::Refused { seq, error } => {
                if self.run.is_some_and(|r| r.galvo_seq == seq) {
                    self.link
                        .notify(format_args!("error: galvo: {error}; stopped"));
                    self.stop("galvo refused the point");
                }
            }
            GalvoEvent::Underrun(underrun) => {
                self.link.notify(format_args!(
                    "error: galvo underrun ({} half buffers late); stopped, laser off",
                    underrun.halves
                ));
                self.stop("galvo underrun");
            }
            GalvoEvent::ConfigRefused(error) => {
                self.link.notify(format_args!(
                    "error: galvo parameters refused: {error}; previous ones kept"
                ));
            }
        }
    }

    /// Sends the galvo parameters to the loop (applied between points).
    pub(super) fn configure_galvo(&mut self) {
        if let Some(galvo) = self.galvo {
            galvo.config.signal(config_from(&self.settings.galvo));
        }
        self.allow_galvo_laser();
    }

    /// Tells the galvo loop whether the laser mode lets it light (`laser
    /// off`: it still moves, dark). `laser off` also shuts the gate, so
    /// the halves the loop computed before it (up to three, 384 ms at
    /// 1 ms per sample) go dark at once too; the run goes on and lights
    /// again after `laser auto`.
    /// `laser dwell` lights only dwells: a marked path (which has none)
    /// stays dark, like the gimbal's.
    pub(super) fn allow_galvo_laser(&self) {
        if let Some(galvo) = self.galvo {
            let marking = self
                .run
                .is_some_and(|r| r.pattern.is_some_and(|p| p.is_path()));
            let allowed = match self.settings.laser_mode {
                LaserMode::Off => false,
                LaserMode::Dwell => !marking,
                LaserMode::Auto => true,
            };
            galvo.allow_laser(allowed);
            if !allowed {
                self.gate.shut();
            }
        }
    }

    /// `galvo status` lines.
    pub(super) fn report_galvo_status(&self) {
        let link = self.link;
        let Some(galvo) = self.galvo else {
            link.data(format_args!("galvo: not in this build"));
            return;
        };
        let (phase, queued) = galvo.state();
        let g = &self.settings.galvo;
        link.data(format_args!("galvo: {phase:?}, {queued} points queued"));
        link.data(format_args!(
            "planner: {}, sample period {} us",
            g.planner.name(),
            Shortest(g.sample_period_us)
        ));
        link.data(format_args!(
            "underruns: {}, half buffers: {}",
            galvo.underruns.load(Ordering::Relaxed),
            galvo.halves.load(Ordering::Relaxed)
        ));
    }
}
