//! The PNGs' text is drawn as the font lays it out: a word's ink spans what DejaVu Sans's own
//! metrics say at the SVG's size (each glyph's advance, from the first glyph's left edge to
//! the last one's right), to 2 px in 168. Plotters' bitmap backend, which drew the PNGs before resvg,
//! spread words apart ("Probabili ty"): the same measure on its drawing is kept here as the
//! control that fails.

use super::*;

/// The word, its size as plotters takes it, and the canvas it is drawn on.
const WORD: &str = "Probability";
const PX: f64 = 40.0;
/// Plotters' SVG sets a size as font-size = size / 1.24 (plotters-svg's `draw_text`): the em
/// the figure's text has, px.
const EM: f64 = PX / 1.24;
const CANVAS: (u32, u32) = (500, 80);

struct Word;

impl Figure for Word {
    fn size(&self) -> (u32, u32) {
        CANVAS
    }
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        root.fill(&WHITE).map_err(plot_err)?;
        let style = TextStyle::from((FONT, PX).into_font()).color(&BLACK);
        root.draw_text(WORD, &style, (20, 15)).map_err(plot_err)
    }
}

/// The word's ink across `rgb` (w × h, 3 bytes a pixel): its first and last dark column, and
/// the widest run of blank columns between them.
fn ink(rgb: &[u8], (w, h): (u32, u32)) -> (u32, u32, u32) {
    let dark = |x: u32| (0..h).any(|y| rgb[3 * (y * w + x) as usize] < 128);
    let cols: Vec<u32> = (0..w).filter(|&x| dark(x)).collect();
    let (first, last) = (cols[0], *cols.last().unwrap());
    let gap = cols.windows(2).map(|p| p[1] - p[0] - 1).max().unwrap_or(0);
    (first, last, gap)
}

/// The word's ink width as the font lays it out, px: the advances of all glyphs but the last,
/// then the last one's right edge, less the first one's left side bearing (no kerning pair of
/// DejaVu Sans falls in this word).
fn laid_out() -> f64 {
    let face = ttf_parser::Face::parse(dejavu::sans::regular(), 0).unwrap();
    let scale = EM / f64::from(face.units_per_em());
    let glyphs: Vec<ttf_parser::GlyphId> =
        WORD.chars().map(|c| face.glyph_index(c).unwrap()).collect();
    let (first, last) = (glyphs[0], *glyphs.last().unwrap());
    let advances: f64 = glyphs[..glyphs.len() - 1]
        .iter()
        .map(|g| f64::from(face.glyph_hor_advance(*g).unwrap()))
        .sum();
    let right = f64::from(face.glyph_bounding_box(last).unwrap().x_max);
    let left = f64::from(face.glyph_bounding_box(first).unwrap().x_min);
    (advances + right - left) * scale
}

fn new_rgb() -> Vec<u8> {
    ensure_font().unwrap();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, CANVAS).into_drawing_area();
        Word.draw(&root).unwrap();
        root.present().unwrap();
    }
    let png = png_of(&svg, CANVAS).unwrap();
    image::load_from_memory(&png).unwrap().to_rgb8().into_raw()
}

fn old_rgb() -> Vec<u8> {
    ensure_font().unwrap();
    let mut rgb = vec![0u8; 3 * (CANVAS.0 * CANVAS.1) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, CANVAS).into_drawing_area();
        Word.draw(&root).unwrap();
        root.present().unwrap();
    }
    rgb
}

/// Whether a drawing's word is as wide as the font lays it out, to 2 px.
fn set_right(name: &str, rgb: &[u8]) -> bool {
    let (first, last, gap) = ink(rgb, CANVAS);
    let (span, want) = (f64::from(last - first + 1), laid_out());
    eprintln!("{name}: ink {span} px, laid out {want:.1} px, widest gap {gap} px");
    (span - want).abs() <= 2.0
}

#[test]
fn the_pngs_text_is_set_as_the_font_lays_it_out() {
    assert!(set_right("resvg", &new_rgb()));
}

#[test]
fn plotters_bitmap_text_was_not() {
    assert!(!set_right("plotters' bitmap", &old_rgb()));
}
