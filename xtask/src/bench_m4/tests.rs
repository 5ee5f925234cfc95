use super::*;

const OUT: &str = "bench-m4 1\ncalibration 2000000 50000\nempty 0 64\n\
    check sqrt+dac ok 6960\n\
    bench loop.holding.steady 40 128\nbench loop.line.steady 100 128\n\
    bench loop.arc_r40.steady 100 128\nbench loop.jump.steady 10 40\n\
    bench loop.holding.refill 40 1\nbench loop.line.refill 100 1\n\
    bench loop.arc_r40.refill 100 1\nbench loop.jump.refill 1000 1\n\
    bench loop.jump.prep 1500 1\nbench loop.line.prep 2000 1\n\
    bench loop.arc_r40.prep 2000 1\n\
    bench loop.tuning.steady 100 128\nbench loop.tuning.refill 100 1\n\
    bench loop.tuning.prep 2000 1\nbench loop.reconfigure 150 1\n\
    bench loop.stroke.steady 100 128\nbench loop.stroke.refill 100 1\n\
    bench loop.stroke.prep 2000 1\nbench loop.join.prep 700 1\n\
    bench plan.xy.optimal.1lsb 250 1\nbench plan.xy.optimal.160mm 300 1\n\
    bench plan.seed.1deg 100 1\n\
    bench stepper.step_tick.event 100 50\nbench stepper.step_tick.event_one_pulse 100 50\n\
    bench stepper.step_tick.segment 20 8\n\
    bench sweep.plan.xy 300 1\n\
    median sweep.plan.xy 130 1\n\
    worst sweep.plan.xy 3000 (-80.109,136.229)->(-80.261,140.839) mm\n\
    bench sweep.stroke.steady 800 128\n\
    worst sweep.stroke.steady 200 input 58: (33.489,-55.039) (32.483,-52.896)\n\
    bench sweep.stroke.refill 800 1\n\
    worst sweep.stroke.refill 200 input 58: (33.489,-55.039) (32.483,-52.896)\n\
    bench sweep.stroke.prep 2000 1\n\
    worst sweep.stroke.prep 200 input 6: (-44.691,-53.845) (-45.054,-54.270)\n\
    bench pelco.frame.move 1656 1\nbench pelco.frame.set_pan 479 1\n\
    bench pelco.frame.query_pan 237 1\nbench pelco.frame.goto_preset 236 1\n\
    bench sweep.pelco.frame 1930 1\n\
    worst sweep.pelco.frame 2000 A00000120106AF1A (P move) at (21.64,29.03) cm\n\
    bench gcode.line.gimbal 5693 1\nmedian gcode.line.gimbal 5027 1\n\
    bench gcode.line.gimbal.core 2832 1\n\
    worst gcode.line.gimbal 300 G2 X31.251 Y2.232 I14.892 J15.371 F2303\n\
    bench gcode.line.galvo 1526 1\nbench gcode.line.stepper 38525 1\n\
    done 0\n";

#[test]
fn turns_ticks_into_instructions_and_checks_budgets() {
    let r = parse(OUT).unwrap();
    assert_eq!(r.instructions_per_tick, 40.0);
    let holding = r
        .rows
        .iter()
        .find(|m| m.id == "loop.holding.steady")
        .unwrap();
    // 40 ticks · 40 / 128 = 12.5 instructions per sample.
    assert_eq!(holding.instructions, 12.5);
    assert!((holding.est_us - 12.5 * 1.3 / 168.0).abs() < 1e-12);
    assert!(!holding.over_budget);
    // Planning is within its enforced budget: 300 ticks = 12 000
    // instructions = 92.9 µs of 100 µs.
    let plan = r
        .rows
        .iter()
        .find(|m| m.id == "plan.xy.optimal.160mm")
        .unwrap();
    assert!(plan.share.unwrap() < 1.0 && !plan.over_budget);
    assert_eq!(plan.status.as_deref(), Some("enforced"));
    let seed = r.rows.iter().find(|m| m.id == "plan.seed.1deg").unwrap();
    assert_eq!(seed.what, "one-axis seed plan, 1deg");
    assert!(check(&r).is_ok());
}

