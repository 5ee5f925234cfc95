//! `cargo xtask kin …`: gimbal kinematics from the command line.
//!
//! * `kin ik [--model exact|seed] --x-cm X --y-cm Y [--oq-cm 25 --ol-cm 5.4]`
//!   prints `{"yaw_deg":…,"pitch_deg":…}` (joint angles for a board point,
//!   within the default ±135° servo limits);
//! * `kin fk [--model exact|seed] --yaw-deg A --pitch-deg B [...]` prints
//!   `{"x_cm":…,"y_cm":…}`;
//! * errors of both print `{"error":"…"}` and exit 1;
//! * `kin grid-error [--oq-cm … --ol-cm … --pitch-cm … --cols … --rows …]`
//!   prints the seed model's pointing error (mm, the spot computed with the
//!   exact model) at every grid point as a table, then its maximum.
//!
//! `--x-offset-cm`, `--y-offset-cm` (the seed's board offsets) and
//! `--roll-deg` (board rotation about global x) are accepted everywhere.

use std::fmt::Write as _;
use std::process::ExitCode;

use kinematics_core::{
    BoardFrame, BoardPoint, BoardPose, Gimbal, GimbalGeometry, GimbalModel, Grid, GridIndex,
    JointAngles, Pattern,
};
use serde::Serialize;

/// `cargo xtask kin …`
#[derive(clap::Args, Debug)]
pub struct KinArgs {
    #[command(subcommand)]
    command: KinCommand,
}

#[derive(clap::Subcommand, Debug)]
enum KinCommand {
    /// Joint angles (deg) that put the spot on a board point (cm); JSON.
    Ik(IkArgs),
    /// Board point (cm) of the spot for joint angles (deg); JSON.
    Fk(FkArgs),
    /// Seed model's pointing error at every grid point (table) and its maximum.
    GridError(GridErrorArgs),
}

/// Gimbal model on the command line.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum ModelArg {
    /// Exact coupled model (SPEC §4.3).
    Exact,
    /// The seed's model (SPEC §4.2).
    Seed,
}

impl From<ModelArg> for GimbalModel {
    fn from(m: ModelArg) -> Self {
        match m {
            ModelArg::Exact => GimbalModel::Exact,
            ModelArg::Seed => GimbalModel::Seed,
        }
    }
}

/// Geometry options shared by every subcommand.
#[derive(clap::Args, Debug, Clone)]
struct GeometryArgs {
    /// Gimbal centre to board origin distance OQ, cm.
    #[arg(long, default_value_t = 25.0, allow_hyphen_values = true)]
    oq_cm: f64,
    /// Laser axis offset OL, cm.
    #[arg(long, default_value_t = 5.4, allow_hyphen_values = true)]
    ol_cm: f64,
    /// Seed XB_OFFSET: added to every board x, cm.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    x_offset_cm: f64,
    /// Seed YB_OFFSET: added to every board y, cm.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    y_offset_cm: f64,
    /// Board rotation about global x (mounting error), deg.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    roll_deg: f64,
}

impl GeometryArgs {
    fn gimbal(&self, model: GimbalModel) -> Gimbal {
        Gimbal {
            model,
            geometry: GimbalGeometry {
                ol_cm: self.ol_cm,
                frame: BoardFrame {
                    oq_cm: self.oq_cm,
                    x_offset_cm: self.x_offset_cm,
                    y_offset_cm: self.y_offset_cm,
                    pose: BoardPose {
                        roll_deg: self.roll_deg,
                        ..BoardPose::default()
                    },
                },
                ..GimbalGeometry::default()
            },
        }
    }
}

#[derive(clap::Args, Debug)]
struct IkArgs {
    /// Gimbal model.
    #[arg(long, value_enum, default_value_t = ModelArg::Exact)]
    model: ModelArg,
    /// Board x of the target, cm.
    #[arg(long, allow_hyphen_values = true)]
    x_cm: f64,
    /// Board y of the target, cm.
    #[arg(long, allow_hyphen_values = true)]
    y_cm: f64,
    #[command(flatten)]
    geometry: GeometryArgs,
}

#[derive(clap::Args, Debug)]
struct FkArgs {
    /// Gimbal model.
    #[arg(long, value_enum, default_value_t = ModelArg::Exact)]
    model: ModelArg,
    /// Yaw joint angle α, deg.
    #[arg(long, allow_hyphen_values = true)]
    yaw_deg: f64,
    /// Pitch joint angle β, deg.
    #[arg(long, allow_hyphen_values = true)]
    pitch_deg: f64,
    #[command(flatten)]
    geometry: GeometryArgs,
}

