use super::*;
use crate::json_out::error_json;
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
    let v = json(&ik("ik --model exact --x-cm -11.496 --y-cm 7.664 --oq-cm 30 --ol-cm 4").unwrap());
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
        (seed["pitch_deg"].as_f64().unwrap() - exact["pitch_deg"].as_f64().unwrap()).abs() > 0.1
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