#[test]
fn an_enforced_budget_over_fails() {
    // 3000 ticks for a holding half: 120 000 instructions, 929 µs of
    // the 640 µs allowed.
    let out = OUT.replace(
        "bench loop.holding.refill 40 1",
        "bench loop.holding.refill 3000 1",
    );
    let r = parse(&out).unwrap();
    let err = check(&r).unwrap_err().to_string();
    assert!(err.contains("loop.holding.refill"), "{err}");
    // A two-axis jump plan over 100 µs (14 000 instructions) fails.
    let out = OUT.replace(
        "bench plan.xy.optimal.160mm 300 1",
        "bench plan.xy.optimal.160mm 350 1",
    );
    let err = check(&parse(&out).unwrap()).unwrap_err().to_string();
    assert!(err.contains("plan.xy.optimal.160mm"), "{err}");
    // Holding per sample is enforced too: 1000 ticks for 128 samples,
    // 312.5 instructions (2.4 µs) each, over its 0.5 µs.
    let holding = OUT.replace(
        "bench loop.holding.steady 40 128",
        "bench loop.holding.steady 1000 128",
    );
    let err = check(&parse(&holding).unwrap()).unwrap_err().to_string();
    assert!(err.contains("loop.holding.steady"), "{err}");
    // So are the refill that starts a jump and the prep of a step: 20 000
    // ticks, 800 000 instructions (6.2 ms), over their 640 µs.
    for id in ["loop.jump.refill", "loop.jump.prep"] {
        let before = format!("bench {id} ");
        let out: String = OUT
            .lines()
            .map(|l| {
                if l.trim_start().starts_with(&before) {
                    format!("{before}20000 1\n")
                } else {
                    format!("{l}\n")
                }
            })
            .collect();
        let err = check(&parse(&out).unwrap()).unwrap_err().to_string();
        assert!(err.contains(id), "{err}");
    }
    // So are the per-sample jump and marking budgets: 1000 ticks for 40
    // jump samples, 1000 instructions (7.7 µs) each, over its 1 µs.
    let jumping = OUT.replace(
        "bench loop.jump.steady 10 40",
        "bench loop.jump.steady 1000 40",
    );
    let r = parse(&jumping).unwrap();
    let m = r.rows.iter().find(|m| m.id == "loop.jump.steady").unwrap();
    assert!(m.share.unwrap() > 1.0 && m.over_budget);
    assert_eq!(m.status.as_deref(), Some("enforced"));
    let err = check(&r).unwrap_err().to_string();
    assert!(err.contains("loop.jump.steady"), "{err}");
    // A PELCO frame over a quarter of a 19 200-baud frame time (911 µs):
    // 5000 ticks, 200 000 instructions (1.5 ms), fails, with its input.
    let pelco = OUT.replace(
        "bench sweep.pelco.frame 1930 1",
        "bench sweep.pelco.frame 5000 1",
    );
    let err = check(&parse(&pelco).unwrap()).unwrap_err().to_string();
    assert!(err.contains("sweep.pelco.frame"), "{err}");
    assert!(err.contains("A00000120106AF1A"), "{err}");
}

#[test]
fn a_goal_not_met_is_shown_against_its_budget_and_enforced_at_its_ceiling() {
    let r = parse(OUT).unwrap();
    let m = r.rows.iter().find(|m| m.id == "gcode.line.gimbal").unwrap();
    // 5 693 ticks: 227 720 instructions against the goal 16 000, within
    // the restated 250 000.
    assert_eq!(m.instructions, 5_693.0 * 40.0);
    assert!(m.share.unwrap() > 10.0 && !m.over_budget);
    assert!(m.status.as_deref().unwrap().starts_with("not met: "));
    assert_eq!(
        m.worst_input.as_deref(),
        Some("G2 X31.251 Y2.232 I14.892 J15.371 F2303")
    );
    check(&r).unwrap();
    // Above the ceiling (6 400 ticks: 256 000 instructions) the run fails.
    let over = OUT.replace(
        "bench gcode.line.gimbal 5693 1",
        "bench gcode.line.gimbal 6400 1",
    );
    let err = check(&parse(&over).unwrap()).unwrap_err().to_string();
    assert!(err.contains("gcode.line.gimbal"), "{err}");
    // Without its line the run is incomplete.
    let missing = OUT.replace("bench gcode.line.galvo 1526 1\n", "");
    let err = parse(&missing).unwrap_err().to_string();
    assert!(err.contains("gcode.line.galvo"), "{err}");
}

