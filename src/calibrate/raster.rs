//! A small raster plotter for the calibration PNG: panels with axes, decade or linear ticks,
//! lines, markers, error bars and a legend, lettered with a built-in 3×5 pixel font, so the
//! PNG needs no system fonts (a fresh machine may have none). Encoded with the `png` crate.

pub type Rgb = [u8; 3];

pub const BLACK: Rgb = [20, 20, 20];
pub const RED: Rgb = [200, 40, 40];
pub const BLUE: Rgb = [30, 90, 200];
const GREY: Rgb = [205, 205, 205];
const WHITE: Rgb = [255, 255, 255];
/// Font pixels are drawn as squares of this many screen pixels.
const FONT_SCALE: i64 = 2;

pub struct Canvas {
    pub width: usize,
    pub height: usize,
    pixels: Vec<Rgb>,
}

impl Canvas {
    pub fn new(width: usize, height: usize) -> Canvas {
        Canvas {
            width,
            height,
            pixels: vec![WHITE; width * height],
        }
    }

    pub fn pixel(&self, x: usize, y: usize) -> Rgb {
        self.pixels[y * self.width + x]
    }

    fn set(&mut self, x: i64, y: i64, c: Rgb) {
        if x >= 0 && y >= 0 && (x as usize) < self.width && (y as usize) < self.height {
            self.pixels[y as usize * self.width + x as usize] = c;
        }
    }

    fn fill(&mut self, x0: i64, y0: i64, x1: i64, y1: i64, c: Rgb) {
        for y in y0.min(y1)..=y0.max(y1) {
            for x in x0.min(x1)..=x0.max(x1) {
                self.set(x, y, c);
            }
        }
    }

    /// A line `width` pixels wide (Bresenham, thickened with a square brush).
    pub fn line(&mut self, a: (f64, f64), b: (f64, f64), c: Rgb, width: i64) {
        let (mut x0, mut y0) = (a.0.round() as i64, a.1.round() as i64);
        let (x1, y1) = (b.0.round() as i64, b.1.round() as i64);
        let (dx, dy) = ((x1 - x0).abs(), -(y1 - y0).abs());
        let (sx, sy) = (if x0 < x1 { 1 } else { -1 }, if y0 < y1 { 1 } else { -1 });
        let mut err = dx + dy;
        let half = (width - 1) / 2;
        loop {
            self.fill(
                x0 - half,
                y0 - half,
                x0 - half + width - 1,
                y0 - half + width - 1,
                c,
            );
            if x0 == x1 && y0 == y1 {
                break;
            }
            let e2 = 2 * err;
            if e2 >= dy {
                err += dy;
                x0 += sx;
            }
            if e2 <= dx {
                err += dx;
                y0 += sy;
            }
        }
    }

    fn marker(&mut self, x: f64, y: f64, c: Rgb) {
        let (x, y) = (x.round() as i64, y.round() as i64);
        self.fill(x - 3, y - 3, x + 3, y + 3, c);
    }

    /// Text with its top-left corner at (x, y); lower case is drawn as upper case.
    pub fn text(&mut self, x: i64, y: i64, s: &str, c: Rgb) {
        for (k, ch) in s.chars().enumerate() {
            let rows = glyph(fold(ch));
            let left = x + k as i64 * 4 * FONT_SCALE;
            for (r, bits) in rows.iter().enumerate() {
                for col in 0..3 {
                    if bits & (0b100 >> col) != 0 {
                        let px = left + col * FONT_SCALE;
                        let py = y + r as i64 * FONT_SCALE;
                        self.fill(px, py, px + FONT_SCALE - 1, py + FONT_SCALE - 1, c);
                    }
                }
            }
        }
    }

    pub fn text_width(s: &str) -> i64 {
        s.chars().count() as i64 * 4 * FONT_SCALE
    }

    /// The image as PNG bytes (8-bit RGB).
    pub fn to_png(&self) -> Result<Vec<u8>, png::EncodingError> {
        let mut out = Vec::new();
        {
            let mut encoder = png::Encoder::new(&mut out, self.width as u32, self.height as u32);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            let mut writer = encoder.write_header()?;
            let data: Vec<u8> = self.pixels.iter().flatten().copied().collect();
            writer.write_image_data(&data)?;
        }
        Ok(out)
    }
}

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mark {
    Line,
    /// Markers with vertical error bars (the points' third value is 1σ).
    ErrorBars,
}

