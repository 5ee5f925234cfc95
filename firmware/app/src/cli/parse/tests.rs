extern crate std;
use super::*;
use crate::command::HELP_LINES;
use std::string::ToString;

fn ok(line: &str) -> Command {
    match parse_line(line) {
        Ok(Some(c)) => c,
        other => panic!("{line:?} → {other:?}"),
    }
}

#[test]
fn parses_the_basic_commands_case_insensitively() {
    assert_eq!(ok("help"), Command::Help);
    assert_eq!(ok("  VERSION \t"), Command::Version);
    assert_eq!(ok("Status"), Command::Status);
    assert_eq!(ok("stop"), Command::Stop);
    assert_eq!(ok("params"), Command::Params);
    assert_eq!(ok("save"), Command::Save);
}

#[test]
fn blank_lines_and_comments_do_nothing() {
    assert_eq!(parse_line(""), Ok(None));
    assert_eq!(parse_line("   \t "), Ok(None));
    assert_eq!(parse_line("# set err.dx.c0 1.0"), Ok(None));
}

#[test]
fn unknown_words_are_named() {
    assert_eq!(
        parse_line("frobnicate now"),
        Err(CommandError::UnknownCommand(word("frobnicate")))
    );
    assert_eq!(
        parse_line("~~~").map_err(|e| e.to_string()),
        Err("unknown command '~~~'".to_string())
    );
}

#[test]
fn degenerate_figures_are_refused() {
    for line in [
        "pattern line 1 1 1 1",
        "pattern line 1 1 1.05 0.95 once",
        "pattern rect 0 0 0 0",
        "pattern rect 0 0 5 0.05",
        "pattern rect -3 2 -3 7 once",
    ] {
        match parse_line(line) {
            Err(CommandError::Rejected(why)) => assert!(why.contains("0.1 cm"), "{why}"),
            other => panic!("{line:?} → {other:?}"),
        }
    }
    // At the limit they draw.
    assert!(matches!(
        ok("pattern line 1 1 1.1 1"),
        Command::Pattern { .. }
    ));
    assert!(matches!(
        ok("pattern rect 0 0 0.1 -0.1 once"),
        Command::Pattern { .. }
    ));
}

#[test]
fn extra_arguments_are_refused() {
    assert_eq!(
        parse_line("version 2"),
        Err(CommandError::UnexpectedArgument(word("2")))
    );
    assert!(parse_line("pattern corner twice").is_err());
    assert!(parse_line("goto 1 2 3").is_err());
}

#[test]
fn patterns_with_options() {
    assert_eq!(
        ok("pattern corner once"),
        Command::Pattern {
            pattern: Pattern::Grid(GridPattern::Corner),
            once: true
        }
    );
    assert_eq!(
        ok("pattern grid-full serpentine"),
        Command::Pattern {
            pattern: Pattern::Grid(GridPattern::FullSerpentine),
            once: false
        }
    );
    assert_eq!(
        ok("pattern grid-full once"),
        Command::Pattern {
            pattern: Pattern::Grid(GridPattern::FullRaster),
            once: true
        }
    );
    assert_eq!(
        ok("pattern circle 0 0 5 cw once"),
        Command::Pattern {
            pattern: Pattern::Path(Figure::Circle {
                centre: PointCm {
                    x_cm: 0.0,
                    y_cm: 0.0
                },
                radius_cm: 5.0,
                rotation: Rotation::Cw
            }),
            once: true
        }
    );
    assert_eq!(
        ok("pattern line -5 1 5 -1"),
        Command::Pattern {
            pattern: Pattern::Path(Figure::Line {
                from: PointCm {
                    x_cm: -5.0,
                    y_cm: 1.0
                },
                to: PointCm {
                    x_cm: 5.0,
                    y_cm: -1.0
                }
            }),
            once: false
        }
    );
    assert!(matches!(
        parse_line("pattern spiral"),
        Err(CommandError::InvalidArgument { .. })
    ));
    assert_eq!(
        parse_line("pattern line 1 2 3"),
        Err(CommandError::MissingArgument("y1_cm"))
    );
    assert!(matches!(
        parse_line("pattern circle 0 0 0"),
        Err(CommandError::OutOfRange { .. })
    ));
}

