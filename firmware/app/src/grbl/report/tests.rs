extern crate std;
use super::*;
use crate::grbl::settings_map::{SETTINGS, find};
use crate::grbl::state::Coolant;
use std::string::String;

fn text(f: impl FnOnce(&mut String) -> fmt::Result) -> String {
    let mut s = String::new();
    f(&mut s).unwrap();
    s
}

fn idle() -> Status {
    Status {
        state: MachineState::Idle,
        machine_mm: PointMm::ZERO,
        work_offset_mm: PointMm::ZERO,
        report_machine: true,
        buffer: None,
        line_number: None,
        feed_mm_min: 0.0,
        power: 0.0,
        show_work_offset: false,
        overrides: None,
    }
}

#[test]
fn simple_replies_match_grbl() {
    assert_eq!(BANNER, "Grbl 1.1h ['$' for help]");
    let mut ok = String::new();
    write_ok(&mut ok).unwrap();
    assert_eq!(ok, "ok");
    assert_eq!(
        text(|w| write_error(w, GrblError::UnsupportedCommand)),
        "error:20"
    );
    assert_eq!(text(|w| write_alarm(w, Alarm::ResetWhileMoving)), "ALARM:3");
    assert_eq!(
        text(|w| write_message(w, "Caution: Unlocked")),
        "[MSG:Caution: Unlocked]"
    );
}

#[test]
fn status_reports_match_grbl_examples() {
    // interface.md: `<Idle|MPos:0.000,0.000,0.000|FS:0,0>`
    assert_eq!(
        text(|w| write_status(w, &idle())),
        "<Idle|MPos:0.000,0.000,0.000|FS:0,0>"
    );
    let run = Status {
        state: MachineState::Run,
        machine_mm: PointMm {
            x_mm: 12.3456,
            y_mm: -4.0,
        },
        work_offset_mm: PointMm {
            x_mm: 10.0,
            y_mm: 1.0,
        },
        buffer: Some((15, 128)),
        line_number: Some(42),
        feed_mm_min: 1499.6,
        power: 800.0,
        show_work_offset: true,
        overrides: Some((
            Overrides {
                feed: 110,
                rapid: 100,
                spindle: 90,
            },
            SpindleMode::Dynamic,
            Coolant {
                mist: false,
                flood: true,
            },
        )),
        ..idle()
    };
    assert_eq!(
        text(|w| write_status(w, &run)),
        "<Run|MPos:12.346,-4.000,0.000|Bf:15,128|Ln:42|FS:1500,800\
         |WCO:10.000,1.000,0.000|Ov:110,100,90|A:CF>"
    );
    let work = Status {
        report_machine: false,
        state: MachineState::Hold {
            decelerating: false,
        },
        ..run
    };
    assert!(text(|w| write_status(w, &work)).starts_with("<Hold:0|WPos:2.346,-5.000,0.000|"));
    for (state, name) in [
        (MachineState::Hold { decelerating: true }, "Hold:1"),
        (MachineState::Jog, "Jog"),
        (MachineState::Alarm, "Alarm"),
        (MachineState::Check, "Check"),
        (MachineState::Home, "Home"),
        (MachineState::Sleep, "Sleep"),
    ] {
        let line = text(|w| write_status(w, &Status { state, ..idle() }));
        assert!(line.starts_with(&std::format!("<{name}|MPos:")), "{line}");
    }
}

#[test]
fn parser_state_line_matches_grbl_default() {
    let mut state = ParserState::new();
    assert_eq!(
        text(|w| write_parser_state(w, &state)),
        "[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]"
    );
    state.execute("G20 G91 G93 G1 X0 F1 M4 M7 T2 S300").unwrap();
    state.execute("M8").unwrap();
    state.execute("G94 F10").unwrap();
    assert_eq!(
        text(|w| write_parser_state(w, &state)),
        "[GC:G1 G54 G17 G20 G91 G94 M4 M7 M8 T2 F254 S300]"
    );
}

#[test]
fn parameter_lines_list_offsets() {
    let mut state = ParserState::new();
    state.execute("G10 L2 P1 X1.5 Y-2").unwrap();
    state.execute("G0 X0 Y0").unwrap();
    state.execute("G92 X1").unwrap();
    let lines: std::vec::Vec<String> = (0..=PARAMETER_LINES)
        .map(|i| text(|w| write_parameter_line(w, i, &state)))
        .collect();
    assert_eq!(lines[0], "[G54:1.500,-2.000,0.000]");
    assert_eq!(lines[1], "[G55:0.000,0.000,0.000]");
    assert_eq!(lines[6], "[G28:0.000,0.000,0.000]");
    assert_eq!(lines[8], "[G92:-1.000,0.000,0.000]");
    assert_eq!(lines[9], "[TLO:0.000]");
    assert_eq!(lines[10], "[PRB:0.000,0.000,0.000:0]");
    assert_eq!(lines[11], "", "past the end: nothing");
}

#[test]
fn build_info_and_settings_lines() {
    assert_eq!(
        text(|w| write_version(w, "20190830", "laser")),
        "[VER:1.1h.20190830:laser]"
    );
    assert_eq!(text(|w| write_options(w, "VN", 15, 128)), "[OPT:VN,15,128]");
    let line = |n, v| text(|w| write_setting(w, find(n).unwrap(), v));
    assert_eq!(line(11, 0.01), "$11=0.010");
    assert_eq!(line(30, 1000.0), "$30=1000");
    assert_eq!(line(32, 1.0), "$32=1");
    assert_eq!(line(110, 5000.0), "$110=5000.000");
    for setting in SETTINGS {
        let l = text(|w| write_setting(w, setting, setting.default));
        assert!(l.starts_with(&std::format!("${}=", setting.number)), "{l}");
    }
}

proptest::proptest! {
    #[test]
    fn settings_lines_parse_back(index in 0..SETTINGS.len(), thousandths in 0u32..100_000_000) {
        // $$ output pasted back as `$N=value` sets the same value.
        use crate::grbl::system::{SystemCommand, parse_system};
        let setting = &SETTINGS[index];
        let scale = 10f64.powi(i32::from(setting.decimals));
        let value = libm::round(f64::from(thousandths) / 1000.0 * scale) / scale;
        let line = text(|w| write_setting(w, setting, value));
        let parsed = parse_system(&line);
        proptest::prop_assert_eq!(
            parsed,
            Ok(SystemCommand::SetSetting { number: setting.number, value })
        );
    }

    #[test]
    fn status_positions_read_back_within_half_a_micron(
        x in -1.0e6f64..1.0e6, y in -1.0e6f64..1.0e6
    ) {
        let s = Status { machine_mm: PointMm { x_mm: x, y_mm: y }, ..idle() };
        let line = text(|w| write_status(w, &s));
        let fields = line.split_once("MPos:").unwrap().1.split('|').next().unwrap();
        let mut parts = fields.split(',').map(|v| v.parse::<f64>().unwrap());
        let (rx, ry) = (parts.next().unwrap(), parts.next().unwrap());
        proptest::prop_assert!((rx - x).abs() <= 0.0005 + 1e-9 && (ry - y).abs() <= 0.0005 + 1e-9);
    }
}

#[test]
fn default_parser_state_line_is_valid_gcode_for_the_same_state() {
    // Senders replay `$G` words; grbl's default line must parse back to
    // the power-up state.
    let line = text(|w| write_parser_state(w, &ParserState::new()));
    let words = line.trim_start_matches("[GC:").trim_end_matches(']');
    let mut state = ParserState::new();
    state.motion = MotionMode::Linear;
    state.execute(words).unwrap();
    assert_eq!(state, ParserState::new());
}
