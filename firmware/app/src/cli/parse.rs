//! Command-line text → [`Command`].

use super::args::Args;
use super::error::{CommandError, word};
use crate::command::Command;
use crate::domain::{Actuator, AimModel, Figure, GridPattern, Pattern, PointCm, Rotation};
use crate::settings::{JumpPlanner, LaserMode, find_param};

/// Largest board coordinate accepted anywhere, cm.
pub const BOARD_LIMIT_CM: f64 = 200.0;

/// Smallest extent of a drawn figure, cm: a line's length, a rect's sides
/// (as a circle's radius and the tuning figure's size).
pub const MIN_FIGURE_CM: f64 = 0.1;
/// Largest grid index magnitude accepted by the parser (the sequencer
/// checks against the configured grid).
const GRID_INDEX_LIMIT: i32 = 20;

/// Parses one command line. Blank lines and `#` comments parse to `None`
/// (they are acknowledged with `ok` and do nothing, so a file of commands
/// with comments can be pasted into the terminal).
pub fn parse_line(line: &str) -> Result<Option<Command>, CommandError> {
    let text = line.trim();
    if text.is_empty() || text.starts_with('#') {
        return Ok(None);
    }
    let mut args = Args::new(text);
    let name = args.word("command")?;
    let is = |candidate: &str| name.eq_ignore_ascii_case(candidate);
    let command = if is("help") {
        Command::Help
    } else if is("version") {
        Command::Version
    } else if is("status") {
        Command::Status
    } else if is("stop") {
        Command::Stop
    } else if is("params") {
        Command::Params
    } else if is("target") {
        Command::Target(keyword(
            &mut args,
            "gimbal|galvo|both",
            &[
                ("gimbal", Actuator::Gimbal),
                ("galvo", Actuator::Galvo),
                ("both", Actuator::Both),
            ],
        )?)
    } else if is("planner") {
        Command::Planner(keyword(
            &mut args,
            "optimal|seed",
            &[
                ("optimal", JumpPlanner::Optimal),
                ("seed", JumpPlanner::Seed),
            ],
        )?)
    } else if is("galvo") {
        keyword(&mut args, "status", &[("status", Command::GalvoStatus)])?
    } else if is("save") {
        Command::Save
    } else if is("pattern") {
        return parse_pattern(args).map(Some);
    } else if is("goto") {
        Command::Goto(point(&mut args, "x_cm", "y_cm")?)
    } else if is("grid") {
        let xi = args.integer("xi", -GRID_INDEX_LIMIT, GRID_INDEX_LIMIT)? as i8;
        let yi = args.integer("yi", -GRID_INDEX_LIMIT, GRID_INDEX_LIMIT)? as i8;
        Command::Grid { xi, yi }
    } else if is("laser") {
        // `on` enables the laser for runs: SPEC §9 keeps it off whenever no
        // pattern or goto is active, so `on` is `auto`.
        Command::Laser(keyword(
            &mut args,
            "on|off|auto|dwell",
            &[
                ("on", LaserMode::Auto),
                ("off", LaserMode::Off),
                ("auto", LaserMode::Auto),
                ("dwell", LaserMode::Dwell),
            ],
        )?)
    } else if is("model") {
        Command::Model(keyword(
            &mut args,
            "exact|seed",
            &[("exact", AimModel::Exact), ("seed", AimModel::Seed)],
        )?)
    } else if is("set") {
        let name = args.word("parameter name")?;
        let param = find_param(name).ok_or(CommandError::InvalidArgument {
            expected: "a parameter name (see 'params')",
            got: word(name),
        })?;
        let value = args.number(param.name, param.min, param.max)?;
        Command::Set { param, value }
    } else if is("get") {
        let name = args.word("parameter name")?;
        Command::Get(find_param(name).ok_or(CommandError::InvalidArgument {
            expected: "a parameter name (see 'params')",
            got: word(name),
        })?)
    } else {
        return Err(CommandError::UnknownCommand(word(name)));
    };
    args.finish()?;
    Ok(Some(command))
}

fn point(args: &mut Args<'_>, x: &'static str, y: &'static str) -> Result<PointCm, CommandError> {
    Ok(PointCm {
        x_cm: args.number(x, -BOARD_LIMIT_CM, BOARD_LIMIT_CM)?,
        y_cm: args.number(y, -BOARD_LIMIT_CM, BOARD_LIMIT_CM)?,
    })
}

