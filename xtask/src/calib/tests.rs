use super::output::{FIRMWARE_MAX_LINE, comment_line, exact_number};
use super::*;
use kinematics_core::MeasuredPoint;
use std::path::Path;

/// Known quadratic behind `kinematics-core/tests/data/quadratic_noise.csv`
/// (11 × 11 grid over ±100 mm, Gaussian noise σ = 0.02 mm; see
/// kinematics-core/README.md).
const TRUE_DX: [f64; 6] = [0.5, 0.004, -0.002, 2e-5, -1e-5, 3e-5];
const TRUE_DY: [f64; 6] = [-0.3, 0.001, 0.006, -1e-5, 2e-5, -2e-5];
const SIGMA_MM: f64 = 0.02;

fn data_file() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../kinematics-core/tests/data/quadratic_noise.csv")
}

fn tmp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("xtask-calib-{}-{name}", std::process::id()))
}

#[test]
fn recovers_the_known_quadratic_from_the_noisy_grid() {
    let points = read_points(File::open(data_file()).unwrap()).unwrap();
    assert_eq!(points.len(), 121);
    let report = fit(&points).unwrap();
    // Standard errors for σ = 0.02 on an 11 × 11 grid over ±100 mm are
    // about 0.004 (c0), 2.6e-5 (linear), 4e-7 (quadratic); allow 5σ.
    let tol = [0.02, 1.3e-4, 1.3e-4, 2e-6, 2e-6, 2e-6];
    for (fit, truth) in [(&report.dx, TRUE_DX), (&report.dy, TRUE_DY)] {
        for ((c, t), tol) in fit.coef.iter().zip(truth).zip(tol) {
            assert!((c - t).abs() < tol, "{c} vs {t}");
        }
        // RMSE estimates σ (115 residual degrees of freedom: ±20 %).
        let rmse = fit.rmse.unwrap();
        assert!((rmse - SIGMA_MM).abs() < 0.2 * SIGMA_MM, "rmse {rmse}");
        assert!(fit.r2 > 0.99 && fit.r2 <= 1.0);
        assert_eq!(fit.n, 121);
    }
}

#[test]
fn command_prints_json_and_writes_firmware_commands() {
    let out = tmp("model.txt");
    let args = FitArgs {
        input: data_file(),
        output: Some(out.clone()),
    };
    let json: serde_json::Value = serde_json::from_str(&fit_command(&args).unwrap()).unwrap();
    let dx = &json["dx"];
    assert_eq!(dx["coef"].as_array().unwrap().len(), 6);
    assert_eq!(dx["n"].as_u64(), Some(121));
    for key in ["sse", "r2", "rmse"] {
        assert!(dx[key].is_f64() && json["dy"][key].is_f64(), "{key}");
    }
    let text = std::fs::read_to_string(&out).unwrap();
    std::fs::remove_file(&out).ok();
    let mut sets = Vec::new();
    for line in text.lines() {
        assert!(line.len() <= FIRMWARE_MAX_LINE, "{line}");
        assert!(
            line.bytes().all(|b| b == b' ' || b.is_ascii_graphic()),
            "{line}"
        );
        if let Some(rest) = line.strip_prefix("set ") {
            let (name, value) = rest.split_once(' ').unwrap();
            sets.push((name.to_owned(), value.parse::<f64>().unwrap()));
        } else {
            assert!(line.starts_with('#'), "{line}");
        }
    }
    // Exactly the 12 parameters, in order, each the printed coefficient bit for bit.
    let names: Vec<String> = ["dx", "dy"]
        .iter()
        .flat_map(|a| (0..6).map(move |i| format!("err.{a}.c{i}")))
        .collect();
    assert_eq!(sets.iter().map(|s| s.0.clone()).collect::<Vec<_>>(), names);
    for (k, (_, v)) in sets.iter().enumerate() {
        let axis = if k < 6 { "dx" } else { "dy" };
        assert_eq!(*v, json[axis]["coef"][k % 6].as_f64().unwrap());
    }
}