#[derive(clap::Args, Debug)]
struct GridErrorArgs {
    #[command(flatten)]
    geometry: GeometryArgs,
    /// Grid pitch, cm.
    #[arg(long, default_value_t = kinematics_core::grid::DEFAULT_PITCH_CM, allow_hyphen_values = true)]
    pitch_cm: f64,
    /// Grid cells across (even).
    #[arg(long, default_value_t = kinematics_core::grid::DEFAULT_COLS)]
    cols: u8,
    /// Grid cells down (even).
    #[arg(long, default_value_t = kinematics_core::grid::DEFAULT_ROWS)]
    rows: u8,
}

#[derive(Serialize)]
struct IkOut {
    yaw_deg: f64,
    pitch_deg: f64,
}

#[derive(Serialize)]
struct FkOut {
    x_cm: f64,
    y_cm: f64,
}

#[derive(Serialize)]
struct ErrorOut {
    error: String,
}

/// Runs `kin …`.
pub fn run(args: KinArgs) -> anyhow::Result<ExitCode> {
    match args.command {
        KinCommand::Ik(a) => Ok(emit(ik_json(&a))),
        KinCommand::Fk(a) => Ok(emit(fk_json(&a))),
        KinCommand::GridError(a) => {
            let report = grid_error(&a).map_err(|e| anyhow::anyhow!("kin grid-error: {e}"))?;
            print!("{}", report.table());
            Ok(ExitCode::SUCCESS)
        }
    }
}

/// Prints the JSON result line; errors as `{"error":"…"}` with exit 1.
fn emit(result: Result<String, String>) -> ExitCode {
    match result {
        Ok(json) => {
            println!("{json}");
            ExitCode::SUCCESS
        }
        Err(msg) => {
            println!("{}", error_json(&msg));
            ExitCode::FAILURE
        }
    }
}