pub struct PanelSeries {
    pub label: String,
    pub colour: Rgb,
    pub mark: Mark,
    /// (x, y, σ)
    pub points: Vec<(f64, f64, f64)>,
}

pub struct Panel {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_log: bool,
    pub series: Vec<PanelSeries>,
    /// Category names for x = 1, 2, ... instead of numeric ticks.
    pub categories: Vec<String>,
}

struct Frame {
    left: f64,
    top: f64,
    right: f64,
    bottom: f64,
    x: (f64, f64),
    y: (f64, f64),
    x_log: bool,
}

impl Frame {
    fn map(&self, x: f64, y: f64) -> Option<(f64, f64)> {
        let xv = if self.x_log { x.log10() } else { x };
        let fx = (xv - self.x.0) / (self.x.1 - self.x.0);
        let fy = (y - self.y.0) / (self.y.1 - self.y.0);
        (fx.is_finite() && fy.is_finite()).then_some((
            self.left + fx * (self.right - self.left),
            self.bottom - fy * (self.bottom - self.top),
        ))
    }
}

/// Draws `panel` into the rectangle (x0, y0, width, height) of `canvas`.
pub fn draw_panel(canvas: &mut Canvas, panel: &Panel, x0: f64, y0: f64, w: f64, h: f64) {
    let points = || panel.series.iter().flat_map(|s| s.points.iter());
    let finite = |v: f64| v.is_finite();
    let xs: Vec<f64> = points()
        .map(|p| if panel.x_log { p.0.log10() } else { p.0 })
        .filter(|v| finite(*v))
        .collect();
    let ys: Vec<f64> = points()
        .flat_map(|p| [p.1 - p.2.max(0.0), p.1 + p.2.max(0.0)])
        .filter(|v| finite(*v))
        .collect();
    let span = |v: &[f64]| {
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if lo.is_finite() && hi > lo {
            (lo, hi)
        } else if lo.is_finite() {
            (lo - 0.5, lo + 0.5)
        } else {
            (0.0, 1.0)
        }
    };
    let (mut xl, mut xh) = span(&xs);
    if panel.x_log {
        xl = xl.floor();
        xh = xh.ceil();
    } else if !panel.categories.is_empty() {
        xl = 0.5;
        xh = panel.categories.len() as f64 + 0.5;
    }
    let (yl, yh) = span(&ys);
    let pad = 0.08 * (yh - yl);
    let step = nice_step((yh - yl + 2.0 * pad) / 5.0);
    let f = Frame {
        left: x0 + 78.0,
        top: y0 + 30.0,
        right: x0 + w - 16.0,
        bottom: y0 + h - 44.0,
        x: (xl, xh),
        y: (
            ((yl - pad) / step).floor() * step,
            ((yh + pad) / step).ceil() * step,
        ),
        x_log: panel.x_log,
    };
    // Grid and tick labels.
    let mut y = f.y.0;
    while y <= f.y.1 + 1e-9 * step {
        if let Some((_, py)) = f.map(if f.x_log { 10f64.powf(f.x.0) } else { f.x.0 }, y) {
            canvas.line((f.left, py), (f.right, py), GREY, 1);
            let label = format!("{:.*}", decimals(step), y);
            canvas.text(
                f.left as i64 - 8 - Canvas::text_width(&label),
                py as i64 - 5,
                &label,
                BLACK,
            );
        }
        y += step;
    }
    if panel.categories.is_empty() {
        let ticks: Vec<f64> = if f.x_log {
            (f.x.0 as i64..=f.x.1 as i64).map(|d| d as f64).collect()
        } else {
            let s = nice_step((f.x.1 - f.x.0) / 5.0);
            let mut t = Vec::new();
            let mut v = (f.x.0 / s).ceil() * s;
            while v <= f.x.1 + 1e-9 * s {
                t.push(v);
                v += s;
            }
            t
        };
        for t in ticks {
            let xv = if f.x_log { 10f64.powf(t) } else { t };
            if let Some((px, _)) = f.map(xv, f.y.0) {
                canvas.line((px, f.top), (px, f.bottom), GREY, 1);
                let label = if f.x_log {
                    format!("10^{}", t as i64)
                } else {
                    format!("{:.*}", decimals(t.abs().max(1e-12)), t)
                };
                canvas.text(
                    px as i64 - Canvas::text_width(&label) / 2,
                    f.bottom as i64 + 8,
                    &label,
                    BLACK,
                );
            }
        }
    } else {
        for (k, name) in panel.categories.iter().enumerate() {
            if let Some((px, _)) = f.map(k as f64 + 1.0, f.y.0) {
                canvas.text(
                    px as i64 - Canvas::text_width(name) / 2,
                    f.bottom as i64 + 8,
                    name,
                    BLACK,
                );
            }
        }
    }
    // Frame, titles.
    let corners = [
        (f.left, f.top),
        (f.right, f.top),
        (f.right, f.bottom),
        (f.left, f.bottom),
    ];
    for k in 0..4 {
        canvas.line(corners[k], corners[(k + 1) % 4], BLACK, 1);
    }
    canvas.text(
        ((f.left + f.right) / 2.0) as i64 - Canvas::text_width(&panel.title) / 2,
        y0 as i64 + 8,
        &panel.title,
        BLACK,
    );
    canvas.text(
        ((f.left + f.right) / 2.0) as i64 - Canvas::text_width(&panel.x_label) / 2,
        f.bottom as i64 + 26,
        &panel.x_label,
        BLACK,
    );
    canvas.text(x0 as i64 + 4, y0 as i64 + 8, &panel.y_label, BLACK);
    // Data.
    for s in &panel.series {
        let mapped: Vec<Option<(f64, f64)>> = s.points.iter().map(|p| f.map(p.0, p.1)).collect();
        match s.mark {
            Mark::Line => {
                for w in mapped.windows(2) {
                    if let (Some(a), Some(b)) = (w[0], w[1]) {
                        canvas.line(a, b, s.colour, 3);
                    }
                }
                if mapped.iter().flatten().count() == 1 {
                    let p = mapped.iter().flatten().next().unwrap();
                    canvas.line((p.0 - 12.0, p.1), (p.0 + 12.0, p.1), s.colour, 3);
                }
            }
            Mark::ErrorBars => {
                for (p, m) in s.points.iter().zip(&mapped) {
                    if let (Some((px, py)), Some((_, lo)), Some((_, hi))) =
                        (*m, f.map(p.0, p.1 - p.2), f.map(p.0, p.1 + p.2))
                    {
                        canvas.line((px, lo), (px, hi), s.colour, 1);
                        canvas.marker(px, py, s.colour);
                    }
                }
            }
        }
    }
    // Legend, top left inside the frame.
    for (k, s) in panel.series.iter().enumerate() {
        let ly = f.top + 12.0 + 16.0 * k as f64;
        let lx = f.left + 10.0;
        match s.mark {
            Mark::Line => canvas.line((lx, ly), (lx + 20.0, ly), s.colour, 3),
            Mark::ErrorBars => canvas.marker(lx + 10.0, ly, s.colour),
        }
        canvas.text(lx as i64 + 28, ly as i64 - 5, &s.label, s.colour);
    }
}

