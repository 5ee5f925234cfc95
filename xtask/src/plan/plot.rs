//! SVG plot of a jump: position, velocity, current and voltage against time.

use std::path::Path;

use anyhow::anyhow;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::row::Row;

type Series = Vec<(f64, f64)>;

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
        (l.min(v), h.max(v))
    });
    if !lo.is_finite() || !hi.is_finite() {
        return (-1.0, 1.0);
    }
    let pad = ((hi - lo) * 0.05).max(1e-12 * hi.abs().max(1.0));
    (lo - pad, hi + pad)
}

/// The right-hand corner (upper or lower) with fewer data points near it,
/// so the legend hides as little as possible.
fn legend_corner(
    series: &[(String, Series, RGBColor)],
    t_end: f64,
    ylo: f64,
    yhi: f64,
) -> SeriesLabelPosition {
    let right = |p: &&(f64, f64)| p.0 > 0.65 * t_end;
    let band = 0.3 * (yhi - ylo);
    let (mut upper, mut lower) = (0usize, 0usize);
    for (_, s, _) in series {
        upper += s.iter().filter(right).filter(|p| p.1 > yhi - band).count();
        lower += s.iter().filter(right).filter(|p| p.1 < ylo + band).count();
    }
    if upper <= lower {
        SeriesLabelPosition::UpperRight
    } else {
        SeriesLabelPosition::LowerRight
    }
}

/// One panel: several labelled series sharing the y axis.
struct Panel<'a> {
    title: &'a str,
    unit: &'a str,
    series: Vec<(String, Series, RGBColor)>,
}

/// Draws the jump's position, velocity, current and voltage panels into
/// an SVG file at `path`.
pub(crate) fn jump_svg(path: &Path, title: &str, rows: &[Row], u_max: f64) -> anyhow::Result<()> {
    let t_us = |r: &Row| r.t_s * 1e6;
    let t_end = rows.last().map_or(1.0, t_us).max(1e-9);
    let panels = panels(rows, u_max, t_end);
    let root = SVGBackend::new(path, (960, 1200)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
    let root = root
        .titled(title, ("sans-serif", 22))
        .map_err(|e| anyhow!("{e}"))?;
    for (area, panel) in root.split_evenly((4, 1)).iter().zip(panels.iter()) {
        draw_panel(area, panel, t_end)?;
    }
    root.present().map_err(|e| anyhow!("{e}"))?;
    Ok(())
}

/// The four panels of the plot, time in µs up to `t_end`.
fn panels(rows: &[Row], u_max: f64, t_end: f64) -> [Panel<'static>; 4] {
    let t_us = |r: &Row| r.t_s * 1e6;
    let mut position = vec![(
        "θ motor".to_string(),
        rows.iter()
            .map(|r| (t_us(r), r.theta_rad.to_degrees()))
            .collect::<Series>(),
        BLUE,
    )];
    let mut velocity = vec![(
        "ω motor".to_string(),
        rows.iter()
            .map(|r| (t_us(r), r.omega_rad_s))
            .collect::<Series>(),
        BLUE,
    )];
    if rows.first().is_some_and(|r| r.load.is_some()) {
        position.push((
            "φ mirror".into(),
            rows.iter()
                .filter_map(|r| r.load.map(|(phi, _)| (t_us(r), phi.to_degrees())))
                .collect(),
            RED,
        ));
        velocity.push((
            "ω mirror".into(),
            rows.iter()
                .filter_map(|r| r.load.map(|(_, w)| (t_us(r), w)))
                .collect(),
            RED,
        ));
    }
    // The voltage is held over each sample: draw it as steps.
    let mut voltage: Series = Vec::with_capacity(2 * rows.len());
    for w in rows.windows(2) {
        voltage.push((t_us(&w[0]), w[0].u_v));
        voltage.push((t_us(&w[1]), w[0].u_v));
    }
    [
        Panel {
            title: "position",
            unit: "deg",
            series: position,
        },
        Panel {
            title: "velocity",
            unit: "rad/s",
            series: velocity,
        },
        Panel {
            title: "current",
            unit: "A",
            series: vec![(
                "I".into(),
                rows.iter().map(|r| (t_us(r), r.current_a)).collect(),
                BLUE,
            )],
        },
        Panel {
            title: "voltage",
            unit: "V",
            series: vec![
                ("±Umax".into(), vec![(0.0, u_max), (t_end, u_max)], RED),
                (String::new(), vec![(0.0, -u_max), (t_end, -u_max)], RED),
                ("U (zero-order hold)".into(), voltage, BLUE),
            ],
        },
    ]
}

/// One panel's chart: its series, axes and legend.
fn draw_panel(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    panel: &Panel<'_>,
    t_end: f64,
) -> anyhow::Result<()> {
    let (ylo, yhi) = range(
        panel
            .series
            .iter()
            .flat_map(|(_, s, _)| s.iter().map(|p| p.1)),
    );
    let mut chart = ChartBuilder::on(area)
        .caption(panel.title, ("sans-serif", 16))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..t_end, ylo..yhi)
        .map_err(|e| anyhow!("{e}"))?;
    chart
        .configure_mesh()
        .x_desc("t (µs)")
        .y_desc(panel.unit)
        .draw()
        .map_err(|e| anyhow!("{e}"))?;
    for (label, data, color) in &panel.series {
        let color = *color;
        let drawn = chart
            .draw_series(LineSeries::new(data.iter().copied(), color.stroke_width(2)))
            .map_err(|e| anyhow!("{e}"))?;
        if !label.is_empty() {
            drawn
                .label(label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
        }
    }
    chart
        .configure_series_labels()
        .position(legend_corner(&panel.series, t_end, ylo, yhi))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| anyhow!("{e}"))?;
    Ok(())
}
