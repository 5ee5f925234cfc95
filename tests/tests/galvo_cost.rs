//! The simulator charges the galvo loop's M4 cost: the cost model's
//! constants against bench-m4's table, and the demo without underruns
//! (an overloaded loop underrunning: `galvo_loop.rs`).

use std::path::PathBuf;

use laser_app::galvo::M4_COST;
use laser_sim::script::DEMO_SCRIPT;
use system_tests::run_to_idle;

/// bench-m4's JSON table: the one `cargo xtask test` names in
/// `BENCH_M4_JSON` (it runs bench-m4 first, so the table is this build's
/// and must exist), else one a run left in this build's target directory.
fn bench_table() -> Option<String> {
    if let Some(path) = std::env::var_os("BENCH_M4_JSON") {
        let table = std::fs::read_to_string(&path);
        return Some(table.unwrap_or_else(|e| panic!("BENCH_M4_JSON {path:?}: {e}")));
    }
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target"));
    std::fs::read_to_string(target.join("bench-m4.json")).ok()
}

/// Instructions of row `id` in the table (the number after its
/// `"instructions":` key).
fn row(table: &str, id: &str) -> f64 {
    let at = table
        .find(&format!("\"id\": \"{id}\""))
        .unwrap_or_else(|| panic!("{id} not in bench-m4.json"));
    let rest = &table[at..];
    let key = "\"instructions\": ";
    let from = rest.find(key).expect("instructions") + key.len();
    let end = rest[from..].find([',', '\n']).expect("number end");
    rest[from..from + end].trim().parse().expect("a number")
}

/// Each constant of [`M4_COST`] covers its bench row (the model never
/// charges less than the target measured) and stays within 10 % (+ 100
/// instructions) of it (it charges what was measured, not a guess). The
/// constants' sources are in `laser_app::galvo::cost`; without a table
/// (no `cargo xtask bench-m4` run in this target directory yet) the test
/// says so and checks only the documented arithmetic.
#[test]
fn m4_cost_model_matches_the_bench_table() {
    let m = M4_COST;
    assert!(m.refill + 128 * m.held >= 128 * m.held);
    assert_eq!((m.cpi, m.clock_hz), (1.3, 168e6));
    let Some(table) = bench_table() else {
        eprintln!(
            "no bench-m4.json: run `cargo xtask bench-m4` to check the cost model against it"
        );
        return;
    };
    let fits = |name: &str, model: u64, measured: f64| {
        let model = model as f64;
        assert!(
            model >= measured.floor() && model <= measured * 1.1 + 100.0,
            "{name}: model {model}, bench {measured}"
        );
    };
    fits(
        "refill + 128 held",
        m.refill + 128 * m.held,
        row(&table, "loop.holding.refill"),
    );
    fits(
        "jump_copied",
        m.jump_copied,
        row(&table, "loop.jump.steady"),
    );
    fits(
        "jump_stepped",
        m.jump_stepped,
        row(&table, "integrator.xy.step") + row(&table, "galvo.sample_map.angles_to_codes"),
    );
    let marking = row(&table, "loop.arc_r40.steady")
        .max(row(&table, "loop.line.steady"))
        .max(row(&table, "loop.tuning.steady"))
        .max(row(&table, "loop.stroke.steady"));
    fits("marked", m.marked, marking);
    fits(
        "step_started",
        m.step_started,
        row(&table, "loop.jump.refill"),
    );
    fits(
        "point_prepared",
        m.point_prepared,
        row(&table, "loop.jump.prep"),
    );
    let stroke = row(&table, "loop.tuning.prep")
        .max(row(&table, "loop.arc_r40.prep"))
        .max(row(&table, "loop.line.prep"))
        .max(row(&table, "loop.stroke.prep"));
    fits("stroke_prepared", m.stroke_prepared, stroke);
    // A continuation joined to the stroke being marked is charged as a
    // stroke step: an upper bound.
    let join = row(&table, "loop.join.prep");
    assert!(
        join <= m.stroke_prepared as f64,
        "loop.join.prep {join} is charged as a stroke step, {}",
        m.stroke_prepared
    );
    fits("rebuild", m.rebuild, row(&table, "loop.reconfigure"));
    fits(
        "bisection_axis",
        m.bisection_axis,
        row(&table, "plan.seed.0.1deg"),
    );
    fits("model_sampled", m.model_sampled, row(&table, "loop.new"));
}

/// The demo (the galvo's tuning figure, then the gimbal) at the M4's
/// cost: no underrun.
#[test]
fn the_demo_keeps_up_at_the_m4_cost() {
    let report = run_to_idle(DEMO_SCRIPT);
    assert_eq!(report.galvo_underruns, 0);
    assert!(report.dac.iter().any(|(_, s)| s.laser), "the galvo marked");
}

/// `planner seed` in the simulator: allowed (for comparison), charged its
/// M4 cost (bisection, ≥ 1.57 M instructions per jump axis), so the
/// pattern underruns as it would on the M4 — where the board refuses the
/// planner instead.
#[test]
fn a_seed_planned_pattern_underruns_at_the_m4_cost() {
    let report = run_to_idle("planner seed\ntarget galvo\npattern tuning 0 0 8 once\nwait 1500\n");
    assert!(
        report.galvo_underruns > 0,
        "seed planning kept up on the M4's cost"
    );
    let optimal = run_to_idle("target galvo\npattern tuning 0 0 8 once\nwait 1500\n");
    assert_eq!(optimal.galvo_underruns, 0);
}
