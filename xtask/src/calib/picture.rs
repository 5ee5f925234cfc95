//! Pictures of the error vectors of a camera calibration, SVG and PNG:
//! at each commanded point, the measured error (red) and what is left
//! after the fit (blue), magnified so the longest measured arrow is one
//! grid pitch.

use std::fmt::Write as _;

use kinematics_core::MeasuredPoint;

/// Grid pitch the arrows are scaled to, mm.
const PITCH_MM: f64 = 19.16;
/// PNG pixels per board mm.
const PNG_PX_PER_MM: f64 = 3.0;
/// Colours (RGB) of the measured and the remaining error.
const RED: [u8; 3] = [0xdd, 0x22, 0x22];
const BLUE: [u8; 3] = [0x22, 0x22, 0xdd];
const DOT: [u8; 3] = [0x44, 0x44, 0x44];

/// The drawing in board mm, y up: its view box and the arrows.
struct Drawing {
    /// Arrow length per mm of error.
    gain: f64,
    /// Longest measured error, mm.
    worst: f64,
    /// View box `[x0, y0 (top, SVG y down), width, height]`, mm.
    view: [f64; 4],
    /// Arrows `(from, to, colour)` in SVG coordinates (mm, y down).
    arrows: Vec<([f64; 2], [f64; 2], [u8; 3])>,
    /// Commanded points in SVG coordinates.
    dots: Vec<[f64; 2]>,
}

impl Drawing {
    fn new(points: &[MeasuredPoint], after: &[(f64, f64)]) -> Self {
        let worst = points
            .iter()
            .map(|p| p.dx_mm.hypot(p.dy_mm))
            .fold(0.0, f64::max);
        let gain = if worst > 0.0 { PITCH_MM / worst } else { 1.0 };
        let (xmax, ymax) = points.iter().fold((10.0f64, 10.0f64), |(a, b), p| {
            (a.max(p.x_mm.abs()), b.max(p.y_mm.abs()))
        });
        let (w, h) = (
            2.0 * (xmax + 2.0 * PITCH_MM),
            2.0 * (ymax + 2.0 * PITCH_MM) + 12.0,
        );
        let mut arrows = Vec::new();
        let mut dots = Vec::new();
        for (p, (ax, ay)) in points.iter().zip(after) {
            let from = [p.x_mm, -p.y_mm];
            dots.push(from);
            for (dx, dy, colour) in [(p.dx_mm, p.dy_mm, RED), (*ax, *ay, BLUE)] {
                arrows.push((from, [from[0] + gain * dx, from[1] - gain * dy], colour));
            }
        }
        Self {
            gain,
            worst,
            view: [-w / 2.0, -h / 2.0 + 6.0, w, h],
            arrows,
            dots,
        }
    }
}

fn hex([r, g, b]: [u8; 3]) -> String {
    format!("#{r:02x}{g:02x}{b:02x}")
}

/// The error vectors as SVG (1 unit = 1 mm of board).
pub fn error_vectors_svg(points: &[MeasuredPoint], after: &[(f64, f64)]) -> String {
    let d = Drawing::new(points, after);
    let [x0, y0, w, h] = d.view;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{:.0}\" height=\"{:.0}\" viewBox=\"{x0:.2} {y0:.2} {w:.2} {h:.2}\">",
        w * 3.0,
        h * 3.0,
    );
    let _ = writeln!(
        s,
        "<rect x=\"{x0:.2}\" y=\"{y0:.2}\" width=\"{w:.2}\" height=\"{h:.2}\" fill=\"white\"/>"
    );
    let _ = writeln!(
        s,
        "<text x=\"{:.2}\" y=\"{:.2}\" font-size=\"4\" font-family=\"sans-serif\">error vectors x{:.1}: red measured (worst {:.3} mm), blue left after the fit</text>",
        x0 + 3.0,
        y0 + 5.0,
        d.gain,
        d.worst
    );
    for [x, y] in &d.dots {
        let _ = writeln!(
            s,
            "<circle cx=\"{x:.2}\" cy=\"{y:.2}\" r=\"0.6\" fill=\"{}\"/>",
            hex(DOT)
        );
    }
    for (from, to, colour) in &d.arrows {
        let _ = writeln!(
            s,
            "<line x1=\"{:.2}\" y1=\"{:.2}\" x2=\"{:.2}\" y2=\"{:.2}\" stroke=\"{}\" stroke-width=\"0.5\"/>",
            from[0],
            from[1],
            to[0],
            to[1],
            hex(*colour)
        );
    }
    s.push_str("</svg>\n");
    s
}

