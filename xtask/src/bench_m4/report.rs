//! The bench's output parsed into the table, printed and checked against
//! the budgets.

use anyhow::{Context, Result, bail};
use serde::Serialize;

use super::budgets::{Enforcement, ROWS, Row, plan_row};
use super::gcode_rows::GCODE_ROWS;
use super::pelco_rows::PELCO_ROWS;
use super::stepper_rows::STEPPER_ROWS;

/// Every row with a description: the galvo's, the stepper's, the PELCO
/// port's, the G-code lines'.
fn all_rows() -> impl Iterator<Item = &'static Row> {
    ROWS.iter()
        .chain(STEPPER_ROWS)
        .chain(PELCO_ROWS)
        .chain(GCODE_ROWS)
}

pub use super::budgets::{CLOCK_MHZ, CPI};
/// Instructions per timer tick the board model implies (1 ns per
/// instruction, 25 MHz timer); the calibration must agree within 0.5 %.
const NOMINAL_INSTRUCTIONS_PER_TICK: f64 = 40.0;

/// One measured benchmark.
#[derive(Debug, Clone, Serialize)]
pub struct Measured {
    pub id: String,
    pub what: String,
    pub unit: String,
    /// Guest instructions per unit.
    pub instructions: f64,
    /// Estimated µs per unit on the M4 (CPI × instructions / clock).
    pub est_us: f64,
    pub budget_us: Option<f64>,
    pub budget: Option<String>,
    /// Fraction of the budget used.
    pub share: Option<f64>,
    /// For a sweep's row (`sweep.*`): the dearest input of the seeded
    /// random sweep and how many inputs were tried.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub worst_input: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub inputs_tried: Option<u32>,
    /// For a sweep's row: the median input's instructions per unit.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub median_instructions: Option<f64>,
    /// "enforced" for a row with a budget.
    pub status: Option<String>,
    pub over_budget: bool,
}

/// The run's parsed output.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    pub method: &'static str,
    pub clock_mhz: f64,
    pub cpi: f64,
    pub instructions_per_tick: f64,
    pub rows: Vec<Measured>,
}

/// Estimated µs on the M4 for `instructions`.
pub fn est_us(instructions: f64) -> f64 {
    instructions * CPI / CLOCK_MHZ
}

/// Parses the bench's semihosting output into the table.
pub fn parse(output: &str) -> Result<Report> {
    let mut ipt = None;
    let mut overhead_ticks = 0.0;
    let mut rows = Vec::new();
    let mut errors = Vec::new();
    let mut done = false;
    let mut self_checked = false;
    for line in output.lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        match f.as_slice() {
            ["calibration", instr, ticks] => {
                let instr: f64 = instr.parse().context("calibration instructions")?;
                let ticks: f64 = ticks.parse().context("calibration ticks")?;
                if ticks <= 0.0 {
                    bail!("calibration window read no timer ticks");
                }
                let k = instr / ticks;
                if (k / NOMINAL_INSTRUCTIONS_PER_TICK - 1.0).abs() > 0.005 {
                    bail!(
                        "calibration: {k:.3} instructions per timer tick, expected \
                         {NOMINAL_INSTRUCTIONS_PER_TICK} (is QEMU running with -icount shift=0?)"
                    );
                }
                ipt = Some(k);
            }
            ["empty", ticks, n] => {
                let ticks: f64 = ticks.parse().context("empty ticks")?;
                let n: f64 = n.parse().context("empty count")?;
                overhead_ticks = ticks / n.max(1.0);
            }
            ["bench", id, ticks, units] => {
                let k = ipt.context("bench line before calibration")?;
                let instructions = per_unit(id, ticks, units, k, overhead_ticks)?;
                rows.push(measured(id, instructions));
            }
            ["median", id, ticks, units] => {
                let k = ipt.context("median line before calibration")?;
                let instructions = per_unit(id, ticks, units, k, overhead_ticks)?;
                let row = rows
                    .iter_mut()
                    .find(|m: &&mut Measured| m.id == *id)
                    .with_context(|| format!("median of {id} before its bench line"))?;
                row.median_instructions = Some(instructions);
            }
            ["worst", id, tried, input @ ..] => {
                let row = rows
                    .iter_mut()
                    .find(|m: &&mut Measured| m.id == *id)
                    .with_context(|| format!("worst input of {id} before its bench line"))?;
                row.inputs_tried = Some(tried.parse().with_context(|| format!("inputs of {id}"))?);
                row.worst_input = Some(input.join(" "));
            }
            ["error", id, rest @ ..] => errors.push(format!("{id}: {}", rest.join(" "))),
            ["check", .., "ok", _] => self_checked = true,
            ["done", _] => done = true,
            _ => {}
        }
    }
    if !errors.is_empty() {
        bail!("bench-m4 reported errors: {}", errors.join("; "));
    }
    if !done {
        bail!("bench-m4 did not finish (no `done` line); output:\n{output}");
    }
    for row in rows.iter().filter(|m| m.id.starts_with("sweep.")) {
        if row.worst_input.is_none() {
            bail!("bench-m4 reported `{}` without its worst input", row.id);
        }
    }
    if !self_checked {
        bail!("bench-m4 did not report its on-target self-check (VSQRT, DAC conversion)");
    }
    for row in all_rows().filter(|r| r.budget.is_some()) {
        if !rows.iter().any(|m| m.id == row.id) {
            bail!("bench-m4 did not report `{}`", row.id);
        }
    }
    Ok(Report {
        method: "QEMU mps2-an386 (Cortex-M4F), -icount shift=0: 1 ns per instruction, \
                 25 MHz APB timer 0 = 40 instructions per tick, calibrated on an asm loop",
        clock_mhz: CLOCK_MHZ,
        cpi: CPI,
        instructions_per_tick: ipt.unwrap_or(NOMINAL_INSTRUCTIONS_PER_TICK),
        rows,
    })
}

