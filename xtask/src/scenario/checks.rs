//! The assertions every board must meet in each scenario. The safety
//! bounds (laser dark within 1 ms of a stop, a fault or a move; never lit
//! while moving) are the simulator's and are not widened for QEMU.

use anyhow::{Result, bail, ensure};

use super::outcome::Outcome;
use crate::qemu::BoardEvent;

/// The laser is dark this soon after a stop, fault or move, µs (SPEC).
pub const DARK_WITHIN_US: u64 = 1_000;

/// Checks `outcome` against the common rules and scenario `name`'s own.
pub fn check(name: &str, outcome: &Outcome) -> Result<()> {
    let board = outcome.board;
    let specific: fn(&Outcome) -> Result<()> = match name {
        "grid" => grid,
        "switch" => switch,
        "silent_servo" => silent_servo,
        "garbage_flood" => garbage_flood,
        "save_reset" => save_reset,
        "galvo_tuning" => galvo_tuning,
        "interlock" => interlock,
        other => bail!("no assertions for scenario {other:?}"),
    };
    ensure!(outcome.script_done, "{board}: the script did not finish");
    ensure!(
        outcome.idle_at_end,
        "{board}: the sequencer was busy at the end"
    );
    ensure!(
        !lit_at(outcome, u64::MAX),
        "{board}: the laser is lit at the end"
    );
    dark_while_moving_or_stopped(outcome)?;
    specific(outcome).map_err(|e| e.context(board))
}

/// The laser's state at `t_us` (dark before the first switch).
fn lit_at(outcome: &Outcome, t_us: u64) -> bool {
    outcome
        .laser_events
        .iter()
        .take_while(|(t, _)| *t <= t_us)
        .last()
        .is_some_and(|(_, on)| *on)
}

/// Times the laser was switched on.
fn lit_edges(outcome: &Outcome) -> Vec<u64> {
    let mut lit = false;
    let mut edges = Vec::new();
    for &(t, on) in &outcome.laser_events {
        if on && !lit {
            edges.push(t);
        }
        lit = on;
    }
    edges
}

fn count(outcome: &Outcome, wanted: &BoardEvent) -> usize {
    outcome.events.iter().filter(|(_, e)| e == wanted).count()
}

fn stopped_because(outcome: &Outcome, word: &str) -> Option<u64> {
    outcome
        .events
        .iter()
        .find(|(_, e)| matches!(e, BoardEvent::Stopped(why) if why.contains(word)))
        .map(|(t, _)| *t)
}

/// From each stop, run start (its approach is dark in every mode) or servo
/// move on, the laser is dark within [`DARK_WITHIN_US`] and stays dark
/// until the gimbal has arrived again.
fn dark_while_moving_or_stopped(outcome: &Outcome) -> Result<()> {
    for (i, (t, event)) in outcome.events.iter().enumerate() {
        if *event == BoardEvent::GimbalArrived {
            continue;
        }
        let until = outcome.events[i + 1..]
            .iter()
            .find(|(_, e)| *e == BoardEvent::GimbalArrived)
            .map_or(u64::MAX, |(a, _)| *a);
        let dark_from = t + DARK_WITHIN_US;
        if dark_from < until && lit_at(outcome, dark_from) {
            bail!(
                "{}: laser still lit 1 ms after {event:?} at {t} µs",
                outcome.board
            );
        }
        if let Some((on_at, _)) = outcome
            .laser_events
            .iter()
            .find(|(at, on)| *on && *at > *t && *at < until)
        {
            bail!(
                "{}: laser lit at {on_at} µs after {event:?} at {t} µs, before the gimbal arrived",
                outcome.board
            );
        }
    }
    Ok(())
}

/// The 3 x 3 grid completes: nine arrivals, nine lit dwells, no errors.
fn grid(o: &Outcome) -> Result<()> {
    ensure!(o.error_replies == 0, "{} error replies", o.error_replies);
    let points = 9;
    let arrivals = count(o, &BoardEvent::GimbalArrived);
    ensure!(
        arrivals >= points,
        "{arrivals} arrivals for {points} points"
    );
    let dwells = lit_edges(o).len();
    ensure!(dwells == points, "{dwells} lit dwells for {points} points");
    ensure!(
        stopped_because(o, "complete").is_some(),
        "the pattern never completed"
    );
    Ok(())
}