/// `pattern <name> [args] [once]`.
fn parse_pattern(mut args: Args<'_>) -> Result<Command, CommandError> {
    let name = args.word("pattern name (see 'help')")?;
    let is = |candidate: &str| name.eq_ignore_ascii_case(candidate);
    let pattern = if is("grid-full") {
        // Optional order word; anything else is left for `once`.
        let mut peek = args.clone();
        match peek.next_word() {
            Some(w) if w.eq_ignore_ascii_case("serpentine") => {
                args = peek;
                Pattern::Grid(GridPattern::FullSerpentine)
            }
            Some(w) if w.eq_ignore_ascii_case("raster") => {
                args = peek;
                Pattern::Grid(GridPattern::FullRaster)
            }
            _ => Pattern::Grid(GridPattern::FullRaster),
        }
    } else if let Some(grid) = GridPattern::from_name(name) {
        // home, corner, horizontal, vertical, visit-all
        Pattern::Grid(grid)
    } else if is("line") {
        let (from, to) = (
            point(&mut args, "x0_cm", "y0_cm")?,
            point(&mut args, "x1_cm", "y1_cm")?,
        );
        if libm::fabs(to.x_cm - from.x_cm).max(libm::fabs(to.y_cm - from.y_cm)) < MIN_FIGURE_CM {
            return Err(CommandError::Rejected(
                "a line needs end points at least 0.1 cm apart (goto holds a single point)",
            ));
        }
        Pattern::Path(Figure::Line { from, to })
    } else if is("tuning") {
        // Optional centre and size; defaults: a 4 cm figure at the origin.
        let mut peek = args.clone();
        match peek.next_word() {
            Some(w) if !w.eq_ignore_ascii_case("once") => Pattern::Path(Figure::Tuning {
                centre: point(&mut args, "cx_cm", "cy_cm")?,
                size_cm: args.number("size_cm", MIN_FIGURE_CM, BOARD_LIMIT_CM)?,
            }),
            _ => Pattern::Path(Figure::Tuning {
                centre: PointCm {
                    x_cm: 0.0,
                    y_cm: 0.0,
                },
                size_cm: 4.0,
            }),
        }
    } else if is("rect") {
        let (a, b) = (
            point(&mut args, "x0_cm", "y0_cm")?,
            point(&mut args, "x1_cm", "y1_cm")?,
        );
        if libm::fabs(b.x_cm - a.x_cm).min(libm::fabs(b.y_cm - a.y_cm)) < MIN_FIGURE_CM {
            return Err(CommandError::Rejected(
                "a rect needs a width and a height of at least 0.1 cm (use line for one side)",
            ));
        }
        Pattern::Path(Figure::Rect { a, b })
    } else if is("circle") {
        let centre = point(&mut args, "cx_cm", "cy_cm")?;
        let radius_cm = args.number("radius_cm", MIN_FIGURE_CM, BOARD_LIMIT_CM)?;
        let mut peek = args.clone();
        let rotation = match peek.next_word() {
            Some(w) if w.eq_ignore_ascii_case("cw") => {
                args = peek;
                Rotation::Cw
            }
            Some(w) if w.eq_ignore_ascii_case("ccw") => {
                args = peek;
                Rotation::Ccw
            }
            _ => Rotation::Ccw,
        };
        Pattern::Path(Figure::Circle {
            centre,
            radius_cm,
            rotation,
        })
    } else {
        return Err(CommandError::InvalidArgument {
            expected: "home|corner|horizontal|vertical|visit-all|grid-full|line|circle|rect|tuning",
            got: word(name),
        });
    };
    let once = match args.next_word() {
        None => false,
        Some(w) if w.eq_ignore_ascii_case("once") => true,
        Some(w) => return Err(CommandError::UnexpectedArgument(word(w))),
    };
    args.finish()?;
    Ok(Command::Pattern { pattern, once })
}

/// The next word as one of `choices` (ASCII case-insensitive); `expected`
/// names them in the error.
fn keyword<T: Copy>(
    args: &mut Args<'_>,
    expected: &'static str,
    choices: &[(&str, T)],
) -> Result<T, CommandError> {
    let given = args.word(expected)?;
    choices
        .iter()
        .find(|(name, _)| name.eq_ignore_ascii_case(given))
        .map(|&(_, value)| value)
        .ok_or(CommandError::InvalidArgument {
            expected,
            got: word(given),
        })
}

/// One line per command for `help`.
pub const HELP_LINES: &[&str] = &[
    "pattern home|corner|horizontal|vertical|visit-all [once]",
    "pattern grid-full [raster|serpentine] [once]",
    "pattern line <x0_cm> <y0_cm> <x1_cm> <y1_cm> [once]",
    "pattern circle <cx_cm> <cy_cm> <radius_cm> [cw|ccw] [once]",
    "pattern rect <x0_cm> <y0_cm> <x1_cm> <y1_cm> [once]",
    "pattern tuning [<cx_cm> <cy_cm> <size_cm>] [once]   (galvo)",
    "stop                         stop the pattern, laser off",
    "goto <x_cm> <y_cm>           aim at a board point",
    "grid <xi> <yi>               aim at a grid point",
    "laser on|off|auto|dwell      laser mode",
    "model exact|seed             gimbal kinematic model",
    "target gimbal|galvo|both     which actuator draws",
    "planner optimal|seed         galvo jump planner",
    "galvo status                 galvo loop state, underruns",
    "set <param> <value>          change a parameter",
    "get <param>                  read a parameter",
    "params                       list parameters",
    "save                         store parameters in flash",
    "status                       state, target, faults",
    "version                      firmware version",
    "help                         this list",
];

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
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
            "goto 1 1",
            "grid 1 1",
            "laser on",
            "model exact",
            "target both",
            "planner seed",
            "galvo status",
            "set dwell_ms 1",
            "get dwell_ms",
            "params",
            "save",
            "status",
            "version",
            "help",
        ];
        assert_eq!(examples.len(), HELP_LINES.len());
        for (line, example) in HELP_LINES.iter().zip(examples) {
            let name = line.split_ascii_whitespace().next().unwrap_or("");
            assert!(example.starts_with(name));
            assert!(matches!(parse_line(example), Ok(Some(_))), "{example}");
        }
    }
}
