//! `cargo xtask plan …`: galvo jump planning from the command line.
//!
//! * `plan jump --from-deg A --to-deg B --method seed|optimal|tcurve|scurve
//!   [--model rigid|flexible] [--ts-us 10] [--p 8] [--csv FILE] [--plot FILE.svg]`
//!   plans one rest-to-rest jump (mechanical degrees), prints one JSON object
//!   and optionally writes the sampled trajectory as CSV and an SVG plot.
//! * `plan compare` prints a table of move time, ratio to the time-optimal
//!   planner and peak voltage for every method over 0.05°…20°.
//!
//! Model parameters default to the reference galvo of SPEC §6 and can be
//! overridden with `--kt-nm-per-a`, `--j-kg-m2`, `--l-h`, `--r-ohm`,
//! `--umax-v` (and `--jm-kg-m2`, `--jl-kg-m2`, `--k-nm-per-rad` or
//! `--resonance-hz` for the flexible model).

mod compare;
mod method;
mod model;
mod plot;
mod row;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use galvo_planner::jump::plan_jump;
use galvo_planner::model::Discrete;
use serde::Serialize;

use crate::json_out::{fail, print_json};
pub(crate) use method::MethodArg;
pub(crate) use model::{Built, ModelArgs};
pub(crate) use row::Row;

/// `cargo xtask plan …`
#[derive(clap::Args, Debug)]
pub struct PlanArgs {
    #[command(subcommand)]
    command: PlanCommand,
}

#[derive(clap::Subcommand, Debug)]
enum PlanCommand {
    /// Plan one rest-to-rest jump; prints a JSON summary on stdout.
    Jump(JumpArgs),
    /// Compare the planners over step sizes 0.05°…20° (markdown table).
    Compare(CompareArgs),
}

#[derive(clap::Args, Debug)]
struct JumpArgs {
    /// Start angle, mechanical degrees.
    #[arg(long, allow_hyphen_values = true)]
    from_deg: f64,
    /// Target angle, mechanical degrees.
    #[arg(long, allow_hyphen_values = true)]
    to_deg: f64,
    /// Planner.
    #[arg(long, value_enum)]
    method: MethodArg,
    #[command(flatten)]
    model: ModelArgs,
    /// Seed planner: number of bisection halvings (precision (Tmax−Tmin)/2^p; at most 64 are used).
    #[arg(long = "p", default_value_t = 8)]
    p: u32,
    /// Largest number of samples the move may take (the buffer size).
    #[arg(long, default_value_t = 1_000_000)]
    capacity: usize,
    /// Write the sampled trajectory here (k,t_s,theta_rad,omega_rad_s,current_a,u_v[,phi_rad,omega_load_rad_s]).
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Write an SVG plot of position, velocity, current and voltage here.
    #[arg(long)]
    plot: Option<PathBuf>,
}

#[derive(clap::Args, Debug)]
struct CompareArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// Seed planner halvings.
    #[arg(long = "p", default_value_t = 8)]
    p: u32,
    /// Step sizes, mechanical degrees (comma separated).
    #[arg(long, value_delimiter = ',', default_values_t = compare::DEFAULT_STEPS_DEG)]
    steps_deg: Vec<f64>,
    /// Print JSON rows instead of the markdown table.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct JumpSummary {
    method: &'static str,
    model: &'static str,
    move_time_s: f64,
    samples: usize,
    max_abs_u_v: f64,
    final_theta_error_rad: f64,
}

/// Entry point called by `xtask/src/main.rs`.
pub fn run(args: PlanArgs) -> anyhow::Result<ExitCode> {
    match args.command {
        PlanCommand::Jump(a) => run_jump(&a),
        PlanCommand::Compare(a) => compare::run(&a.model, a.p, &a.steps_deg, a.json),
    }
}