/// Instructions per unit of a window of `ticks` timer ticks over `units`
/// repetitions (`k` instructions per tick, less the empty window's
/// `overhead_ticks`).
fn per_unit(id: &str, ticks: &str, units: &str, k: f64, overhead_ticks: f64) -> Result<f64> {
    let ticks: f64 = ticks.parse().with_context(|| format!("ticks of {id}"))?;
    let units: f64 = units.parse().with_context(|| format!("units of {id}"))?;
    Ok(((ticks - overhead_ticks).max(0.0) * k) / units.max(1.0))
}

fn measured(id: &str, instructions: f64) -> Measured {
    let row = all_rows().find(|r| r.id == id);
    let (what, unit) = match (row, plan_row(id)) {
        (Some(r), _) => (r.what.to_owned(), r.unit),
        (None, Some((what, unit))) => (what, unit),
        (None, None) => (id.to_owned(), "call"),
    };
    let us = est_us(instructions);
    let budget = row.and_then(|r| r.budget);
    let share = budget.map(|(b, _, _)| us / b);
    Measured {
        id: id.to_owned(),
        what,
        unit: unit.to_owned(),
        instructions,
        est_us: us,
        budget_us: budget.map(|(b, _, _)| b),
        budget: budget.map(|(_, text, _)| text.to_owned()),
        share,
        worst_input: None,
        inputs_tried: None,
        median_instructions: None,
        status: budget.map(|(_, _, e)| match e {
            Enforcement::Enforced => "enforced".to_owned(),
            Enforcement::NotMet {
                why,
                ceiling_instructions,
            } => format!("not met: {why}; enforced: {ceiling_instructions:.0} instructions"),
        }),
        over_budget: budget.is_some_and(|(b, _, e)| match e {
            Enforcement::Enforced => us > b,
            Enforcement::NotMet {
                ceiling_instructions,
                ..
            } => instructions > ceiling_instructions,
        }),
    }
}

/// Prints the table.
pub fn print(report: &Report) {
    println!(
        "M4 instructions (QEMU mps2-an386, -icount; {:.2} instructions/tick); \
         µs estimated at {} MHz, CPI {}",
        report.instructions_per_tick, report.clock_mhz, report.cpi
    );
    println!(
        "{:<34} {:<66} {:>12} {:>10} {:>8}  budget",
        "id", "what", "instr/unit", "est. µs", "share"
    );
    for m in &report.rows {
        let share = m
            .share
            .map_or(String::new(), |s| format!("{:.0} %", 100.0 * s));
        let budget = match (&m.budget, &m.status) {
            (Some(b), Some(s)) => {
                format!("{b}: {s}{}", if m.over_budget { " EXCEEDED" } else { "" })
            }
            _ => String::new(),
        };
        println!(
            "{:<34} {:<66} {:>12.0} {:>10.2} {:>8}  {}",
            m.id,
            format!("{} (per {})", m.what, m.unit),
            m.instructions,
            m.est_us,
            share,
            budget
        );
        if let (Some(input), Some(tried)) = (&m.worst_input, m.inputs_tried) {
            let median = m
                .median_instructions
                .map_or(String::new(), |i| format!(" (median {i:.0})"));
            println!("{:<34}   worst of {tried}{median}: {input}", "");
        }
    }
}

/// Fails when an enforced budget is exceeded.
pub fn check(report: &Report) -> Result<()> {
    let over: Vec<String> = report
        .rows
        .iter()
        .filter(|m| m.over_budget)
        .map(|m| {
            format!(
                "{} ({}): {:.2} µs per {} > {:.2} µs{}",
                m.id,
                m.what,
                m.est_us,
                m.unit,
                m.budget_us.unwrap_or(0.0),
                m.worst_input
                    .as_ref()
                    .map_or(String::new(), |i| format!(" (worst input: {i})"))
            )
        })
        .collect();
    if !over.is_empty() {
        bail!("M4 budgets exceeded:\n  {}", over.join("\n  "));
    }
    Ok(())
}
