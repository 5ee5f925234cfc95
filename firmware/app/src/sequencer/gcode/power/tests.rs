//! G-code laser power on the gimbal: S mapped into `$31`..`$30` and
//! clamped, power overrides on the fly, M4 scaled by the step's speed and
//! dark at rest, `FS:` / `Ov:` in the status report.

extern crate std;

use std::vec::Vec;

use embassy_time::Instant;

use crate::grbl::realtime::{OverrideStep, Realtime};
use crate::sequencer::gcode::tests::{closers, line, move_seq, pump, realtime, status};
use crate::sequencer::laser::LaserPower;
use crate::sequencer::machine::{Action, Core};

/// The last power level `actions` set for the gimbal laser.
fn power(actions: &[Action]) -> Option<u16> {
    actions.iter().rev().find_map(|a| match a {
        Action::GimbalPower(p) => Some(p.per_mille()),
        _ => None,
    })
}

/// A core on the gimbal with `settings` (`$N=v` lines) that has travelled
/// to X1 and settled there, then runs `gcode`; its actions.
fn lit_core(settings: &[&str], gcode: &str) -> (Core, Vec<Action>) {
    let mut core = Core::new(Instant::from_millis(0));
    for s in settings {
        assert_eq!(closers(&line(&mut core, 1, s)), 1, "{s}");
    }
    assert!(move_seq(&line(&mut core, 2, "G0 X1")).is_some(), "rapid");
    let (ms, _) = pump(&mut core, 2, |_| false);
    let out = line(&mut core, ms + 100, gcode);
    (core, out)
}

#[test]
fn m3_s_maps_into_the_power_range_and_clamps_like_grbl() {
    for (s, per_mille) in [(300, 300), (1000, 1000), (1500, 1000)] {
        let (mut core, out) =
            lit_core(&["$30=1000", "$31=0"], &std::format!("G1 X20 F600 M3 S{s}"));
        assert_eq!(core.laser_power.per_mille(), per_mille, "S{s}: {out:?}");
        assert!(out.contains(&Action::GimbalLaser(true)));
        let report = status(&mut core, 101);
        let fs = std::format!("|FS:600,{}", per_mille);
        assert!(report.contains(&fs), "S{s}: {report}");
    }
    // A narrower range: S250 of 0..500 is half power.
    let (_, out) = lit_core(&["$30=500"], "G1 X20 F600 M3 S250");
    assert_eq!(power(&out), Some(500), "sent before the laser lights");
    // S0 lights nothing.
    let (core, out) = lit_core(&[], "G1 X20 F600 M3 S0");
    assert!(!out.contains(&Action::GimbalLaser(true)), "{out:?}");
    assert!(!core.laser_on());
}

#[test]
fn power_overrides_change_the_lit_power_at_once_within_10_to_200_percent() {
    let (mut core, out) = lit_core(&[], "G1 X20 F600 M3 S500");
    assert_eq!(power(&out), Some(500));
    let step = |core: &mut Core, ms, s| power(&realtime(core, ms, Realtime::SpindleOverride(s)));
    assert_eq!(step(&mut core, 101, OverrideStep::CoarseMinus), Some(450));
    assert_eq!(step(&mut core, 102, OverrideStep::FineMinus), Some(445));
    assert_eq!(step(&mut core, 103, OverrideStep::Reset), Some(500));
    assert_eq!(step(&mut core, 104, OverrideStep::CoarsePlus), Some(550));
    assert_eq!(step(&mut core, 105, OverrideStep::FinePlus), Some(555));
    // 10 × +10 %: capped at 200 % of S500 = S1000, full power.
    for k in 0..10 {
        step(&mut core, 106 + k, OverrideStep::CoarsePlus);
    }
    let reports: Vec<_> = (0..10).map(|k| status(&mut core, 120 + k)).collect();
    assert!(
        reports.iter().all(|r| r.contains("|FS:600,1000")),
        "{reports:?}"
    );
    assert!(
        reports[0].contains("|Ov:100,100,200"),
        "the next report: {reports:?}"
    );
    assert!(
        !reports[1].contains("|Ov:"),
        "then every tenth: {reports:?}"
    );
    // Down to the 10 % floor: S50.
    for k in 0..25 {
        step(&mut core, 140 + k, OverrideStep::CoarseMinus);
    }
    assert!(status(&mut core, 170).contains("|FS:600,50"));
    assert!(core.laser_on());
}

#[test]
fn m4_scales_with_the_step_speed_and_is_dark_at_rest() {
    // At 10 mm/s the servos keep up: full S.
    let (core, out) = lit_core(&[], "G1 X20 F600 M4 S1000");
    assert_eq!(core.laser_power, LaserPower::FULL, "{out:?}");
    // At 1000 mm/s the servos' speed limit stretches each step: M4 runs
    // at the actual speed's fraction, M3 stays at S.
    let (core, m3) = lit_core(&[], "G1 X20 F60000 M3 S1000");
    assert!(
        core.laser_on() && core.laser_power == LaserPower::FULL,
        "{m3:?}"
    );
    let (mut core, first) = lit_core(&[], "G1 X20 F60000 M4 S1000");
    // The gimbal accelerates from rest: lit from the first period moving.
    let (_, more) = pump(&mut core, 200, |out| power(out).is_some());
    let m4: Vec<Action> = first.into_iter().chain(more).collect();
    let slow = power(&m4).unwrap_or_else(|| panic!("{m4:?}"));
    assert!(
        slow > 0 && slow < 1000,
        "M4 at a servo-limited step: {slow}"
    );
    assert!(m4.contains(&Action::GimbalLaser(true)));
    // Drive the block to its end: the gimbal brakes to rest there and
    // settles (speed 0), M4 goes dark; M3 would stay lit.
    let (ms, out) = pump(&mut core, 200, |_| false);
    assert!(out.contains(&Action::GimbalLaser(false)), "{out:?}");
    assert!(status(&mut core, ms).contains("|FS:"), "report at rest");
    assert!(!core.laser_on());
}

#[test]
fn feed_hold_and_reset_darken_the_powered_laser() {
    let (mut core, _) = lit_core(&[], "G1 X20 F600 M3 S300");
    assert!(core.laser_on());
    let out = realtime(&mut core, 101, Realtime::FeedHold);
    assert!(out.contains(&Action::GimbalLaser(false)), "{out:?}");
    assert!(status(&mut core, 102).contains("|FS:0,0"));
    let (mut core, _) = lit_core(&[], "G1 X20 F600 M3 S300");
    let out = realtime(&mut core, 101, Realtime::SoftReset);
    assert!(
        out.contains(&Action::CloseGate) && !core.laser_on(),
        "{out:?}"
    );
}

#[test]
fn product_runs_light_at_full_power() {
    let core = Core::new(Instant::from_millis(0));
    let power = core
        .gcode
        .gimbal_power(&core.settings, &core.jobs, core.drivers());
    assert_eq!(power, LaserPower::FULL);
}