pub(crate) fn error_json(msg: &str) -> String {
    serde_json::to_string(&ErrorOut {
        error: msg.to_owned(),
    })
    .unwrap_or_else(|_| String::from(r#"{"error":"unprintable error"}"#))
}

fn ik_json(a: &IkArgs) -> Result<String, String> {
    let gimbal = a.geometry.gimbal(a.model.into());
    let j = gimbal
        .ik(BoardPoint::new(a.x_cm, a.y_cm))
        .map_err(|e| e.to_string())?;
    serde_json::to_string(&IkOut {
        yaw_deg: j.yaw_deg,
        pitch_deg: j.pitch_deg,
    })
    .map_err(|e| e.to_string())
}

fn fk_json(a: &FkArgs) -> Result<String, String> {
    let gimbal = a.geometry.gimbal(a.model.into());
    let p = gimbal
        .fk(JointAngles {
            yaw_deg: a.yaw_deg,
            pitch_deg: a.pitch_deg,
        })
        .map_err(|e| e.to_string())?;
    serde_json::to_string(&FkOut {
        x_cm: p.x_cm,
        y_cm: p.y_cm,
    })
    .map_err(|e| e.to_string())
}

/// Seed and exact pointing errors over the grid.
#[derive(Debug)]
struct GridErrorReport {
    /// What was evaluated (first line of the table).
    title: String,
    /// Largest column index (the table has `2·max_xi + 1` columns).
    max_xi: i8,
    /// `(index, seed error mm, exact error mm)` in raster order.
    errors: Vec<(GridIndex, f64, f64)>,
    max_seed_mm: f64,
    max_at: Vec<GridIndex>,
    max_exact_mm: f64,
}

impl GridErrorReport {
    /// Rows `yi` (top down) by columns `xi`, seed error in mm, then the
    /// maxima.
    fn table(&self) -> String {
        let mut t = String::new();
        let _ = writeln!(t, "{}", self.title);
        let _ = write!(t, "{:>6}", "yi\\xi");
        for xi in -self.max_xi..=self.max_xi {
            let _ = write!(t, "{xi:>7}");
        }
        t.push('\n');
        let width = 2 * usize::from(self.max_xi.unsigned_abs()) + 1;
        for row in self.errors.chunks(width) {
            if let Some(first) = row.first() {
                let _ = write!(t, "{:>6}", first.0.yi);
            }
            for e in row {
                let _ = write!(t, "{:>7.2}", e.1);
            }
            t.push('\n');
        }
        let at: Vec<String> = self
            .max_at
            .iter()
            .map(|i| format!("({}, {})", i.xi, i.yi))
            .collect();
        let _ = writeln!(
            t,
            "max seed-model error: {:.3} mm at {}",
            self.max_seed_mm,
            at.join(", ")
        );
        let _ = writeln!(t, "max exact-model error: {:.3e} mm", self.max_exact_mm);
        t
    }
}

fn grid_error(a: &GridErrorArgs) -> Result<GridErrorReport, String> {
    let grid = Grid {
        pitch_cm: a.pitch_cm,
        cols: a.cols,
        rows: a.rows,
        ..Grid::default()
    };
    let seed = a.geometry.gimbal(GimbalModel::Seed);
    let exact = a.geometry.gimbal(GimbalModel::Exact);
    let err = |e: kinematics_core::Error, idx: GridIndex| {
        format!("grid point ({}, {}): {e}", idx.xi, idx.yi)
    };
    let points = Pattern::FullRaster
        .points(&grid)
        .map_err(|e| e.to_string())?;
    let mut errors: Vec<(GridIndex, f64, f64)> = Vec::new();
    for (idx, p) in points.with_indices() {
        let seed_mm = seed.pointing_error_cm(p).map_err(|e| err(e, idx))? * 10.0;
        let exact_mm = exact.pointing_error_cm(p).map_err(|e| err(e, idx))? * 10.0;
        errors.push((idx, seed_mm, exact_mm));
    }
    let max_seed_mm = errors.iter().map(|e| e.1).fold(0.0, f64::max);
    let max_exact_mm = errors.iter().map(|e| e.2).fold(0.0, f64::max);
    // Symmetric points tie up to rounding.
    let max_at: Vec<GridIndex> = errors
        .iter()
        .filter(|e| e.1 >= max_seed_mm - 1e-9)
        .map(|e| e.0)
        .collect();
    let g = &a.geometry;
    let title = format!(
        "Seed-model pointing error, mm (seed IK, spot by exact FK): OQ {} cm, OL {} cm, \
         pitch {} cm, {} x {} cells, offsets ({}, {}) cm, roll {} deg",
        g.oq_cm, g.ol_cm, a.pitch_cm, a.cols, a.rows, g.x_offset_cm, g.y_offset_cm, g.roll_deg
    );
    Ok(GridErrorReport {
        title,
        max_xi: grid.max_xi(),
        errors,
        max_seed_mm,
        max_at,
        max_exact_mm,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        kin: KinArgs,
    }

    fn parse(cmd: &str) -> KinCommand {
        let argv = std::iter::once("kin").chain(cmd.split_whitespace());
        Cli::try_parse_from(argv).unwrap().kin.command
    }

    fn json(s: &str) -> serde_json::Value {
        serde_json::from_str(s).unwrap()
    }

    fn ik(cmd: &str) -> Result<String, String> {
        match parse(cmd) {
            KinCommand::Ik(a) => ik_json(&a),
            _ => unreachable!(),
        }
    }

    fn fk(cmd: &str) -> Result<String, String> {
        match parse(cmd) {
            KinCommand::Fk(a) => fk_json(&a),
            _ => unreachable!(),
        }
    }

    #[test]
    fn ik_prints_exactly_yaw_then_pitch() {
        let out = ik("ik --model exact --x-cm 0 --y-cm 0").unwrap();
        assert!(out.starts_with(r#"{"yaw_deg":"#), "{out}");
        let v = json(&out);
        assert_eq!(v.as_object().unwrap().len(), 2);
        // Board origin: β = 90° − acos(OL/OQ).
        let pitch = 90.0 - (5.4f64 / 25.0).acos().to_degrees();
        assert!((v["pitch_deg"].as_f64().unwrap() - pitch).abs() < 1e-12);
        assert_eq!(v["yaw_deg"].as_f64().unwrap(), 0.0);
    }

    #[test]
    fn ik_then_fk_round_trips_with_negative_numbers_and_options() {
        let v =
            json(&ik("ik --model exact --x-cm -11.496 --y-cm 7.664 --oq-cm 30 --ol-cm 4").unwrap());
        let (yaw, pitch) = (
            v["yaw_deg"].as_f64().unwrap(),
            v["pitch_deg"].as_f64().unwrap(),
        );
        // Board x < 0 is global +y: positive yaw = atan(11.496 / 30).
        assert!((yaw - (11.496f64 / 30.0).atan().to_degrees()).abs() < 1e-12);
        let p = json(
            &fk(&format!(
                "fk --model exact --yaw-deg {yaw} --pitch-deg {pitch} --oq-cm 30 --ol-cm 4"
            ))
            .unwrap(),
        );
        assert!((p["x_cm"].as_f64().unwrap() + 11.496).abs() < 1e-9);
        assert!((p["y_cm"].as_f64().unwrap() - 7.664).abs() < 1e-9);
    }

    #[test]
    fn seed_and_exact_differ_off_axis_and_model_defaults_to_exact() {
        let seed = json(&ik("ik --model seed --x-cm 11.496 --y-cm -7.664").unwrap());
        let exact = json(&ik("ik --model exact --x-cm 11.496 --y-cm -7.664").unwrap());
        let default = json(&ik("ik --x-cm 11.496 --y-cm -7.664").unwrap());
        assert_eq!(default, exact);
        assert_eq!(seed["yaw_deg"], exact["yaw_deg"]);
        assert!(
            (seed["pitch_deg"].as_f64().unwrap() - exact["pitch_deg"].as_f64().unwrap()).abs()
                > 0.1
        );
    }

    #[test]
    fn errors_are_json() {
        let e = ik("ik --model exact --x-cm 0 --y-cm 0 --oq-cm 3").unwrap_err();
        assert!(e.contains("offset circle"), "{e}");
        let line = error_json(&e);
        assert_eq!(json(&line)["error"].as_str(), Some(e.as_str()));
        let e = ik("ik --x-cm nan --y-cm 0").unwrap_err();
        assert!(e.contains("x_cm"), "{e}");
        let e = ik("ik --x-cm 0 --y-cm 0 --oq-cm -5").unwrap_err();
        assert!(e.contains("behind the gimbal"), "{e}");
        let e = fk("fk --model seed --yaw-deg 90 --pitch-deg 0").unwrap_err();
        assert!(e.contains("does not hit the board"), "{e}");
        let e = fk("fk --yaw-deg 0 --pitch-deg 0 --ol-cm -1").unwrap_err();
        assert!(e.contains("ol_cm"), "{e}");
        assert!(
            Cli::try_parse_from([
                "kin", "ik", "--model", "approx", "--x-cm", "0", "--y-cm", "0"
            ])
            .is_err()
        );
    }

    #[test]
    fn grid_error_defaults_max_about_14_mm_at_the_corners() {
        let KinCommand::GridError(a) = parse("grid-error") else {
            unreachable!()
        };
        let r = grid_error(&a).unwrap();
        assert!((13.0..15.0).contains(&r.max_seed_mm), "{}", r.max_seed_mm);
        assert!(r.max_exact_mm < 1e-9);
        assert!(!r.max_at.is_empty());
        assert!(r.max_at.iter().all(|i| i.xi.abs() == 6 && i.yi.abs() == 4));
        // Header, column line, 9 rows, two summary lines.
        let table = r.table();
        assert_eq!(table.lines().count(), 2 + 9 + 2);
        assert!(table.contains("max seed-model error:"));
        // Rows yi = 4..−4; the centre column (xi = 0, no yaw) has no seed
        // error, and mirroring the board left–right mirrors the error.
        let rows: Vec<Vec<f64>> = table
            .lines()
            .skip(2)
            .take(9)
            .map(|l| l.split_whitespace().map(|c| c.parse().unwrap()).collect())
            .collect();
        for (row, yi) in rows.iter().zip((-4..=4).rev()) {
            assert_eq!(row.len(), 14);
            assert_eq!(row[0], f64::from(yi));
            assert_eq!(row[7], 0.0);
            for k in 1..=6 {
                assert_eq!(row[7 - k], row[7 + k]);
            }
        }
    }

    #[test]
    fn grid_error_rejects_bad_grids() {
        let KinCommand::GridError(a) = parse("grid-error --cols 11") else {
            unreachable!()
        };
        assert!(grid_error(&a).unwrap_err().contains("even"));
        let KinCommand::GridError(a) = parse("grid-error --oq-cm 2 --pitch-cm 0.1") else {
            unreachable!()
        };
        assert!(grid_error(&a).unwrap_err().contains("offset circle"));
    }
}
