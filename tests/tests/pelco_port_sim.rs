//! The simulator's PELCO port through the real task wiring, in virtual
//! time: the port task reads the saved `pelco.baud` and `pelco.address`
//! at boot and sets the line's rate (recorded by the simulated port);
//! without a port no task runs and `pelco status` says so. (A real client
//! on the port: `tests/tests/pelco_client.rs`.)

use laser_sim::pelco_port::PelcoPtyOptions;
use laser_sim::world::SimOptions;
use system_tests::{run_with, terminal_lines};

#[test]
fn the_port_runs_at_the_saved_baud_rate_and_address() {
    let first = run_with(
        "set pelco.baud 4800\nset pelco.address 7\nsave\npelco status\n",
        SimOptions::default(),
    );
    assert!(
        terminal_lines(&first).contains(&"pelco: no port on this board"),
        "{:?}",
        terminal_lines(&first)
    );
    assert_eq!(first.pelco.baud, None, "no port, no task");
    let defaults = run_with(
        "wait 50\npelco status\n",
        SimOptions {
            pelco_pty: Some(PelcoPtyOptions::default()),
            ..SimOptions::default()
        },
    );
    assert_eq!(defaults.pelco.baud, Some(9600));
    let saved = run_with(
        "wait 50\npelco status\n",
        SimOptions {
            settings_flash: Some(first.settings_flash.clone()),
            pelco_pty: Some(PelcoPtyOptions::default()),
            ..SimOptions::default()
        },
    );
    assert_eq!(saved.pelco.baud, Some(4800));
    let lines = terminal_lines(&saved);
    assert!(lines.contains(&"pelco: address 7"), "{lines:?}");
}

#[test]
fn console_errors_typed_while_the_port_reads_its_settings_stay_the_consoles() {
    // The CI run of stop 26: on QEMU, `goto 1 2 3 4` typed ahead at boot
    // was answered `pelco.baud = 9600 …` / `ok`. The port task's `get`s
    // (quiet commands) were in flight; the console's own error for the
    // bad line closed the quiet command instead, and the `get`'s reply
    // went to the host. Every bad line typed at any instant of the port's
    // boot gets its own error, and the port still reads its settings.
    let bad = ["goto 1 2 3 4", "stop now please", "get nothing", "xyzzy"];
    for delay_ms in 0..12 {
        let mut script = format!("wait {delay_ms}\n");
        for _ in 0..4 {
            for line in bad {
                script += &format!("@type-ahead {line}\n");
            }
        }
        script += "version\nwait 100\n";
        let report = run_with(&script, with_port());
        let lines = terminal_lines(&report);
        let errors = lines.iter().filter(|l| l.starts_with("error:")).count();
        let oks = lines.iter().filter(|l| **l == "ok").count();
        assert_eq!(
            (errors, oks),
            (4 * bad.len(), 1),
            "typed after {delay_ms} ms: {lines:#?}"
        );
        assert!(
            !lines
                .iter()
                .any(|l| l.starts_with("pelco.") || l.starts_with("oq_cm")),
            "a quiet reply reached the host: {lines:#?}"
        );
        assert_eq!(report.pelco.baud, Some(9600));
    }
}

#[test]
fn status_reports_asked_while_the_port_reads_its_settings_reach_the_host() {
    // A realtime `?` is answered at once, also while the PELCO port's
    // quiet `get` is in flight: its `<…>` report is not that command's
    // reply (it was taken as the `get`'s value and never reached the
    // G-code sender).
    for delay_ms in 0..12 {
        let script = format!("wait {delay_ms}\n@realtime ?\nwait 100\n");
        let report = run_with(&script, with_port());
        let lines = terminal_lines(&report);
        assert_eq!(
            lines.iter().filter(|l| l.starts_with("<Idle|")).count(),
            1,
            "asked after {delay_ms} ms: {lines:#?}"
        );
        assert_eq!(report.pelco.baud, Some(9600), "after {delay_ms} ms");
    }
}

/// The simulator's options with a PELCO port (its settings read at boot).
fn with_port() -> SimOptions {
    SimOptions {
        pelco_pty: Some(PelcoPtyOptions::default()),
        ..SimOptions::default()
    }
}