fn nice_step(raw: f64) -> f64 {
    let raw = if raw > 0.0 && raw.is_finite() {
        raw
    } else {
        0.1
    };
    let mag = 10f64.powf(raw.log10().floor());
    let r = raw / mag;
    mag * if r <= 1.0 {
        1.0
    } else if r <= 2.0 {
        2.0
    } else if r <= 5.0 {
        5.0
    } else {
        10.0
    }
}

fn decimals(step: f64) -> usize {
    (-step.log10().floor()).clamp(0.0, 6.0) as usize
}

/// Upper case without accents ("Güttler" is drawn as GUTTLER): the font has no diacritics.
fn fold(ch: char) -> char {
    match ch.to_uppercase().next().unwrap_or(ch) {
        'Ä' | 'Á' | 'À' | 'Â' => 'A',
        'Ö' | 'Ó' | 'Ò' | 'Ô' => 'O',
        'Ü' | 'Ú' | 'Ù' | 'Û' => 'U',
        'É' | 'È' | 'Ê' | 'Ë' => 'E',
        'ß' => 'S',
        c => c,
    }
}

/// 3×5 glyphs, one row per entry, bit 2 = left column.
fn glyph(c: char) -> [u8; 5] {
    match c {
        '0' => [7, 5, 5, 5, 7],
        '1' => [2, 6, 2, 2, 7],
        '2' => [7, 1, 7, 4, 7],
        '3' => [7, 1, 7, 1, 7],
        '4' => [5, 5, 7, 1, 1],
        '5' => [7, 4, 7, 1, 7],
        '6' => [7, 4, 7, 5, 7],
        '7' => [7, 1, 1, 1, 1],
        '8' => [7, 5, 7, 5, 7],
        '9' => [7, 5, 7, 1, 7],
        'A' => [2, 5, 7, 5, 5],
        'B' => [6, 5, 6, 5, 6],
        'C' => [3, 4, 4, 4, 3],
        'D' => [6, 5, 5, 5, 6],
        'E' => [7, 4, 6, 4, 7],
        'F' => [7, 4, 6, 4, 4],
        'G' => [3, 4, 5, 5, 3],
        'H' => [5, 5, 7, 5, 5],
        'I' => [7, 2, 2, 2, 7],
        'J' => [1, 1, 1, 5, 2],
        'K' => [5, 5, 6, 5, 5],
        'L' => [4, 4, 4, 4, 7],
        'M' => [5, 7, 7, 5, 5],
        'N' => [6, 5, 5, 5, 5],
        'O' => [2, 5, 5, 5, 2],
        'P' => [6, 5, 6, 4, 4],
        'Q' => [2, 5, 5, 6, 3],
        'R' => [6, 5, 6, 5, 5],
        'S' => [3, 4, 2, 1, 6],
        'T' => [7, 2, 2, 2, 2],
        'U' => [5, 5, 5, 5, 7],
        'V' => [5, 5, 5, 5, 2],
        'W' => [5, 5, 7, 7, 5],
        'X' => [5, 5, 2, 5, 5],
        'Y' => [5, 5, 2, 2, 2],
        'Z' => [7, 1, 2, 4, 7],
        '.' => [0, 0, 0, 0, 2],
        ',' => [0, 0, 0, 2, 4],
        '-' | '−' => [0, 0, 7, 0, 0],
        '+' => [0, 2, 7, 2, 0],
        '=' => [0, 7, 0, 7, 0],
        '/' => [1, 1, 2, 4, 4],
        '(' => [2, 4, 4, 4, 2],
        ')' => [2, 1, 1, 1, 2],
        ':' => [0, 2, 0, 2, 0],
        '%' => [5, 1, 2, 4, 5],
        '^' => [2, 5, 0, 0, 0],
        '_' => [0, 0, 0, 0, 7],
        'Φ' | 'φ' => [2, 7, 5, 7, 2],
        _ => [0, 0, 0, 0, 0],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_series_in_their_colours_and_encodes_a_png() {
        let mut canvas = Canvas::new(400, 300);
        let panel = Panel {
            title: "test".into(),
            x_label: "P (Pa)".into(),
            y_label: "phi".into(),
            x_log: true,
            categories: Vec::new(),
            series: vec![
                PanelSeries {
                    label: "measured".into(),
                    colour: BLACK,
                    mark: Mark::ErrorBars,
                    points: vec![(1e2, 0.2, 0.01), (1e4, 0.4, 0.01)],
                },
                PanelSeries {
                    label: "model".into(),
                    colour: RED,
                    mark: Mark::Line,
                    points: vec![(1e2, 0.25, 0.0), (1e4, 0.45, 0.0)],
                },
            ],
        };
        draw_panel(&mut canvas, &panel, 0.0, 0.0, 400.0, 300.0);
        let count = |c: Rgb| {
            (0..300)
                .flat_map(|y| (0..400).map(move |x| (x, y)))
                .filter(|&(x, y)| canvas.pixel(x, y) == c)
                .count()
        };
        assert!(count(RED) > 200, "{}", count(RED));
        assert_eq!(fold('ü'), 'U');
        assert_eq!(glyph(fold('ä')), glyph('A'));
        let bytes = canvas.to_png().unwrap();
        let decoder = png::Decoder::new(bytes.as_slice());
        let reader = decoder.read_info().unwrap();
        assert_eq!(reader.info().width, 400);
        assert_eq!(reader.info().height, 300);
    }
}
