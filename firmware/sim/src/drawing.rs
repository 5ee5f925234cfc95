//! Draws a run as SVG: the board with its grid, the spot's path (solid
//! where the laser was on, faint where it was off), and each dwell point.

use anyhow::{Result, anyhow};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use crate::recorder::Recording;

/// Board area drawn, half-width and half-height, cm.
const HALF_WIDTH_CM: f64 = 16.0;
const HALF_HEIGHT_CM: f64 = 11.0;

/// Grid geometry to draw (indices −half_cols..=half_cols etc.).
#[derive(Debug, Clone, Copy)]
pub struct GridView {
    /// Pitch, cm.
    pub pitch_cm: f64,
    /// Half the number of columns.
    pub half_cols: i32,
    /// Half the number of rows.
    pub half_rows: i32,
}

/// The galvo spot to draw, cm.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GalvoTrace {
    /// Path of the spot while it moved (laser off: jumps).
    pub path: Vec<(f64, f64)>,
    /// Where the laser was on.
    pub lit: Vec<(f64, f64)>,
}

/// The chart the run is drawn on: board x and y, cm.
type BoardChart<'a, 'b> =
    ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Renders the gimbal's `recording` and the `galvo` trace into an SVG
/// document.
pub fn render_svg(
    recording: &Recording,
    galvo: &GalvoTrace,
    grid: GridView,
    title: &str,
) -> Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (960, 680)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(44)
            .build_cartesian_2d(
                -HALF_WIDTH_CM..HALF_WIDTH_CM,
                -HALF_HEIGHT_CM..HALF_HEIGHT_CM,
            )
            .map_err(|e| anyhow!("{e}"))?;
        chart
            .configure_mesh()
            .x_desc("board x (cm)")
            .y_desc("board y (cm)")
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        draw_grid(&mut chart, grid)?;
        draw_gimbal_spot(&mut chart, recording)?;
        draw_galvo_spot(&mut chart, galvo)?;
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.3))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    Ok(svg)
}

/// Every grid point, a faint dot.
fn draw_grid(chart: &mut BoardChart<'_, '_>, grid: GridView) -> Result<()> {
    let grid_points: Vec<(f64, f64)> = (-grid.half_rows..=grid.half_rows)
        .flat_map(|yi| {
            (-grid.half_cols..=grid.half_cols)
                .map(move |xi| (f64::from(xi) * grid.pitch_cm, f64::from(yi) * grid.pitch_cm))
        })
        .collect();
    chart
        .draw_series(
            grid_points
                .iter()
                .map(|&p| Circle::new(p, 3, ShapeStyle::from(&BLACK.mix(0.25)).filled())),
        )
        .map_err(|e| anyhow!("{e}"))?
        .label("grid point")
        .legend(|(x, y)| Circle::new((x + 10, y), 3, BLACK.mix(0.25).filled()));
    Ok(())
}

/// The spot's path split into runs of equal laser power (‰, 0 dark),
/// each run starting where the one before ended.
fn laser_runs(recording: &Recording) -> Vec<(u16, Vec<(f64, f64)>)> {
    let mut runs: Vec<(u16, Vec<(f64, f64)>)> = Vec::new();
    for s in &recording.spot {
        let power = if s.laser { s.power.max(1) } else { 0 };
        match runs.last_mut() {
            Some((p, pts)) if *p == power => pts.push((s.x_cm, s.y_cm)),
            _ => {
                let mut pts = Vec::new();
                if let Some(&p) = runs.last().and_then(|(_, prev)| prev.last()) {
                    pts.push(p);
                }
                pts.push((s.x_cm, s.y_cm));
                runs.push((power, pts));
            }
        }
    }
    runs
}

