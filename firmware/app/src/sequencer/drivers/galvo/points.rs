//! The galvo driver's points: a pattern's points, goto and marked paths,
//! what its loop's reports ask of the core, its configuration and status.

use crate::domain::{Pattern, Target};
use crate::galvo::{GalvoEvent, GalvoRequest};
use crate::log;
use crate::sequencer::drivers::Said;
use crate::sequencer::drivers::galvo::{HOLD_US, config_from};
use crate::sequencer::drivers::stage::{Stage, StopAsked};
use crate::sequencer::io::{Action, ActionSink, GalvoReadout, Inputs, Line};
use crate::sequencer::run::{Run, RunKind};
use crate::settings::{LaserMode, Settings};
use crate::status::Phase;
use crate::text::{Shortest, reply_text};

/// Sends the galvo job built for the next request number and makes it
/// the run's job in flight.
fn send_job(
    st: &mut Stage,
    job: impl FnOnce(u32) -> GalvoRequest,
    out: &mut dyn ActionSink,
) -> bool {
    let seq = st.take_seq();
    if !st.send_galvo(job(seq), out) {
        return false;
    }
    if let Some(run) = st.run.as_mut() {
        run.galvo_seq = seq;
    }
    true
}

/// Sends the current grid or goto point `target` to the galvo (board cm
/// → galvo mm); `false` when it could not. Paths go whole ([`mark`]).
pub(in crate::sequencer) fn aim(st: &mut Stage, target: Target, out: &mut dyn ActionSink) -> bool {
    allow_laser(*st.run, st.settings, st.inputs, out);
    let Some(run) = *st.run else { return false };
    let dwell_us = match run.kind {
        RunKind::Goto(_) => HOLD_US,
        _ => (st.settings.dwell_ms * 1000.0) as u32,
    };
    let [x_mm, y_mm] = target.point.galvo_mm();
    let job = |seq| GalvoRequest::Point {
        seq,
        x_mm,
        y_mm,
        dwell_us,
    };
    if !send_job(st, job, out) {
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
pub(in crate::sequencer) fn mark(st: &mut Stage, pattern: Pattern, out: &mut dyn ActionSink) {
    allow_laser(*st.run, st.settings, st.inputs, out);
    let Some(path) = pattern.figure() else {
        st.stop = Some(StopAsked {
            notice: None,
            why: "not a path",
        });
        return;
    };
    if !send_job(
        st,
        |seq| GalvoRequest::Path {
            seq,
            path,
            mark_speed_mm_s: None,
        },
        out,
    ) {
        return;
    }
    if let Some(run) = st.run.as_mut() {
        run.galvo_busy = true;
        run.gimbal_busy = false;
        run.phase = Phase::Moving;
        run.dwell_until = None;
    }
    log::info!("galvo marks the path");
}

/// What a report of the galvo loop the G-code session did not take asks
/// of the core (`gcode_idle`: no G-code queued or running).
pub(in crate::sequencer) fn said(event: GalvoEvent, run: Option<Run>, gcode_idle: bool) -> Said {
    match event {
        GalvoEvent::Done { seq } => Said::JobDone(seq),
        GalvoEvent::Refused { seq, error } if run.is_some_and(|r| r.galvo_seq == seq) => {
            let notice = reply_text(format_args!("error: galvo: {error}; stopped"));
            Said::Stop(Some(notice), "galvo refused the point")
        }
        // Told only when it stops something: an underrun of a loop
        // already parked (after the stop an earlier underrun made, or a
        // `stop`) would say "stopped" of a run that had stopped before it
        // (counted in `status` all the same).
        GalvoEvent::Underrun(underrun) => Said::Stop(
            (run.is_some() || !gcode_idle).then(|| {
                reply_text(format_args!(
                    "error: galvo underrun ({} half buffers late); stopped, laser off",
                    underrun.halves
                ))
            }),
            "galvo underrun",
        ),
        GalvoEvent::ConfigRefused(error) => Said::Notice(reply_text(format_args!(
            "error: galvo parameters refused: {error}; previous ones kept"
        ))),
        GalvoEvent::Refused { .. } | GalvoEvent::Stopped(_) => Said::Nothing,
    }
}

/// Sends the galvo parameters of `settings` to the loop (applied between
/// points), and whether it may light ([`allow_laser`]).
pub(in crate::sequencer) fn configure(
    settings: &Settings,
    run: Option<Run>,
    inputs: &Inputs,
    out: &mut dyn ActionSink,
) {
    let config = config_from(&settings.galvo, settings.gcode_junction_mm);
    out.act(Action::ConfigureGalvo(config));
    allow_laser(run, settings, inputs, out);
}

/// Tells the galvo loop whether the laser mode lets it light (`laser
/// off`: it still moves, dark). `laser off` also shuts the gate (where a
/// galvo loop runs), so the halves the loop computed before it (up to
/// three, 384 ms at 1 ms per sample) go dark at once too; the run goes on
/// and lights again after `laser auto`. `laser dwell` lights only dwells:
/// a marked path (which has none) stays dark, like the gimbal's.
pub(in crate::sequencer) fn allow_laser(
    run: Option<Run>,
    settings: &Settings,
    inputs: &Inputs,
    out: &mut dyn ActionSink,
) {
    let marking = run.is_some_and(|r| r.kind.pattern().is_some_and(|p| p.is_path()));
    let allowed = match settings.laser_mode {
        LaserMode::Off => false,
        LaserMode::Dwell => !marking,
        LaserMode::Auto => true,
    };
    out.act(Action::AllowGalvoLaser(allowed));
    // Only a galvo loop computes halves ahead.
    if !allowed && inputs.galvo_room.is_some() {
        out.act(Action::ShutGate);
    }
}

/// `galvo status` lines for `settings` and what the shell read (`galvo`).
pub(in crate::sequencer) fn report_status(
    settings: &Settings,
    galvo: &GalvoReadout,
    out: &mut dyn ActionSink,
) {
    let mut data = |args: core::fmt::Arguments<'_>| {
        out.act(Action::Line(Line::Data(reply_text(args))));
    };
    let g = &settings.galvo;
    let (phase, queued) = (galvo.phase, galvo.queued);
    data(format_args!("galvo: {phase:?}, {queued} points queued"));
    data(format_args!(
        "planner: {}, sample period {} us",
        g.planner.name(),
        Shortest(g.sample_period_us)
    ));
    data(format_args!(
        "underruns: {}, half buffers: {}",
        galvo.underruns, galvo.halves
    ));
    if let Some(t) = galvo.refill {
        let us = |cycles: u32| u64::from(cycles) * 1_000_000 / u64::from(t.cpu_hz.max(1));
        let percent = u64::from(t.cycles) * 100 / u64::from(t.window_cycles.max(1));
        data(format_args!(
            "worst refill: {} cycles = {} us, {} % of the {} us half",
            t.cycles,
            us(t.cycles),
            percent,
            us(t.window_cycles)
        ));
    }
}
