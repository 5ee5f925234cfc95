//! Command-line text → [`Command`].

use super::args::Args;
use super::error::{CommandError, word};
use crate::command::{Command, PresetCommand, ServoSetup};
use crate::domain::{Actuator, AimModel, Figure, GridPattern, Pattern, PointCm, Rotation};
use crate::settings::{JumpPlanner, LaserMode, find_param};

pub use crate::domain::BOARD_LIMIT_CM;

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
    let text = crate::text::trim(line);
    if text.is_empty() || text.starts_with('#') {
        return Ok(None);
    }
    let mut args = Args::new(text);
    let name = args.word("command")?;
    if name.eq_ignore_ascii_case("pattern") {
        return parse_pattern(args).map(Some);
    }
    let command = parse_command(name, &mut args)?;
    args.finish()?;
    Ok(Some(command))
}

/// Every command but `pattern`, named `name`, its arguments from `args`
/// (the caller checks that none are left).
fn parse_command(name: &str, args: &mut Args<'_>) -> Result<Command, CommandError> {
    let is = |candidate: &str| name.eq_ignore_ascii_case(candidate);
    let command = if is("help") {
        Command::Help
    } else if is("version") {
        Command::Version
    } else if is("status") {
        Command::Status
    } else if is("stop") {
        Command::Stop
    } else if is("arm") {
        Command::Arm
    } else if is("home") {
        Command::Home
    } else if is("params") {
        Command::Params
    } else if is("galvo") {
        keyword(args, "status", &[("status", Command::GalvoStatus)])?
    } else if is("save") {
        Command::Save
    } else if is("trace") {
        keyword(
            args,
            "on|off",
            &[("on", Command::Trace(true)), ("off", Command::Trace(false))],
        )?
    } else if is("goto") {
        Command::Goto(point(args, "x_cm", "y_cm")?)
    } else if is("grid") {
        let xi = args.integer("xi", -GRID_INDEX_LIMIT, GRID_INDEX_LIMIT)? as i8;
        let yi = args.integer("yi", -GRID_INDEX_LIMIT, GRID_INDEX_LIMIT)? as i8;
        Command::Grid { xi, yi }
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
    } else if is("servo") {
        Command::Servo(servo_setup(args)?)
    } else if is("preset") {
        Command::Preset(preset(args)?)
    } else if let Some(command) = mode_command(name, args)? {
        command
    } else {
        return Err(CommandError::UnknownCommand(word(name)));
    };
    Ok(command)
}

/// The commands that choose a mode by keyword (`target`, `planner`,
/// `laser`, `model`); `None` when `name` is none of them.
fn mode_command(name: &str, args: &mut Args<'_>) -> Result<Option<Command>, CommandError> {
    let is = |candidate: &str| name.eq_ignore_ascii_case(candidate);
    let command = if is("target") {
        Command::Target(keyword(
            args,
            "gimbal|galvo|both|stepper",
            &[
                ("gimbal", Actuator::Gimbal),
                ("galvo", Actuator::Galvo),
                ("both", Actuator::Both),
                ("stepper", Actuator::Stepper),
            ],
        )?)
    } else if is("planner") {
        Command::Planner(keyword(
            args,
            "optimal|seed",
            &[
                ("optimal", JumpPlanner::Optimal),
                ("seed", JumpPlanner::Seed),
            ],
        )?)
    } else if is("laser") {
        // `on` enables the laser for runs: SPEC §9 keeps it off whenever no
        // pattern or goto is active, so `on` is `auto`.
        Command::Laser(keyword(
            args,
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
            args,
            "exact|seed",
            &[("exact", AimModel::Exact), ("seed", AimModel::Seed)],
        )?)
    } else {
        return Ok(None);
    };
    Ok(Some(command))
}

/// `preset set|clear|goto <n>`, n 1–255.
fn preset(args: &mut Args<'_>) -> Result<PresetCommand, CommandError> {
    let make: fn(u8) -> PresetCommand = keyword(
        args,
        "set|clear|goto",
        &[
            ("set", PresetCommand::Set as fn(u8) -> PresetCommand),
            ("clear", PresetCommand::Clear),
            ("goto", PresetCommand::Goto),
        ],
    )?;
    let n = args.integer("preset number", 1, i32::from(crate::settings::MAX_PRESET))?;
    Ok(make(n as u8))
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
    let pattern = pattern_figure(name, &mut args)?;
    let once = match args.next_word() {
        None => false,
        Some(w) if w.eq_ignore_ascii_case("once") => true,
        Some(w) => return Err(CommandError::UnexpectedArgument(word(w))),
    };
    args.finish()?;
    Ok(Command::Pattern { pattern, once })
}

/// The pattern named `name` with its arguments from `args` (`once` is
/// left there).
fn pattern_figure(name: &str, args: &mut Args<'_>) -> Result<Pattern, CommandError> {
    let is = |candidate: &str| name.eq_ignore_ascii_case(candidate);
    if is("grid-full") {
        Ok(grid_full(args))
    } else if let Some(grid) = GridPattern::from_name(name) {
        // home, corner, horizontal, vertical, visit-all
        Ok(Pattern::Grid(grid))
    } else if is("line") {
        line(args)
    } else if is("tuning") {
        tuning(args)
    } else if is("rect") {
        rect(args)
    } else if is("circle") {
        circle(args)
    } else {
        Err(CommandError::InvalidArgument {
            expected: "home|corner|horizontal|vertical|visit-all|grid-full|line|circle|rect|tuning",
            got: word(name),
        })
    }
}

