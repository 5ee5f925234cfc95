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

use crate::json_out::emit;

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
mod tests;