/// An RGB canvas.
struct Canvas {
    width: usize,
    height: usize,
    rgb: Vec<u8>,
}

impl Canvas {
    fn put(&mut self, x: f64, y: f64, colour: [u8; 3]) {
        if x < 0.0 || y < 0.0 {
            return;
        }
        let (x, y) = (x as usize, y as usize);
        if x < self.width && y < self.height {
            let i = 3 * (y * self.width + x);
            self.rgb[i..i + 3].copy_from_slice(&colour);
        }
    }

    /// A disc of `radius` px at `c`.
    fn disc(&mut self, c: [f64; 2], radius: f64, colour: [u8; 3]) {
        let r = radius.ceil() as i32;
        for dy in -r..=r {
            for dx in -r..=r {
                if f64::from(dx).hypot(f64::from(dy)) <= radius {
                    self.put(c[0] + f64::from(dx), c[1] + f64::from(dy), colour);
                }
            }
        }
    }

    /// A line `width` px wide.
    fn line(&mut self, a: [f64; 2], b: [f64; 2], width: f64, colour: [u8; 3]) {
        let steps = ((b[0] - a[0]).hypot(b[1] - a[1]) * 2.0).ceil().max(1.0) as usize;
        for k in 0..=steps {
            let t = k as f64 / steps as f64;
            let p = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
            self.disc(p, width / 2.0, colour);
        }
    }
}

/// The error vectors as a PNG ([`PNG_PX_PER_MM`] px per board mm; the
/// colours of the SVG, without its caption).
pub fn error_vectors_png(
    points: &[MeasuredPoint],
    after: &[(f64, f64)],
) -> Result<Vec<u8>, String> {
    let d = Drawing::new(points, after);
    let [x0, y0, w, h] = d.view;
    let s = PNG_PX_PER_MM;
    let (width, height) = ((w * s).ceil() as usize, (h * s).ceil() as usize);
    let mut canvas = Canvas {
        width,
        height,
        rgb: vec![255; 3 * width * height],
    };
    let px = |p: [f64; 2]| [(p[0] - x0) * s, (p[1] - y0) * s];
    for p in &d.dots {
        canvas.disc(px(*p), 0.6 * s, DOT);
    }
    for (from, to, colour) in &d.arrows {
        canvas.line(px(*from), px(*to), 0.5 * s, *colour);
    }
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, width as u32, height as u32);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut writer = enc.write_header().map_err(|e| format!("png: {e}"))?;
        writer
            .write_image_data(&canvas.rgb)
            .map_err(|e| format!("png: {e}"))?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_png_shows_the_arrows_in_their_colours() {
        let points = [MeasuredPoint {
            x_mm: 0.0,
            y_mm: 0.0,
            dx_mm: 2.0,
            dy_mm: 0.0,
        }];
        let bytes = error_vectors_png(&points, &[(0.0, -0.5)]).unwrap();
        let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        let d = Drawing::new(&points, &[(0.0, -0.5)]);
        let at = |p: [f64; 2]| {
            let (x, y) = (
                ((p[0] - d.view[0]) * PNG_PX_PER_MM) as usize,
                ((p[1] - d.view[1]) * PNG_PX_PER_MM) as usize,
            );
            let i = 3 * (y * info.width as usize + x);
            [buf[i], buf[i + 1], buf[i + 2]]
        };
        // Red along +x (the measured 2 mm, drawn one pitch long), blue
        // below the point (the 0.5 mm left, y down in the picture).
        assert_eq!(at([PITCH_MM * 0.8, 0.0]), RED);
        assert_eq!(at([0.0, 0.5 * d.gain * 0.8]), BLUE);
        assert_eq!(at([-PITCH_MM * 0.8, 0.0]), [255; 3]);
    }
}