/// `grid-full [raster|serpentine]`.
fn grid_full(args: &mut Args<'_>) -> Pattern {
    // Optional order word; anything else is left for `once`.
    let mut peek = args.clone();
    match peek.next_word() {
        Some(w) if w.eq_ignore_ascii_case("serpentine") => {
            *args = peek;
            Pattern::Grid(GridPattern::FullSerpentine)
        }
        Some(w) if w.eq_ignore_ascii_case("raster") => {
            *args = peek;
            Pattern::Grid(GridPattern::FullRaster)
        }
        _ => Pattern::Grid(GridPattern::FullRaster),
    }
}

/// `line <x0_cm> <y0_cm> <x1_cm> <y1_cm>`.
fn line(args: &mut Args<'_>) -> Result<Pattern, CommandError> {
    let (from, to) = (
        point(args, "x0_cm", "y0_cm")?,
        point(args, "x1_cm", "y1_cm")?,
    );
    if libm::fabs(to.x_cm - from.x_cm).max(libm::fabs(to.y_cm - from.y_cm)) < MIN_FIGURE_CM {
        return Err(CommandError::Rejected(
            "a line needs end points at least 0.1 cm apart (goto holds a single point)",
        ));
    }
    Ok(Pattern::Path(Figure::Line { from, to }))
}

/// `tuning [<cx_cm> <cy_cm> <size_cm>]`.
fn tuning(args: &mut Args<'_>) -> Result<Pattern, CommandError> {
    // Optional centre and size; defaults: a 4 cm figure at the origin.
    let mut peek = args.clone();
    Ok(match peek.next_word() {
        Some(w) if !w.eq_ignore_ascii_case("once") => Pattern::Path(Figure::Tuning {
            centre: point(args, "cx_cm", "cy_cm")?,
            size_cm: args.number("size_cm", MIN_FIGURE_CM, BOARD_LIMIT_CM)?,
        }),
        _ => Pattern::Path(Figure::Tuning {
            centre: PointCm {
                x_cm: 0.0,
                y_cm: 0.0,
            },
            size_cm: 4.0,
        }),
    })
}

/// `rect <x0_cm> <y0_cm> <x1_cm> <y1_cm>`.
fn rect(args: &mut Args<'_>) -> Result<Pattern, CommandError> {
    let (a, b) = (
        point(args, "x0_cm", "y0_cm")?,
        point(args, "x1_cm", "y1_cm")?,
    );
    if libm::fabs(b.x_cm - a.x_cm).min(libm::fabs(b.y_cm - a.y_cm)) < MIN_FIGURE_CM {
        return Err(CommandError::Rejected(
            "a rect needs a width and a height of at least 0.1 cm (use line for one side)",
        ));
    }
    Ok(Pattern::Path(Figure::Rect { a, b }))
}

/// `circle <cx_cm> <cy_cm> <radius_cm> [cw|ccw]`.
fn circle(args: &mut Args<'_>) -> Result<Pattern, CommandError> {
    let centre = point(args, "cx_cm", "cy_cm")?;
    let radius_cm = args.number("radius_cm", MIN_FIGURE_CM, BOARD_LIMIT_CM)?;
    let mut peek = args.clone();
    let rotation = match peek.next_word() {
        Some(w) if w.eq_ignore_ascii_case("cw") => {
            *args = peek;
            Rotation::Cw
        }
        Some(w) if w.eq_ignore_ascii_case("ccw") => {
            *args = peek;
            Rotation::Ccw
        }
        _ => Rotation::Ccw,
    };
    Ok(Pattern::Path(Figure::Circle {
        centre,
        radius_cm,
        rotation,
    }))
}

/// The next word as one of `choices` (ASCII case-insensitive); `expected`
/// names them in the error.
/// A servo bus id as the set-up commands take it (0–254; 255 is the
/// broadcast address).
fn servo_id(args: &mut Args<'_>, what: &'static str) -> Result<u8, CommandError> {
    let id = args.integer(what, 0, i32::from(fashionstar::MAX_SERVO_ID))?;
    // In 0..=254 by the range check.
    Ok(u8::try_from(id).unwrap_or(fashionstar::MAX_SERVO_ID))
}

/// `servo scan|ping <id>|id <id> <new> [confirm]|zero <id>`.
fn servo_setup(args: &mut Args<'_>) -> Result<ServoSetup, CommandError> {
    #[derive(Clone, Copy)]
    enum Verb {
        Scan,
        Ping,
        Id,
        Zero,
    }
    let verb = keyword(
        args,
        "scan|ping|id|zero",
        &[
            ("scan", Verb::Scan),
            ("ping", Verb::Ping),
            ("id", Verb::Id),
            ("zero", Verb::Zero),
        ],
    )?;
    Ok(match verb {
        Verb::Scan => ServoSetup::Scan,
        Verb::Ping => ServoSetup::Ping(servo_id(args, "id")?),
        Verb::Zero => ServoSetup::Zero(servo_id(args, "id")?),
        Verb::Id => {
            let id = servo_id(args, "id")?;
            let new_id = servo_id(args, "new id")?;
            let confirmed = match args.next_word() {
                None => false,
                Some(w) if w.eq_ignore_ascii_case("confirm") => true,
                Some(w) => {
                    return Err(CommandError::InvalidArgument {
                        expected: "confirm",
                        got: word(w),
                    });
                }
            };
            ServoSetup::SetId {
                id,
                new_id,
                confirmed,
            }
        }
    })
}

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

#[cfg(test)]
mod tests;
