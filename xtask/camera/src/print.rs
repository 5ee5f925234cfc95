//! The target as a one-page PDF at true scale (`cargo xtask calib target
//! --out board.pdf`): the page is the board's printed area, the same ink
//! rectangles as the SVG, captions in the viewer's built-in Helvetica.

use pdf_writer::{Content, Finish, Name, Pdf, Rect, Ref, Str};

use crate::target::TargetLayout;

/// PDF points per mm.
pub const PT_PER_MM: f64 = 72.0 / 25.4;

/// The PDF of `layout` (page size = its extent; 1 mm on the page = 1 mm on the board).
pub fn pdf(layout: &TargetLayout) -> Vec<u8> {
    let [x0, y0, x1, y1] = layout.extent_mm;
    let (catalog, tree, page_id, font, content_id) = (
        Ref::new(1),
        Ref::new(2),
        Ref::new(3),
        Ref::new(4),
        Ref::new(5),
    );
    let font_name = Name(b"F1");
    let mut pdf = Pdf::new();
    pdf.catalog(catalog).pages(tree);
    pdf.pages(tree).kids([page_id]).count(1);
    let mut page = pdf.page(page_id);
    page.media_box(Rect::new(
        0.0,
        0.0,
        ((x1 - x0) * PT_PER_MM) as f32,
        ((y1 - y0) * PT_PER_MM) as f32,
    ));
    page.parent(tree);
    page.contents(content_id);
    page.resources().fonts().pair(font_name, font);
    page.finish();
    pdf.type1_font(font).base_font(Name(b"Helvetica"));

    let mut c = Content::new();
    // Board mm (origin at the grid centre, y up) to page points.
    let k = PT_PER_MM as f32;
    c.transform([
        k,
        0.0,
        0.0,
        k,
        (-x0 * PT_PER_MM) as f32,
        (-y0 * PT_PER_MM) as f32,
    ]);
    c.set_fill_gray(0.0);
    for [x, y, w, h] in layout.ink_rects() {
        c.rect(x as f32, y as f32, w as f32, h as f32);
    }
    c.fill_nonzero();
    c.set_fill_gray(0.33);
    for (x, y, size, text) in layout.captions() {
        c.begin_text();
        c.set_font(font_name, size as f32);
        c.next_line(x as f32, y as f32);
        // Helvetica's standard encoding: ASCII only.
        let ascii: Vec<u8> = text
            .bytes()
            .map(|b| {
                if b.is_ascii_graphic() || b == b' ' {
                    b
                } else {
                    b'?'
                }
            })
            .collect();
        c.show(Str(&ascii));
        c.end_text();
    }
    pdf.stream(content_id, &c.finish());
    pdf.finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::target::GridSpec;

    #[test]
    fn the_page_is_the_board_at_true_scale_with_every_rectangle() {
        let l = TargetLayout::for_grid(GridSpec::default()).unwrap();
        let bytes = pdf(&l);
        let text = String::from_utf8_lossy(&bytes);
        assert!(text.starts_with("%PDF-"), "{}", &text[..20]);
        let [x0, y0, x1, y1] = l.extent_mm;
        // The media box in points: the board's extent (335 × 272 mm) at 72/25.4.
        let i = text.find("/MediaBox [").unwrap() + "/MediaBox [".len();
        let numbers: Vec<f64> = text[i..text[i..].find(']').unwrap() + i]
            .split_whitespace()
            .map(|s| s.parse().unwrap())
            .collect();
        assert_eq!(numbers.len(), 4);
        assert!(
            (numbers[2] / PT_PER_MM - (x1 - x0)).abs() < 0.01,
            "{numbers:?}"
        );
        assert!(
            (numbers[3] / PT_PER_MM - (y1 - y0)).abs() < 0.01,
            "{numbers:?}"
        );
        // One `re` per ink rectangle (the content stream is not compressed).
        let rects = text.lines().filter(|l| l.ends_with(" re")).count();
        assert_eq!(rects, l.ink_rects().len());
        assert!(text.contains("(100 mm: check this bar"));
        assert!(text.contains("/BaseFont /Helvetica"));
    }
}