#[test]
fn reported_sse_is_that_of_the_written_model() {
    let out = tmp("model-sse.txt");
    let args = FitArgs {
        input: data_file(),
        output: Some(out.clone()),
    };
    let json: serde_json::Value = serde_json::from_str(&fit_command(&args).unwrap()).unwrap();
    let text = std::fs::read_to_string(&out).unwrap();
    std::fs::remove_file(&out).ok();
    // The coefficients as the firmware will hold them: parsed back from
    // the `set` lines.
    let values: Vec<f64> = text
        .lines()
        .filter_map(|l| l.strip_prefix("set "))
        .map(|rest| rest.split_once(' ').unwrap().1.parse().unwrap())
        .collect();
    let points = read_points(File::open(data_file()).unwrap()).unwrap();
    for (axis, name) in [(0, "dx"), (1, "dy")] {
        let coef: [f64; 6] = values[axis * 6..axis * 6 + 6].try_into().unwrap();
        let q = kinematics_core::Quadratic::new(coef);
        let sse: f64 = points
            .iter()
            .map(|p| {
                let d = if axis == 0 { p.dx_mm } else { p.dy_mm };
                let r = d - q.eval(p.x_mm, p.y_mm).unwrap();
                r * r
            })
            .sum();
        assert_eq!(json[name]["sse"].as_f64(), Some(sse), "{name}");
    }
}

#[test]
fn huge_or_non_finite_measurements_are_refused_naming_the_line() {
    let rows: String = (0..8).map(|i| format!("{i},{},0.1,0\n", i * i)).collect();
    for (bad, col) in [
        ("1e308,5,0.1,0", "x"),
        ("-1e308,5,0.1,0", "x"),
        ("5,10000.5,0.1,0", "y"),
        ("5,5,-20000,0", "dx"),
        ("5,5,0.1,1e300", "dy"),
        ("5,5,NaN,0", "dx"),
    ] {
        let csv = format!("x,y,dx,dy\n{rows}{bad}\n");
        let e = read_points(csv.as_bytes()).unwrap_err();
        assert!(e.starts_with(&format!("line 10: column {col}:")), "{e}");
    }
    // The reproducer: points at ±1e308 mm no longer fit to R² = 1.
    let path = tmp("huge.csv");
    let mut csv = String::from("x,y,dx,dy\n");
    for (x, y) in [(1e308, 0.0), (-1e308, 0.0), (0.0, 1e308), (0.0, -1e308)] {
        csv.push_str(&format!("{x:e},{y:e},1,1\n"));
    }
    csv.push_str(&rows);
    std::fs::write(&path, csv).unwrap();
    let e = fit_command(&FitArgs {
        input: path.clone(),
        output: None,
    })
    .unwrap_err();
    std::fs::remove_file(path).ok();
    assert!(e.contains("line 2: column x:"), "{e}");
}

#[test]
fn numbers_round_trip_and_stay_short() {
    for v in [
        0.0,
        -0.5,
        1.2345678901234567e-7,
        3e-300,
        -1e300,
        2.5e-5,
        1.0 / 3.0,
    ] {
        let s = exact_number(v);
        assert_eq!(s.parse::<f64>().unwrap(), v, "{s}");
        assert!(s.len() <= 24, "{s}");
    }
    assert_eq!(exact_number(0.004), "0.004");
}

#[test]
fn long_or_non_ascii_comments_are_made_safe() {
    let c = comment_line(&format!("from /tmp/Δ/{}", "x".repeat(300)));
    assert!(c.len() == FIRMWARE_MAX_LINE && c.starts_with("# from /tmp/?/"));
}