#[test]
fn goto_grid_laser_model_set_get() {
    assert_eq!(
        ok("goto 1.5 -2"),
        Command::Goto(PointCm {
            x_cm: 1.5,
            y_cm: -2.0
        })
    );
    assert!(parse_line("goto nan 0").is_err());
    assert!(parse_line("goto 1e6 0").is_err());
    assert_eq!(ok("grid -6 4"), Command::Grid { xi: -6, yi: 4 });
    assert!(parse_line("grid 0.5 1").is_err());
    assert_eq!(ok("laser DWELL"), Command::Laser(LaserMode::Dwell));
    assert_eq!(ok("laser on"), Command::Laser(LaserMode::Auto));
    assert_eq!(ok("laser off"), Command::Laser(LaserMode::Off));
    assert_eq!(ok("target GALVO"), Command::Target(Actuator::Galvo));
    assert_eq!(ok("planner seed"), Command::Planner(JumpPlanner::Seed));
    assert_eq!(ok("galvo status"), Command::GalvoStatus);
    assert!(parse_line("target laser").is_err());
    assert!(parse_line("galvo go").is_err());
    assert!(parse_line("laser maybe").is_err());
    assert_eq!(ok("model seed"), Command::Model(AimModel::Seed));
    assert!(parse_line("model exactish").is_err());
    let Command::Set { param, value } = ok("set dwell_ms 250") else {
        panic!("not a set");
    };
    assert_eq!((param.name, value), ("dwell_ms", 250.0));
    assert!(matches!(
        parse_line("set dwell_ms -3"),
        Err(CommandError::OutOfRange { .. })
    ));
    assert!(parse_line("set nosuch 1").is_err());
    assert!(parse_line("set dwell_ms").is_err());
    assert!(matches!(ok("get err.dx.c3"), Command::Get(p) if p.name == "err.dx.c3"));
}

#[test]
fn every_help_line_names_a_command_that_parses_with_its_example() {
    let examples = [
        "pattern home once",
        "pattern grid-full raster once",
        "pattern line 0 0 1 1 once",
        "pattern circle 0 0 1 cw once",
        "pattern rect 0 0 1 1 once",
        "pattern tuning once",
        "stop",
        "arm",
        "home",
        "goto 1 1",
        "grid 1 1",
        "preset goto 1",
        "laser on",
        "model exact",
        "target both",
        "planner seed",
        "galvo status",
        "pelco status",
        "set dwell_ms 1",
        "get dwell_ms",
        "params",
        "save",
        "status",
        "version",
        "trace on",
        "servo scan",
        "servo ping 0",
        "servo id 0 1 confirm",
        "servo zero 1",
        "help",
    ];
    assert_eq!(examples.len(), HELP_LINES.len());
    for (line, example) in HELP_LINES.iter().zip(examples) {
        let name = line.split_ascii_whitespace().next().unwrap_or("");
        assert!(example.starts_with(name));
        if example == "pelco status" {
            // Answered by the console itself (crate::usb), never parsed.
            continue;
        }
        assert!(matches!(parse_line(example), Ok(Some(_))), "{example}");
    }
}

#[test]
fn preset_commands_parse_and_bad_numbers_are_refused() {
    use crate::command::PresetCommand;
    assert_eq!(ok("preset set 1"), Command::Preset(PresetCommand::Set(1)));
    assert_eq!(
        ok("PRESET Clear 255"),
        Command::Preset(PresetCommand::Clear(255))
    );
    assert_eq!(
        ok("preset goto 17"),
        Command::Preset(PresetCommand::Goto(17))
    );
    for bad in [
        "preset goto 0",
        "preset set 256",
        "preset set -1",
        "preset set 1.5",
        "preset call 1",
        "preset set",
        "preset set 1 2",
        "preset",
    ] {
        assert!(parse_line(bad).is_err(), "{bad}");
    }
}

#[test]
fn servo_setup_commands_parse_and_bad_ids_are_refused() {
    use crate::command::ServoSetup;
    assert_eq!(ok("servo scan"), Command::Servo(ServoSetup::Scan));
    assert_eq!(ok("SERVO ping 254"), Command::Servo(ServoSetup::Ping(254)));
    assert_eq!(ok("servo zero 1"), Command::Servo(ServoSetup::Zero(1)));
    assert_eq!(
        ok("servo id 0 1"),
        Command::Servo(ServoSetup::SetId {
            id: 0,
            new_id: 1,
            confirmed: false
        })
    );
    assert_eq!(
        ok("servo id 0 7 CONFIRM"),
        Command::Servo(ServoSetup::SetId {
            id: 0,
            new_id: 7,
            confirmed: true
        })
    );
    for bad in [
        "servo",
        "servo frob",
        "servo ping",
        "servo ping 255",
        "servo ping -1",
        "servo id 0",
        "servo id 0 255 confirm",
        "servo id 0 1 yes",
        "servo id 0 1 confirm now",
        "servo scan 3",
        "servo zero 1.5",
    ] {
        assert!(parse_line(bad).is_err(), "{bad}");
    }
    // The command prints back as typed.
    assert_eq!(
        std::format!("{:?}", ok("servo id 0 7 confirm")),
        "servo id 0 7 confirm"
    );
}