/// The gimbal spot's path (red where its laser was on, the more opaque
/// the higher its power) and its dwells.
fn draw_gimbal_spot(chart: &mut BoardChart<'_, '_>, recording: &Recording) -> Result<()> {
    let mut labelled_on = false;
    let mut labelled_off = false;
    for (power, pts) in laser_runs(recording) {
        let on = power > 0;
        let style = if on {
            let opacity = 0.2 + 0.8 * f64::from(power.min(1000)) / 1000.0;
            ShapeStyle::from(&RED.mix(opacity)).stroke_width(2)
        } else {
            ShapeStyle::from(&BLUE.mix(0.25)).stroke_width(1)
        };
        let series = chart
            .draw_series(LineSeries::new(pts, style))
            .map_err(|e| anyhow!("{e}"))?;
        if on && !labelled_on {
            labelled_on = true;
            series
                .label("gimbal spot, laser on (opacity: power)")
                .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], RED.stroke_width(2)));
        } else if !on && !labelled_off {
            labelled_off = true;
            series
                .label("gimbal spot, laser off")
                .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLUE.mix(0.25)));
        }
    }

    if !recording.dwells.is_empty() {
        chart
            .draw_series(recording.dwells.iter().map(|d| {
                Cross::new(
                    d.spot_cm,
                    6,
                    ShapeStyle::from(&GREEN.mix(0.9)).stroke_width(2),
                )
            }))
            .map_err(|e| anyhow!("{e}"))?
            .label("dwell (spot)")
            .legend(|(x, y)| Cross::new((x + 10, y), 5, GREEN.stroke_width(2)));
    }
    Ok(())
}

/// The galvo spot: its path (faint) and where its laser was on.
fn draw_galvo_spot(chart: &mut BoardChart<'_, '_>, galvo: &GalvoTrace) -> Result<()> {
    if galvo.path.len() > 1 {
        chart
            .draw_series(LineSeries::new(
                galvo.path.iter().copied(),
                ShapeStyle::from(&MAGENTA.mix(0.3)).stroke_width(1),
            ))
            .map_err(|e| anyhow!("{e}"))?
            .label("galvo spot, laser off")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], MAGENTA.mix(0.3)));
    }
    if !galvo.lit.is_empty() {
        chart
            .draw_series(
                galvo
                    .lit
                    .iter()
                    .map(|&p| Circle::new(p, 4, ShapeStyle::from(&MAGENTA).filled())),
            )
            .map_err(|e| anyhow!("{e}"))?
            .label("galvo spot, laser on")
            .legend(|(x, y)| Circle::new((x + 10, y), 4, MAGENTA.filled()));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::recorder::{DwellRecord, SpotSample};

    #[test]
    fn svg_has_path_grid_and_dwells() {
        let rec = Recording {
            spot: (0..50)
                .map(|i| SpotSample {
                    t_us: i * 1000,
                    x_cm: i as f64 * 0.2 - 5.0,
                    y_cm: 1.0,
                    laser: i > 10,
                    power: if i > 10 { 300 + 20 * i as u16 } else { 0 },
                })
                .collect(),
            dwells: vec![DwellRecord {
                t_us: 0,
                target_cm: (0.0, 0.0),
                grid: Some((0, 0)),
                spot_cm: (0.0, 0.0),
                laser: true,
            }],
            ..Default::default()
        };
        let grid = GridView {
            pitch_cm: 1.916,
            half_cols: 6,
            half_rows: 4,
        };
        let svg = render_svg(&rec, &GalvoTrace::default(), grid, "test").unwrap();
        assert!(svg.starts_with("<svg"));
        assert!(
            svg.matches("<circle").count() >= 13 * 9,
            "grid points drawn"
        );
        assert!(svg.contains("<polyline"), "path drawn");
        // Lit runs at different powers, drawn at different opacities.
        let opacities: std::collections::BTreeSet<&str> = svg
            .split("<polyline fill=\"none\" opacity=\"")
            .skip(1)
            .filter_map(|rest| rest.split('>').next())
            .filter(|attributes| attributes.contains("stroke=\"#FF0000\""))
            .filter_map(|attributes| attributes.split('"').next())
            .collect();
        assert!(opacities.len() >= 10, "{opacities:?}");
        assert!(svg.contains("board x (cm)"));
    }
}
