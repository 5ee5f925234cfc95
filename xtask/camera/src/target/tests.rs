use super::*;

#[test]
fn layout_rings_the_working_area_without_overlaps() {
    let l = TargetLayout::for_grid(GridSpec::default()).unwrap();
    assert_eq!(l.tags.len(), 14);
    let g = l.grid_points_mm();
    assert_eq!(g.len(), 13 * 9);
    for (i, a) in l.tags.iter().enumerate() {
        let half = a.size_mm * 10.0 / 16.0;
        // Outside the grid area (with its 10 mm margin) …
        assert!(
            a.centre_mm[0].abs() - half > 6.0 * 19.16 + 10.0
                || a.centre_mm[1].abs() - half > 4.0 * 19.16 + 10.0
        );
        // … and clear of each other, quiet zones included.
        for b in &l.tags[i + 1..] {
            let d = (a.centre_mm[0] - b.centre_mm[0])
                .abs()
                .max((a.centre_mm[1] - b.centre_mm[1]).abs());
            assert!(d >= 2.0 * half, "{} {}", a.id, b.id);
        }
        let [x0, y0, x1, y1] = l.extent_mm;
        assert!(
            a.centre_mm[0] - half > x0
                && a.centre_mm[0] + half < x1
                && a.centre_mm[1] - half > y0
                && a.centre_mm[1] + half < y1
        );
    }
    // Ink at a tag's black border, paper in its quiet zone, ink on the grid crosses.
    let t = &l.tags[0];
    let c = t.cell_mm();
    assert_eq!(
        l.reflectance([t.centre_mm[0] - 3.5 * c, t.centre_mm[1]]),
        INK
    );
    assert_eq!(
        l.reflectance([t.centre_mm[0] - 4.5 * c, t.centre_mm[1]]),
        PAPER
    );
    assert_eq!(l.reflectance([19.16 + 1.0, 0.0]), INK);
    assert_eq!(l.reflectance([19.16 / 2.0, 19.16 / 2.0]), PAPER);
}

#[test]
fn tag_cells_follow_the_family_code() {
    let family = TagFamily::tag36_h11().unwrap();
    let l = TargetLayout::for_grid(GridSpec::default()).unwrap();
    for t in &l.tags {
        let mut code = 0usize;
        for i in 0..36 {
            let (c, r) = (
                (family.bit_x[i] + 1) as usize,
                (family.bit_y[i] + 1) as usize,
            );
            code = (code << 1) | usize::from(!t.is_ink(c, r));
        }
        assert_eq!(code, family.code_data[usize::from(t.id)]);
        for k in 0..10 {
            assert!(!t.is_ink(k, 0) && !t.is_ink(0, k) && !t.is_ink(k, 9) && !t.is_ink(9, k));
            if (1..=8).contains(&k) {
                assert!(t.is_ink(k, 1) && t.is_ink(1, k) && t.is_ink(k, 8) && t.is_ink(8, k));
            }
        }
    }
}

/// The SVG's black rectangles are exactly the ink of [`TargetLayout::reflectance`]
/// (what the virtual camera renders), sampled on a 0.37 mm lattice.
#[test]
fn svg_draws_what_the_renderer_renders() {
    let l = TargetLayout::for_grid(GridSpec::default()).unwrap();
    let svg = l.svg();
    assert!(svg.contains("mm\" height=") && svg.contains("100 mm"));
    let num = |s: &str, key: &str| -> f64 {
        let i = s.find(&format!("{key}=\"")).unwrap() + key.len() + 2;
        s[i..s[i..].find('"').unwrap() + i].parse().unwrap()
    };
    let body = &svg[svg.find("<g fill=\"black\"").unwrap()..svg.find("</g>").unwrap()];
    let rects: Vec<[f64; 4]> = body
        .lines()
        .filter(|s| s.starts_with("<rect"))
        .map(|s| [num(s, "x"), -num(s, "y"), num(s, "width"), num(s, "height")])
        .collect();
    assert!(rects.len() > 14 * 36);
    let [x0, y0, x1, y1] = l.extent_mm;
    let (mut x, mut checked) = (x0 + 0.011, 0);
    while x < x1 {
        let mut y = y0 + 0.013;
        while y < y1 {
            let in_svg = rects
                .iter()
                .any(|r| x >= r[0] && x <= r[0] + r[2] && y <= r[1] && y >= r[1] - r[3]);
            // Edges agree to the SVG's 1e-4 mm rounding.
            let near_edge = [[0.0005, 0.0], [-0.0005, 0.0], [0.0, 0.0005], [0.0, -0.0005]]
                .iter()
                .any(|d| l.ink_at([x + d[0], y + d[1]]) != l.ink_at([x, y]));
            if !near_edge {
                assert_eq!(in_svg, l.ink_at([x, y]), "at ({x}, {y})");
                checked += 1;
            }
            y += 0.37;
        }
        x += 0.37;
    }
    assert!(checked > 500_000);
}