#[test]
fn parses_padding_comments_blank_lines_and_six_points() {
    let csv = "# measured 2024-05-31\n x , y ,dx, dy\n\n0,0,1,0\n10,0,1.1,0\n0,10,0.9,0\n\
               20,0,1.3,0\n10,10,1,0\n0,20,0.7,0.5\n";
    let pts = read_points(csv.as_bytes()).unwrap();
    assert_eq!(pts.len(), 6);
    assert_eq!(
        pts[5],
        MeasuredPoint {
            x_mm: 0.0,
            y_mm: 20.0,
            dx_mm: 0.7,
            dy_mm: 0.5
        }
    );
    let report = fit(&pts).unwrap();
    assert_eq!(report.dx.rmse, None);
    assert!(fit_json(&report).unwrap().contains(r#""rmse":null"#));
}

#[test]
fn malformed_csv_names_the_line() {
    let err = |csv: &str| read_points(csv.as_bytes()).unwrap_err();
    assert_eq!(
        err("x,y,dz,dy\n1,2,3,4\n"),
        "line 1: header must be exactly `x,y,dx,dy`, found `x,y,dz,dy`"
    );
    assert_eq!(
        err(""),
        "line 1: empty file, expected the header `x,y,dx,dy`"
    );
    assert_eq!(
        err("x,y,dx,dy\n1,2,3,4\n1,2,3\n"),
        "line 3: expected 4 fields (x,y,dx,dy), found 3"
    );
    assert_eq!(
        err("x,y,dx,dy\n1,2,3,4\n\n5,6,abc,8\n"),
        "line 4: column dx: `abc` is not a number"
    );
    assert_eq!(
        err("x,y,dx,dy\n1,2,3,4\n5,inf,7,8\n"),
        "line 3: column y: `inf` is not a finite number"
    );
    assert_eq!(
        err("x,y,dx,dy\n1,2,3,4,5\n"),
        "line 2: expected 4 fields (x,y,dx,dy), found 5"
    );
    assert_eq!(
        err("# run 3\nx,y,dx,dy\n# note\n1,2,3,4\n# c\n\n5,6,7\n"),
        "line 7: expected 4 fields (x,y,dx,dy), found 3"
    );
    let bad_utf8: &[u8] = b"x,y,dx,dy\n1,2,\xff,4\n";
    let e = read_points(bad_utf8).unwrap_err();
    assert!(e.starts_with("line 2:"), "{e}");
}

#[test]
fn fit_and_file_errors_are_reported() {
    let missing = FitArgs {
        input: tmp("does-not-exist.csv"),
        output: None,
    };
    assert!(
        fit_command(&missing)
            .unwrap_err()
            .starts_with("cannot read")
    );
    let few = tmp("few.csv");
    std::fs::write(&few, "x,y,dx,dy\n0,0,0,0\n1,0,0,0\n").unwrap();
    let e = fit_command(&FitArgs {
        input: few.clone(),
        output: None,
    })
    .unwrap_err();
    assert_eq!(e, "fit failed: need at least 6 measured points, got 2");
    let line = tmp("line.csv");
    let rows: String = (0..8).map(|i| format!("{i},{},0.1,0\n", 2 * i)).collect();
    std::fs::write(&line, format!("x,y,dx,dy\n{rows}")).unwrap();
    let e = fit_command(&FitArgs {
        input: line.clone(),
        output: None,
    })
    .unwrap_err();
    assert!(e.contains("degenerate"), "{e}");
    let e = fit_command(&FitArgs {
        input: data_file(),
        output: Some(tmp("no-such-dir").join("model.txt")),
    })
    .unwrap_err();
    assert!(e.starts_with("cannot write"), "{e}");
    std::fs::remove_file(few).ok();
    std::fs::remove_file(line).ok();
}

#[test]
fn coefficients_outside_the_firmware_range_are_refused() {
    // Δx = 5000 mm everywhere (e.g. metres mistaken for mm).
    let pts: Vec<MeasuredPoint> = [
        (0.0, 0.0),
        (1.0, 0.0),
        (0.0, 1.0),
        (2.0, 0.0),
        (1.0, 1.0),
        (0.0, 2.0),
    ]
    .iter()
    .map(|&(x_mm, y_mm)| MeasuredPoint {
        x_mm,
        y_mm,
        dx_mm: 5000.0,
        dy_mm: 0.0,
    })
    .collect();
    let report = fit(&pts).unwrap();
    let e = firmware_commands(&report, Path::new("m.csv")).unwrap_err();
    assert!(e.starts_with("err.dx.c0 = "), "{e}");
}

fn offline_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("camera/tests/data/offline")
}

fn camera_args(images: &Path, points: &Path, out: &str) -> camera::CameraRunArgs {
    camera::CameraRunArgs::for_test(
        images,
        points,
        &tmp(&format!("{out}-err.txt")),
        &tmp(&format!("{out}-report.json")),
        &tmp(&format!("{out}-errors.svg")),
    )
}

/// The committed frames (`cargo xtask calib frames --every 11 --scale 0.5`:
/// the simulator's build error seen by the virtual camera at 640 × 360).
#[test]
fn offline_camera_mode_fits_the_committed_frames() {
    let dir = offline_dir();
    let a = camera_args(&dir, &dir.join("points.csv"), "ok");
    let json: serde_json::Value = serde_json::from_str(&run_command(&a).unwrap()).unwrap();
    assert_eq!(json["frames"], 11);
    assert_eq!(json["markers"].as_array().unwrap().len(), 14);
    assert!(json["reprojection_px"].as_f64().unwrap() < 0.3);
    let before = json["before"]["worst_mm"].as_f64().unwrap();
    let after = json["after_predicted"]["worst_mm"].as_f64().unwrap();
    assert!(before > 3.0 && after < 0.5, "{before} -> {after}");
    let lines = std::fs::read_to_string(tmp("ok-err.txt")).unwrap();
    assert_eq!(
        lines.lines().filter(|l| l.starts_with("set err.")).count(),
        12
    );
    assert!(
        std::fs::read_to_string(tmp("ok-errors.svg"))
            .unwrap()
            .contains("<line")
    );
    for f in ["ok-err.txt", "ok-report.json", "ok-errors.svg"] {
        let _ = std::fs::remove_file(tmp(f));
    }
}

#[test]
fn offline_camera_mode_refuses_bad_input_and_writes_nothing() {
    let dir = offline_dir();
    let csv = tmp("bad-points.csv");
    for (text, expect) in [
        (
            "image,x,y\nframe_000.png,-114.96,76.64\nmissing.png,0,0\n",
            "line 3: image ",
        ),
        ("image,x,y\nbackground.png,0,0\n", "no laser spot found"),
        ("image,x\n", "line 1: header must be exactly `image,x,y`"),
    ] {
        std::fs::write(&csv, text).unwrap();
        let a = camera_args(&dir, &csv, "bad");
        let err = run_command(&a).unwrap_err();
        assert!(err.contains(expect), "{err}");
        for f in ["bad-err.txt", "bad-report.json", "bad-errors.svg"] {
            assert!(!tmp(f).exists(), "{f} written on refusal");
        }
    }
    let _ = std::fs::remove_file(csv);
}

#[test]
fn the_readme_example_measurements_fit() {
    let out = tmp("readme-model.txt");
    let args = FitArgs {
        input: Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/examples/measured-grid.csv"),
        output: Some(out.clone()),
    };
    let json: serde_json::Value = serde_json::from_str(&fit_command(&args).unwrap()).unwrap();
    let written = std::fs::read_to_string(&out).unwrap();
    std::fs::remove_file(&out).ok();
    assert_eq!(json["dx"]["n"].as_u64(), Some(121));
    assert_eq!(
        written
            .lines()
            .filter(|l| l.starts_with("set err."))
            .count(),
        12
    );
}

#[test]
fn the_target_is_written_as_svg_or_pdf_by_its_extension() {
    for (name, magic) in [("board.svg", "<svg"), ("board.pdf", "%PDF-")] {
        let out = tmp(name);
        let a = camera::TargetArgs {
            out: out.clone(),
            pitch_mm: 19.16,
            xi_max: 6,
            yi_max: 4,
        };
        let json: serde_json::Value =
            serde_json::from_str(&camera::target_command(&a).unwrap()).unwrap();
        assert_eq!(json["tags"], 14);
        let bytes = std::fs::read(&out).unwrap();
        std::fs::remove_file(&out).ok();
        assert!(bytes.starts_with(magic.as_bytes()), "{name}");
    }
}
