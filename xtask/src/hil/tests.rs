use laser_sim::on_pty::SimOnPty;
use laser_sim::world::SimOptions;

use super::*;

fn scenario(name: &str) -> Scenario {
    scenario::all()
        .unwrap()
        .into_iter()
        .find(|s| s.name == name)
        .unwrap()
}

#[test]
fn scenarios_a_bare_console_cannot_run_say_why() {
    let silent = unrunnable(&scenario("silent_servo"), true).unwrap();
    assert!(silent.contains("fault injection"), "{silent}");
    let reset = unrunnable(&scenario("save_reset"), false).unwrap();
    assert!(reset.contains("--probe-reset"), "{reset}");
    assert_eq!(unrunnable(&scenario("save_reset"), true), None);
    assert_eq!(unrunnable(&scenario("grid"), false), None);
}

#[test]
fn the_report_counts_and_names_every_verdict() {
    let rows = vec![
        Row {
            name: "grid".into(),
            verdict: Verdict::Pass,
            seconds: 3.0,
        },
        Row {
            name: "x".into(),
            verdict: Verdict::Fail("laser lit".into()),
            seconds: 1.0,
        },
        Row {
            name: "y".into(),
            verdict: Verdict::Skipped("no galvo".into()),
            seconds: 0.0,
        },
    ];
    let text = table(&rows);
    assert!(
        text.contains("grid") && text.contains("FAIL") && text.contains("laser lit"),
        "{text}"
    );
    let j = json(Path::new("/dev/ttyACM0"), &rows);
    assert_eq!(
        (
            j["passed"].as_u64(),
            j["failed"].as_u64(),
            j["skipped"].as_u64()
        ),
        (Some(1), Some(1), Some(1))
    );
    assert_eq!(j["scenarios"][1]["reason"], "laser lit");
    assert!(
        require_pass(&rows, "b")
            .unwrap_err()
            .to_string()
            .contains("x: laser lit")
    );
}

/// The runner against the simulator's console on a PTY (real time): every
/// scenario a bare console can run passes the shared assertions, the rest
/// are skipped with their reason.
#[test]
fn the_runner_passes_on_the_simulators_pty() {
    let dir = std::env::temp_dir().join(format!("xtask-hil-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let sim = SimOnPty::start(
        dir.join("console"),
        SimOptions {
            max_time_ms: 600_000,
            ..SimOptions::default()
        },
    )
    .expect("the simulator starts");
    let rows = run_all(&sim.link, None);
    sim.finish();
    std::fs::remove_dir_all(&dir).ok();
    let rows = rows.unwrap();
    eprint!("{}", table(&rows));
    require_pass(&rows, "the simulator's PTY").unwrap();
    let verdict = |name: &str| {
        rows.iter()
            .find(|r| r.name == name)
            .unwrap()
            .verdict
            .clone()
    };
    for name in ["grid", "switch", "garbage_flood", "galvo_tuning"] {
        assert_eq!(verdict(name), Verdict::Pass, "{name}");
    }
    assert!(matches!(verdict("silent_servo"), Verdict::Skipped(_)));
    assert!(matches!(verdict("save_reset"), Verdict::Skipped(_)));
}