fn run_jump(args: &JumpArgs) -> anyhow::Result<ExitCode> {
    let built = match args.model.build() {
        Ok(b) => b,
        Err(e) => return fail(e),
    };
    let result = match &built {
        Built::Rigid(d) => jump_rows(d, args),
        Built::Flexible(d) => jump_rows(d, args),
    };
    let (rows, target_rad, max_abs_u_v) = match result {
        Ok(r) => r,
        Err(e) => return fail(e),
    };
    let ts = args.model.ts_s();
    let n = rows.len().saturating_sub(1);
    let last = rows.last().map_or(target_rad, |r| r.theta_rad);
    if let Some(path) = &args.csv
        && let Err(e) = write_csv(path, &rows)
    {
        return fail(format!("{e:#}"));
    }
    if let Some(path) = &args.plot {
        let title = format!(
            "{} jump {}° → {}° ({} model, Ts = {} µs)",
            args.method.name(),
            args.from_deg,
            args.to_deg,
            args.model.model.name(),
            args.model.ts_us
        );
        let u_max = match &built {
            Built::Rigid(d) => d.u_max_v(),
            Built::Flexible(d) => d.u_max_v(),
        };
        if let Err(e) = plot::jump_svg(path, &title, &rows, u_max) {
            return fail(format!("{e:#}"));
        }
    }
    print_json(&JumpSummary {
        method: args.method.name(),
        model: args.model.model.name(),
        move_time_s: n as f64 * ts,
        samples: n,
        max_abs_u_v,
        final_theta_error_rad: last - target_rad,
    })?;
    Ok(ExitCode::SUCCESS)
}

/// Plans the jump and simulates it: rows k = 0..=N, the target angle and
/// the peak |U|.
fn jump_rows<const S: usize>(
    disc: &Discrete<S>,
    args: &JumpArgs,
) -> Result<(Vec<Row>, f64, f64), String> {
    if !args.from_deg.is_finite() || !args.to_deg.is_finite() {
        return Err("from_deg and to_deg must be finite numbers".into());
    }
    let from = args.from_deg.to_radians();
    let to = args.to_deg.to_radians();
    let plan = plan_jump(disc, from, to, args.method.method(args.p), args.capacity)
        .map_err(|e| e.to_string())?;
    let rows = simulate_rows(disc, &plan)?;
    Ok((rows, to, plan.max_abs_u_v()))
}

/// The exact ZOH simulation of the plan's voltages from its start state.
pub(crate) fn simulate_rows<const S: usize>(
    disc: &Discrete<S>,
    plan: &galvo_planner::JumpPlan<S>,
) -> Result<Vec<Row>, String> {
    let mut u = vec![0.0; plan.samples()];
    plan.write_u_v(&mut u).map_err(|e| e.to_string())?;
    let ts = disc.ts_s();
    let mut rows = Vec::with_capacity(u.len() + 1);
    disc.simulate(plan.start_state(), &u, |k, z, uk| {
        let at = |i: usize| z.get(i).copied().unwrap_or(0.0);
        rows.push(Row {
            k,
            t_s: k as f64 * ts,
            theta_rad: at(0),
            omega_rad_s: at(1),
            current_a: at(2),
            u_v: uk,
            load: (S == 5).then(|| (at(3), at(4))),
        });
    });
    Ok(rows)
}

fn write_csv(path: &Path, rows: &[Row]) -> anyhow::Result<()> {
    let mut w =
        csv::Writer::from_path(path).with_context(|| format!("cannot write {}", path.display()))?;
    let flexible = rows.first().is_some_and(|r| r.load.is_some());
    let mut header = vec!["k", "t_s", "theta_rad", "omega_rad_s", "current_a", "u_v"];
    if flexible {
        header.extend(["phi_rad", "omega_load_rad_s"]);
    }
    w.write_record(&header)?;
    // `{:?}` prints the shortest representation that reads back to the
    // same f64, so the file holds the simulation exactly.
    for r in rows {
        let mut rec = vec![
            r.k.to_string(),
            format!("{:?}", r.t_s),
            format!("{:?}", r.theta_rad),
            format!("{:?}", r.omega_rad_s),
            format!("{:?}", r.current_a),
            format!("{:?}", r.u_v),
        ];
        if let Some((phi, wl)) = r.load {
            rec.push(format!("{phi:?}"));
            rec.push(format!("{wl:?}"));
        }
        w.write_record(&rec)?;
    }
    w.flush()
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}

#[cfg(test)]
mod tests;
