//! `plan compare`: every planner over the acceptance step sizes.

use std::process::ExitCode;

use galvo_planner::model::Discrete;
use galvo_planner::{JumpPlan, Method, plan_jump};
use serde::Serialize;

use super::method::MethodArg;
use super::model::{Built, ModelArg, ModelArgs};
use crate::json_out::{fail, print_json};

/// 0.05° … 20° mechanical.
pub(crate) const DEFAULT_STEPS_DEG: [f64; 9] = [0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0];

/// Capacity used for the comparison (large: the table is about times).
const CAPACITY: usize = 10_000_000;

#[derive(Serialize, Clone)]
struct Entry {
    step_deg: f64,
    method: &'static str,
    samples: usize,
    move_time_s: f64,
    ratio_to_optimal: f64,
    max_abs_u_v: f64,
    within_u_max: bool,
    landing_error_theta_rad: f64,
}

fn entry<const S: usize>(
    step_deg: f64,
    method: MethodArg,
    plan: &JumpPlan<S>,
    t_opt: f64,
) -> Entry {
    let t = plan.move_time_s();
    Entry {
        step_deg,
        method: method.name(),
        samples: plan.samples(),
        move_time_s: t,
        ratio_to_optimal: t / t_opt,
        max_abs_u_v: plan.max_abs_u_v(),
        within_u_max: plan.within_voltage_limit(),
        landing_error_theta_rad: plan.landing_error().first().copied().unwrap_or(0.0),
    }
}

fn plan_one<const S: usize>(
    d: &Discrete<S>,
    step_deg: f64,
    m: Method,
) -> Result<JumpPlan<S>, String> {
    plan_jump(d, 0.0, step_deg.to_radians(), m, CAPACITY)
        .map_err(|e| format!("{step_deg}° {}: {e}", m.name()))
}

fn rows_for<const S: usize>(
    d: &Discrete<S>,
    reference: &Discrete<3>,
    steps: &[f64],
    p: u32,
) -> Result<Vec<Entry>, String> {
    let mut out = Vec::new();
    for &step in steps {
        if !(step.is_finite() && step > 0.0) {
            return Err(format!("step sizes must be positive (got {step})"));
        }
        let opt = plan_one(reference, step, Method::TimeOptimal)?;
        let t_opt = opt.move_time_s();
        out.push(entry(step, MethodArg::Optimal, &opt, t_opt));
        for m in [MethodArg::Seed, MethodArg::Tcurve, MethodArg::Scurve] {
            let plan = plan_one(d, step, m.method(p))?;
            out.push(entry(step, m, &plan, t_opt));
        }
    }
    Ok(out)
}

pub(crate) fn run(
    model: &ModelArgs,
    p: u32,
    steps: &[f64],
    json: bool,
) -> anyhow::Result<ExitCode> {
    let built = match model.build() {
        Ok(b) => b,
        Err(e) => return fail(e),
    };
    let result = match &built {
        Built::Rigid(d) => rows_for(d, d, steps, p),
        Built::Flexible(d) => model
            .rigid_equivalent()
            .model()
            .and_then(|m| m.discretize(model.ts_s()))
            .map_err(|e| e.to_string())
            .and_then(|reference| rows_for(d, &reference, steps, p)),
    };
    let rows = match result {
        Ok(r) => r,
        Err(e) => return fail(e),
    };
    if json {
        print_json(&rows)?;
        return Ok(ExitCode::SUCCESS);
    }
    let u_max = match &built {
        Built::Rigid(d) => d.u_max_v(),
        Built::Flexible(d) => d.u_max_v(),
    };
    let opt_label = match model.model {
        ModelArg::Rigid => "optimal",
        ModelArg::Flexible => "optimal (rigid, J = Jm + Jl)",
    };
    println!(
        "{} model, Ts = {} µs, Umax = {} V, seed p = {p}. Time in µs; × = move time / time-optimal move time; \
         peak = largest |U| of the sampled voltage (V, * above Umax).\n",
        model.model.name(),
        model.ts_us,
        u_max
    );
    println!(
        "| step | {opt_label} | peak | seed | × | peak | T-curve | × | peak | S-curve | × | peak |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for chunk in rows.chunks(4) {
        let mut line = format!("| {}° ", chunk.first().map_or(0.0, |e| e.step_deg));
        for (i, e) in chunk.iter().enumerate() {
            let star = if e.within_u_max { "" } else { "*" };
            if i == 0 {
                line += &format!("| {:.0} | {:.1} ", e.move_time_s * 1e6, e.max_abs_u_v);
            } else {
                line += &format!(
                    "| {:.0} | {:.2} | {:.1}{star} ",
                    e.move_time_s * 1e6,
                    e.ratio_to_optimal,
                    e.max_abs_u_v
                );
            }
        }
        println!("{line}|");
    }
    Ok(ExitCode::SUCCESS)
}
