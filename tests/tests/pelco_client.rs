//! A real PELCO-D client from PyPI (`pyptzcontroller`) against the
//! firmware's PELCO codec and session: every frame the library writes
//! decodes, for this device, to the command it means and to the product
//! command the session makes of it; the library decodes the session's
//! position replies to the spot's angles within 0.01°.
//!
//! The library is installed into a private directory when missing
//! (`target/senders/ptz`, like the G-code senders); `#[ignore]`d like them
//! (it needs PyPI once): `cargo test -p system-tests --test pelco_client
//! -- --ignored`.

use std::path::Path;
use std::process::Command;

use laser_app::command::{Command as Product, PresetCommand};
use laser_app::domain::PointCm;
use laser_app::pelco::sight::{angles_deg, point};
use laser_app::pelco::{Request, Session, View};
use laser_app::settings::LaserMode;
use pelco::{Command as Pelco, Decoder, Frame};

const REPO: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
/// The client, pinned (MIT), and the serial library it imports.
const PY_PACKAGES: &[&str] = &["pyptzcontroller==0.1.2", "pyserial==3.5"];
const OQ_CM: f64 = 100.0;

/// Runs the driver with `replies` (hex) and returns its JSON line.
fn run_client(replies: &str) -> serde_json::Value {
    let dir = Path::new(REPO).join("target/senders/ptz");
    if !dir.join("ptz_control_lib").is_dir() {
        std::fs::create_dir_all(&dir).unwrap();
        let pip = ["-m", "pip", "install", "--quiet", "--target", "."];
        let status = Command::new("python3")
            .args([&pip[..], PY_PACKAGES].concat())
            .current_dir(&dir)
            .status()
            .expect("python3 runs");
        assert!(status.success(), "pip install {PY_PACKAGES:?} failed");
    }
    let out = Command::new("python3")
        .arg(Path::new(REPO).join("tests/senders/ptz_pyptzcontroller.py"))
        .arg(replies)
        .env("PYTHONPATH", &dir)
        .output()
        .expect("driver runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8(out.stdout).unwrap();
    serde_json::from_str(stdout.trim()).expect("one JSON line")
}

fn hex_bytes(hex: &str) -> Vec<u8> {
    (0..hex.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap())
        .collect()
}

#[test]
#[ignore = "installs pyptzcontroller from PyPI"]
fn pyptzcontroller_frames_drive_the_session_and_read_its_replies() {
    let first = run_client("");
    let written: Vec<String> = first["written"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap().to_owned())
        .collect();
    let mut decoder = Decoder::new(1);
    let mut frames: Vec<Frame> = Vec::new();
    for hex in &written {
        decoder.decode(&hex_bytes(hex), |f| frames.push(f));
    }
    let counters = decoder.counters();
    assert_eq!(
        counters.frames as usize,
        written.len(),
        "every frame decodes"
    );
    assert_eq!((counters.bad_checksums, counters.other_addresses), (0, 0));
    let names: Vec<&str> = frames.iter().map(|f| Pelco::of(f).name()).collect();
    assert_eq!(
        names,
        [
            "move",
            "move",
            "move",
            "move",
            "stop",
            "set-preset",
            "goto-preset",
            "clear-preset",
            "set-aux",
            "clear-aux",
            "set-pan",
            "set-tilt",
            "set-pan",
            "set-tilt",
            "query-pan",
            "query-tilt",
        ]
    );

    // The session's product commands, the spot at a fixed point.
    let spot = point([-12.0, 4.5], OQ_CM);
    let view = View {
        now_ms: 0,
        at: Some(spot),
        oq_cm: OQ_CM,
    };
    let mut session = Session::new();
    let mut requests = Vec::new();
    for f in &frames {
        session.on_frame(f, view, &mut |r| requests.push((Pelco::of(f).name(), r)));
    }
    let gotos: Vec<PointCm> = requests
        .iter()
        .filter_map(|(_, r)| match r {
            Request::Command(Product::Goto(p)) => Some(*p),
            _ => None,
        })
        .collect();
    // Presets are the product's preset commands (kept in the settings
    // store, see settings_sim.rs); pan 25.5 / tilt 10° down, pan 12.25 /
    // tilt 7.5° up (each keeps the spot's other angle: the spot does not
    // move in this replay).
    let presets: Vec<PresetCommand> = requests
        .iter()
        .filter_map(|(_, r)| match r {
            Request::Command(Product::Preset(c)) => Some(*c),
            _ => None,
        })
        .collect();
    assert_eq!(
        presets,
        [
            PresetCommand::Set(5),
            PresetCommand::Goto(5),
            PresetCommand::Clear(5)
        ]
    );
    assert_eq!(gotos.len(), 4);
    let angle = |p: PointCm| angles_deg(p, OQ_CM);
    let close = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6;
    assert!(close(angle(gotos[0]), [25.5, 4.5]), "{:?}", angle(gotos[0]));
    assert!(
        close(angle(gotos[1]), [-12.0, -10.0]),
        "{:?}",
        angle(gotos[1])
    );
    assert!(
        close(angle(gotos[2]), [12.25, 4.5]),
        "{:?}",
        angle(gotos[2])
    );
    assert!(
        close(angle(gotos[3]), [-12.0, 7.5]),
        "{:?}",
        angle(gotos[3])
    );
    let laser: Vec<LaserMode> = requests
        .iter()
        .filter_map(|(_, r)| match r {
            Request::Command(Product::Laser(m)) => Some(*m),
            _ => None,
        })
        .collect();
    assert_eq!(laser, [LaserMode::Auto, LaserMode::Off]);
    let jogs = requests
        .iter()
        .filter(|(_, r)| matches!(r, Request::Command(Product::Grbl(_))))
        .count();
    assert!(jogs >= 2, "the moves queue jogs");
    assert!(
        requests
            .iter()
            .any(|(n, r)| *n == "stop" && *r == Request::JogCancel)
    );

    // The replies to the two queries, back through the library.
    let replies: String = requests
        .iter()
        .filter_map(|(_, r)| match r {
            Request::Reply(f) => Some(
                f.encode()
                    .as_slice()
                    .iter()
                    .map(|b| format!("{b:02x}"))
                    .collect::<String>(),
            ),
            _ => None,
        })
        .collect();
    assert_eq!(replies.len(), 2 * 2 * 7);
    let second = run_client(&replies);
    let pan = second["position"][0].as_f64().expect("pan decoded");
    let tilt = second["position"][1].as_f64().expect("tilt decoded");
    // The library reads pan as 0–360°.
    assert!(((pan - 360.0) - -12.0).abs() < 0.01, "pan {pan}");
    assert!((tilt - 4.5).abs() < 0.01, "tilt {tilt}");
}
