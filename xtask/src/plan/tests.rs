use super::*;
use clap::Parser;
use galvo_planner::model::FlexParams;

#[derive(Parser, Debug)]
struct Cli {
    #[command(flatten)]
    plan: PlanArgs,
}

fn jump_args(cmd: &str) -> JumpArgs {
    let argv = std::iter::once("plan").chain(cmd.split_whitespace());
    match Cli::try_parse_from(argv)
        .expect("valid command line")
        .plan
        .command
    {
        PlanCommand::Jump(a) => a,
        PlanCommand::Compare(_) => panic!("not a jump"),
    }
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("xtask-plan-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir.join(name)
}

fn parse(s: &str) -> f64 {
    s.parse().expect("number")
}

/// The CSV is the exact ZOH simulation of its own voltage column: every
/// row follows from the previous one by one step of the sampled model,
/// bit for bit (the numbers are written in round-trip form).
#[test]
fn csv_rows_are_the_exact_zoh_simulation() {
    for (cmd, cols) in [
        ("jump --from-deg -2 --to-deg 3 --method seed", 6),
        ("jump --from-deg 0 --to-deg 5 --method optimal --ts-us 5", 6),
        (
            "jump --from-deg 0 --to-deg 5 --method optimal-f64 --ts-us 5",
            6,
        ),
        (
            "jump --from-deg 1 --to-deg -4 --method scurve --model flexible",
            8,
        ),
    ] {
        let path = tmp("jump.csv");
        let mut args = jump_args(cmd);
        args.csv = Some(path.clone());
        assert_eq!(run_jump(&args).expect("runs"), ExitCode::SUCCESS);
        let mut rd = csv::Reader::from_path(&path).expect("csv");
        let header: Vec<String> = rd
            .headers()
            .expect("header")
            .iter()
            .map(str::to_string)
            .collect();
        let mut want = vec!["k", "t_s", "theta_rad", "omega_rad_s", "current_a", "u_v"];
        if cols == 8 {
            want.extend(["phi_rad", "omega_load_rad_s"]);
        }
        assert_eq!(header, want);
        let rows: Vec<Vec<f64>> = rd
            .records()
            .map(|r| r.expect("row").iter().map(parse).collect())
            .collect();
        let built = args.model.build().expect("model");
        // State vector of a row in model order (θ, ω, I[, φ, ω_φ]).
        let state = |r: &Vec<f64>| -> Vec<f64> {
            let mut z = vec![r[2], r[3], r[4]];
            if cols == 8 {
                z.extend([r[6], r[7]]);
            }
            z
        };
        let ts = args.model.ts_s();
        for (k, r) in rows.iter().enumerate() {
            assert_eq!(r.len(), cols);
            assert_eq!(r[0], k as f64);
            assert_eq!(r[1], k as f64 * ts);
        }
        assert_eq!(
            rows.last().expect("rows")[5],
            0.0,
            "last row holds no voltage"
        );
        for w in rows.windows(2) {
            let (z, u) = (state(&w[0]), w[0][5]);
            let next: Vec<f64> = match &built {
                Built::Rigid(d) => d.step(&[z[0], z[1], z[2]], u).to_vec(),
                Built::Flexible(d) => d.step(&[z[0], z[1], z[2], z[3], z[4]], u).to_vec(),
            };
            assert_eq!(next, state(&w[1]));
        }
        // Starts at rest at --from-deg, lands at --to-deg.
        let first = state(&rows[0]);
        assert_eq!(first[0], args.from_deg.to_radians());
        assert!(first[1..3].iter().all(|v| *v == 0.0));
        let last = state(rows.last().expect("rows"));
        // The f32 time-optimal planner (the target's) lands within the
        // acceptance bound of 1e-6 rad; the f64 planners within 1e-9.
        let tol = if cmd.contains("--method optimal ") {
            1e-6
        } else {
            1e-9
        };
        assert!((last[0] - args.to_deg.to_radians()).abs() < tol, "{cmd}");
    }
}

#[test]
fn invalid_requests_are_errors() {
    let built = |cmd: &str| jump_args(cmd).model.build();
    assert!(built("jump --from-deg 0 --to-deg 1 --method seed --ts-us 0").is_err());
    assert!(built("jump --from-deg 0 --to-deg 1 --method seed --umax-v -1").is_err());
    assert!(built("jump --from-deg 0 --to-deg 1 --method seed --r-ohm nan").is_err());
    assert!(built("jump --from-deg 0 --to-deg 1 --method seed --jm-kg-m2 1e-8").is_err());
    assert!(
        built("jump --from-deg 0 --to-deg 1 --method seed --model flexible --j-kg-m2 1e-8")
            .is_err()
    );
    // Pathological sampling of the 10 kHz mode.
    let e = built(
        "jump --from-deg 0 --to-deg 1 --method seed --model flexible --ts-us 50 --resonance-hz 10000",
    );
    assert!(e.is_ok() || e.is_err(), "either way no panic");
    let rows = |cmd: &str| {
        let a = jump_args(cmd);
        match a.model.build().expect("model") {
            Built::Rigid(d) => jump_rows(&d, &a).map(|_| ()),
            Built::Flexible(d) => jump_rows(&d, &a).map(|_| ()),
        }
    };
    assert!(rows("jump --from-deg 0 --to-deg nan --method seed").is_err());
    assert!(rows("jump --from-deg 0 --to-deg 3 --method optimal --model flexible").is_err());
    assert!(rows("jump --from-deg 0 --to-deg 20 --method tcurve --capacity 10").is_err());
    assert!(rows("jump --from-deg 0 --to-deg -20 --method seed --p 3").is_ok());
}

#[test]
fn flags_override_the_reference_galvo() {
    let a = jump_args(
        "jump --from-deg 0 --to-deg 1 --method seed --kt-nm-per-a 0.02 --j-kg-m2 3e-8 --l-h 1e-4 --r-ohm 2 --umax-v 30",
    );
    let p = a.model.rigid_params();
    assert_eq!(
        (p.kt_nm_per_a, p.j_kg_m2, p.l_h, p.r_ohm, p.u_max_v),
        (0.02, 3e-8, 1e-4, 2.0, 30.0)
    );
    let a = jump_args(
        "jump --from-deg 0 --to-deg 1 --method seed --model flexible --resonance-hz 5000",
    );
    assert!((a.model.flex_params().resonance_hz() - 5000.0).abs() < 1e-6);
    let a = jump_args("jump --from-deg 0 --to-deg 1 --method seed --model flexible");
    assert_eq!(a.model.flex_params(), FlexParams::REFERENCE);
}