fn manifest(path: &str) -> toml::Table {
    let path = workspace_root().join(path);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.parse()
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `[profile.release]` with its per-package overrides.
fn release_profile(manifest: &toml::Table) -> Option<&toml::Value> {
    manifest.get("profile")?.get("release")
}

/// The bench measures the crates as the firmware builds them, and the QEMU
/// board (`firmware/qemu-m4`) runs them so: each workspace's release
/// profile (profiles come from the workspace root only) must equal the
/// root's, overrides included.
#[test]
fn bench_release_profile_is_the_firmware_one() {
    let root = manifest("Cargo.toml");
    let root_release = release_profile(&root).expect("root [profile.release]");
    // Not vacuous: the root builds for size, the math crates for speed.
    assert_eq!(
        root_release.get("opt-level").and_then(toml::Value::as_str),
        Some("z")
    );
    assert!(
        root_release
            .get("package")
            .and_then(|p| p.get("galvo-planner"))
            .is_some()
    );
    for path in [MANIFEST, crate::qemu::MANIFEST] {
        let bench = manifest(path);
        assert_eq!(
            release_profile(&bench),
            Some(root_release),
            "{path}'s [profile.release*] differs from the root Cargo.toml's: \
             copy the root's release profile there"
        );
        // A workspace of its own, excluded by the root: otherwise the
        // linker runs in the root and links the STM32F407 memory map.
        assert!(bench.get("workspace").is_some_and(toml::Value::is_table));
        let dir = path.trim_end_matches("/Cargo.toml");
        let excluded = root
            .get("workspace")
            .and_then(|w| w.get("exclude"))
            .and_then(toml::Value::as_array)
            .is_some_and(|e| e.iter().any(|p| p.as_str() == Some(dir)));
        assert!(excluded, "the root workspace must exclude {dir}");
    }
}

/// The bench's own lock file pins the versions the firmware is built
/// with: every package in it has the same version in the root lock.
#[test]
fn bench_lock_pins_the_root_versions() {
    let versions = |lock: &toml::Table| -> Vec<(String, String)> {
        lock.get("package")
            .and_then(toml::Value::as_array)
            .expect("[[package]] entries")
            .iter()
            .filter_map(|p| {
                Some((
                    p.get("name")?.as_str()?.to_owned(),
                    p.get("version")?.as_str()?.to_owned(),
                ))
            })
            .collect()
    };
    let root = versions(&manifest("Cargo.lock"));
    for (lock, own) in [
        ("firmware/bench-m4/Cargo.lock", "bench-m4"),
        ("firmware/qemu-m4/Cargo.lock", "qemu-m4"),
    ] {
        let bench = versions(&manifest(lock));
        assert!(bench.iter().any(|(name, _)| name == "cortex-m-rt"));
        let drifted: Vec<String> = bench
            .iter()
            .filter(|(name, version)| {
                name != own && !root.iter().any(|(n, v)| n == name && v == version)
            })
            .map(|(name, version)| format!("{name} {version}"))
            .collect();
        assert!(
            drifted.is_empty(),
            "{lock} has versions the root Cargo.lock does not: {drifted:?} \
             (copy the root Cargo.lock there and build once)"
        );
    }
}

#[test]
fn a_sweep_reports_its_worst_input_and_is_enforced_on_it() {
    let r = parse(OUT).unwrap();
    let plan = r.rows.iter().find(|m| m.id == "sweep.plan.xy").unwrap();
    assert_eq!(plan.inputs_tried, Some(3000));
    // The median input: 130 ticks, 5 200 instructions.
    assert_eq!(plan.median_instructions, Some(5200.0));
    let steady = r
        .rows
        .iter()
        .find(|m| m.id == "sweep.stroke.steady")
        .unwrap();
    assert_eq!(steady.median_instructions, None);
    assert_eq!(
        plan.worst_input.as_deref(),
        Some("(-80.109,136.229)->(-80.261,140.839) mm")
    );
    assert!(!plan.over_budget);
    // 413 ticks: 16 520 instructions, 128 µs of the 100 µs: a failure
    // that names the input.
    let over = OUT.replace("bench sweep.plan.xy 300 1", "bench sweep.plan.xy 413 1");
    let r = parse(&over).unwrap();
    let plan = r.rows.iter().find(|m| m.id == "sweep.plan.xy").unwrap();
    assert!(plan.share.unwrap() > 1.0 && plan.over_budget);
    assert_eq!(plan.status.as_deref(), Some("enforced"));
    let err = check(&r).unwrap_err().to_string();
    assert!(
        err.contains("sweep.plan.xy") && err.contains("(-80.109,136.229)"),
        "{err}"
    );
    // 1100 ticks per half: 343.75 instructions per sample, over the
    // 20 % (258); enforced, with the input named.
    let over = OUT.replace(
        "bench sweep.stroke.steady 800 128",
        "bench sweep.stroke.steady 1100 128",
    );
    let err = check(&parse(&over).unwrap()).unwrap_err().to_string();
    assert!(
        err.contains("sweep.stroke.steady") && err.contains("input 58"),
        "{err}"
    );
    // So is the refill of the sweep's worst half (20 000 ticks, 1.2 ms).
    let over = OUT.replace(
        "bench sweep.stroke.refill 800 1",
        "bench sweep.stroke.refill 20000 1",
    );
    let err = check(&parse(&over).unwrap()).unwrap_err().to_string();
    assert!(
        err.contains("sweep.stroke.refill") && err.contains("input 58"),
        "{err}"
    );
    // A sweep without its worst input is not a report.
    let bare = OUT.replace(
        "worst sweep.plan.xy 3000 (-80.109,136.229)->(-80.261,140.839) mm\n",
        "",
    );
    assert!(
        parse(&bare)
            .unwrap_err()
            .to_string()
            .contains("worst input")
    );
}

#[test]
fn refuses_bad_runs() {
    // Without -icount the timer does not tick 40 instructions.
    let wrong = OUT.replace("calibration 2000000 50000", "calibration 2000000 20000");
    assert!(parse(&wrong).unwrap_err().to_string().contains("icount"));
    assert!(parse(&OUT.replace("done 0\n", "")).is_err());
    let missing = OUT.replace("bench loop.jump.steady 10 40\n", "");
    assert!(
        parse(&missing)
            .unwrap_err()
            .to_string()
            .contains("loop.jump.steady")
    );
    let error = format!("{OUT}error loop.jump \"setup\"\n");
    assert!(parse(&error).is_err());
    let unchecked = OUT.replace("check sqrt+dac ok 6960\n", "");
    assert!(
        parse(&unchecked)
            .unwrap_err()
            .to_string()
            .contains("self-check")
    );
}
