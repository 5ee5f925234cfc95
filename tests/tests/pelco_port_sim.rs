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