/// The switch lands mid-dwell (laser lit), goes dark, and the new pattern
/// runs to completion with its own lit dwell.
fn switch(o: &Outcome) -> Result<()> {
    ensure!(o.error_replies == 0, "{} error replies", o.error_replies);
    let switched_at = o
        .events
        .iter()
        .find(|(t, e)| {
            matches!(e, BoardEvent::Stopped(_) | BoardEvent::RunStarted)
                && lit_at(o, t.saturating_sub(1))
        })
        .map(|(t, _)| *t);
    let Some(switched_at) = switched_at else {
        bail!("no stop or new run while the laser was lit (the switch did not land mid-dwell)");
    };
    let lit_after = lit_edges(o)
        .into_iter()
        .filter(|&t| t > switched_at)
        .count();
    ensure!(
        lit_after == 1,
        "{lit_after} lit dwells after the switch (home: one)"
    );
    let done = stopped_because(o, "complete");
    ensure!(
        done.is_some_and(|t| t > switched_at),
        "the new pattern never completed"
    );
    Ok(())
}

/// The silent servo stops the run with a fault; the laser is dark from
/// then on and the user is told.
fn silent_servo(o: &Outcome) -> Result<()> {
    let Some(fault_at) = stopped_because(o, "fault") else {
        bail!("no stop for the servo fault: {:?}", o.events);
    };
    ensure!(
        lit_edges(o).iter().any(|&t| t < fault_at),
        "the pattern never lit the laser before the fault"
    );
    if let Some((t, _)) = o.laser_events.iter().find(|(t, on)| *on && *t > fault_at) {
        bail!("laser lit at {t} µs after the fault at {fault_at} µs");
    }
    ensure!(
        o.notices
            .iter()
            .any(|n| n.starts_with("[error") && n.contains("servo")),
        "no fault notice: {:?}",
        o.notices
    );
    Ok(())
}

/// Every line typed gets exactly one closing reply, every garbage line an
/// error, and the command line still answers afterwards.
fn garbage_flood(o: &Outcome) -> Result<()> {
    let typed = o.transcript.iter().filter(|l| l.starts_with("> ")).count();
    let closing = o
        .transcript
        .iter()
        .filter(|l| *l == "ok" || l.starts_with("error:"))
        .count();
    ensure!(typed >= 40, "only {typed} lines typed");
    ensure!(
        closing == typed,
        "{closing} closing replies to {typed} lines"
    );
    ensure!(
        o.error_replies == typed - 1,
        "{} error replies to {} garbage lines",
        o.error_replies,
        typed - 1
    );
    ensure!(
        o.transcript.last().is_some_and(|l| l == "ok"),
        "the last command (version) did not end with ok"
    );
    Ok(())
}

/// The value saved before the reset is the one read after it.
fn save_reset(o: &Outcome) -> Result<()> {
    ensure!(o.error_replies == 0, "{} error replies", o.error_replies);
    ensure!(o.boots == 2, "{} boots (one reset expected)", o.boots);
    let asked = o
        .transcript
        .iter()
        .rposition(|l| l == "> get dwell_ms")
        .ok_or_else(|| anyhow::anyhow!("get dwell_ms was never typed"))?;
    ensure!(
        o.transcript[asked + 1..]
            .iter()
            .take_while(|l| *l != "ok")
            .any(|l| l.contains("321")),
        "dwell_ms after the reset is not the saved 321: {:?}",
        &o.transcript[asked..]
    );
    Ok(())
}

/// The galvo marks the whole figure on its DAC stream without an underrun.
fn galvo_tuning(o: &Outcome) -> Result<()> {
    ensure!(o.error_replies == 0, "{} error replies", o.error_replies);
    ensure!(
        stopped_because(o, "complete").is_some(),
        "the figure never completed"
    );
    let asked = o
        .transcript
        .iter()
        .rposition(|l| l == "> galvo status")
        .ok_or_else(|| anyhow::anyhow!("galvo status was never typed"))?;
    let underruns = o.transcript[asked + 1..]
        .iter()
        .find(|l| l.starts_with("underruns:"))
        .ok_or_else(|| anyhow::anyhow!("galvo status without an underrun count"))?;
    ensure!(underruns.starts_with("underruns: 0,"), "{underruns}");
    Ok(())
}

/// Nothing lit before `arm`; one lit goto after it; the interlock opening
/// stops it dark within 1 ms; closed again the controls stay latched and
/// the next goto stays dark.
fn interlock(o: &Outcome) -> Result<()> {
    let has = |line: &str| o.transcript.iter().any(|l| l == line);
    ensure!(
        has("laser controls: interlock closed, key on, not armed since power-up"),
        "power-up not reported as not armed"
    );
    ensure!(
        has("laser controls: interlock closed, key on, latched: the interlock opened"),
        "the opening not latched"
    );
    let Some(opened_at) = stopped_because(o, "interlock") else {
        bail!("no stop for the interlock: {:?}", o.events);
    };
    let edges = lit_edges(o);
    ensure!(
        edges.len() == 1 && edges[0] < opened_at,
        "lit at {edges:?} µs (one lit goto before the opening at {opened_at} µs)"
    );
    ensure!(
        !lit_at(o, opened_at + DARK_WITHIN_US),
        "lit 1 ms after the interlock stop at {opened_at} µs"
    );
    Ok(())
}
