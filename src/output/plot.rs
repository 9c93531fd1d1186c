//! Owns every figure dustdem draws: a chart description ([`Plot`]) rendered by `plotters` to
//! SVG or PNG with the same code, lettered with DejaVu Sans embedded in the binary (no system
//! fonts needed). Points that cannot be placed (non-finite, or ≤ 0 on a log axis) are skipped
//! and break the line there; lines are clipped at the frame.

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use std::io;
use std::path::Path;

mod axis;
use axis::{clip, runs, Axis};

/// A colour as 0xRRGGBB.
pub type Rgb = u32;

/// Okabe–Ito colours, by series index: distinguishable with the common colour-vision
/// deficiencies and in greyscale print.
pub const PALETTE: [Rgb; 8] = [
    0x0072B2, 0xD55E00, 0x009E73, 0xCC79A7, 0xE69F00, 0x56B4E9, 0x000000, 0xF0E442,
];
pub const BLACK: Rgb = 0x000000;
const FONT: &str = "sans-serif";

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    Line,
    Dashed,
    Markers,
    /// Markers with vertical ±σ bars (σ from [`Series::sigma`]).
    ErrorBars,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend entry; series with an empty name are left out of the legend.
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub style: Style,
    /// 1σ of each point's y, for [`Style::ErrorBars`].
    pub sigma: Vec<f64>,
    /// `None`: the palette colour of the series' index.
    pub color: Option<Rgb>,
}

impl Series {
    pub fn new(name: impl Into<String>, points: Vec<(f64, f64)>, style: Style) -> Self {
        Self {
            name: name.into(),
            points,
            style,
            sigma: Vec::new(),
            color: None,
        }
    }

    pub fn color(self, color: Rgb) -> Self {
        Self {
            color: Some(color),
            ..self
        }
    }
}

/// A chart with a light grid at the ticks and the legend in its emptiest corner.
#[derive(Clone, Debug, PartialEq)]
pub struct Plot {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_log: bool,
    pub y_log: bool,
    pub series: Vec<Series>,
    /// Axis limits; `None` fits the data. Log axes span whole decades, at least two labelled
    /// ones. Limits that are not finite, or not positive on a log axis, are ignored.
    pub x_range: Option<(f64, f64)>,
    pub y_range: Option<(f64, f64)>,
    /// Labelled x ticks in place of the automatic ones (e.g. category names).
    pub x_ticks: Vec<(f64, String)>,
    /// Size in px.
    pub width: u32,
    pub height: u32,
}

impl Plot {
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            x_log: false,
            y_log: false,
            series: Vec::new(),
            x_range: None,
            y_range: None,
            x_ticks: Vec::new(),
            width: 640,
            height: 480,
        }
    }

    pub fn to_svg(&self) -> Result<String, String> {
        let mut svg = String::new();
        let root = SVGBackend::with_string(&mut svg, (self.width, self.height)).into_drawing_area();
        draw(self, &root, true)?;
        root.present().map_err(err)?;
        drop(root);
        Ok(svg)
    }

    /// Writes the SVG atomically (a reader never sees a half-written figure).
    pub fn save(&self, path: impl AsRef<Path>) -> io::Result<()> {
        let svg = self.to_svg().map_err(io::Error::other)?;
        crate::output::atomic::write_atomic(path.as_ref(), svg.as_bytes())
    }
}

/// Panels per row of a multi-panel figure: three 640-px panels read at page width.
pub const GRID_COLUMNS: usize = 3;

/// Where each panel goes: rows of up to [`GRID_COLUMNS`] panels, each at its own width, a
/// row as tall as its tallest panel. Returns the offsets and the figure's size.
fn grid_layout(panels: &[Plot]) -> (Vec<(i32, i32)>, (u32, u32)) {
    let mut offsets = Vec::with_capacity(panels.len());
    let (mut width, mut top) = (1u32, 0u32);
    for row in panels.chunks(GRID_COLUMNS) {
        let mut x = 0u32;
        for p in row {
            offsets.push((x as i32, top as i32));
            x += p.width;
        }
        width = width.max(x);
        top += row.iter().map(|p| p.height).max().unwrap_or(0);
    }
    (offsets, (width, top.max(1)))
}

/// `panels` in rows of up to [`GRID_COLUMNS`] (see [`grid_layout`]), as PNG bytes.
pub fn panels_png(panels: &[Plot]) -> Result<Vec<u8>, String> {
    let (offsets, (w, h)) = grid_layout(panels);
    let mut rgb = vec![255u8; 3 * w as usize * h as usize];
    let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
    for (p, &(x, y)) in panels.iter().zip(&offsets) {
        let area = root
            .clone()
            .shrink((x, y), (p.width, p.height.min(h - y as u32)));
        draw(p, &area, false)?;
    }
    root.present().map_err(err)?;
    drop(root);
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, w, h);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Best);
    encoder.set_adaptive_filter(png::AdaptiveFilterType::Adaptive);
    let mut writer = encoder.write_header().map_err(err)?;
    writer.write_image_data(&rgb).map_err(err)?;
    writer.finish().map_err(err)?;
    Ok(out)
}

/// The same grid as [`panels_png`], as one SVG document.
pub fn panels_svg(panels: &[Plot]) -> Result<String, String> {
    let (offsets, size) = grid_layout(panels);
    let mut svg = String::new();
    let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
    for (p, &(x, y)) in panels.iter().zip(&offsets) {
        draw(p, &root.clone().shrink((x, y), (p.width, p.height)), true)?;
    }
    root.present().map_err(err)?;
    drop(root);
    Ok(svg)
}

fn err(e: impl std::fmt::Display) -> String {
    format!("plot: {e}")
}

/// DejaVu Sans as plotters' "sans-serif", registered once per process.
fn register_font() -> Result<(), String> {
    static DATA: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
    static OK: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    let ok =
        OK.get_or_init(|| plotters::style::register_font(FONT, FontStyle::Normal, DATA).is_ok());
    ok.then_some(())
        .ok_or_else(|| err("the embedded font is invalid"))
}

/// Draws `p` into `area`: grid, axes, frame, series, legend. `joined`: lines as polylines
/// (SVG), else segment by segment (bitmap).
fn draw<DB: DrawingBackend>(
    p: &Plot,
    area: &DrawingArea<DB, Shift>,
    joined: bool,
) -> Result<(), String> {
    register_font()?;
    area.fill(&WHITE).map_err(err)?;
    let pts = || {
        p.series.iter().flat_map(|s| {
            s.points
                .iter()
                .zip(s.sigma.iter().chain(std::iter::repeat(&0.0)))
        })
    };
    let x = Axis::new(p.x_log, p.x_range, pts().map(|(q, _)| q.0), &p.x_ticks);
    let y = Axis::new(
        p.y_log,
        p.y_range,
        pts().flat_map(|(q, e)| [q.1 - e.abs(), q.1 + e.abs()]),
        &[],
    );
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .margin_right(26)
        .caption(&p.title, (FONT, 21))
        .x_label_area_size(52)
        .y_label_area_size(74)
        .build_cartesian_2d(x.clone(), y.clone())
        .map_err(err)?;
    let (fx, fy) = (|v: &f64| x.label(*v), |v: &f64| y.label(*v));
    chart
        .configure_mesh()
        .x_desc(&p.x_label)
        .y_desc(&p.y_label)
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .label_style((FONT, 16))
        .axis_desc_style((FONT, 17))
        .bold_line_style(RGBColor(222, 222, 222))
        .light_line_style(RGBColor(242, 242, 242))
        .draw()
        .map_err(err)?;
    let (bx, by) = ((x.lo, x.hi), (y.lo, y.hi));
    let frame = Rectangle::new(
        [(bx.0, by.0), (bx.1, by.1)],
        RGBColor(0, 0, 0).stroke_width(1),
    );
    chart.plotting_area().draw(&frame).map_err(err)?;
    // Visible points per quarter of the frame, for the legend's place.
    let mut crowd = [0usize; 4];
    for (i, s) in p.series.iter().enumerate() {
        let c = s.color.unwrap_or(PALETTE[i % PALETTE.len()]);
        let color = RGBColor((c >> 16) as u8, (c >> 8) as u8, c as u8);
        let (line, fill) = (color.stroke_width(2), color.filled());
        let placed: Vec<_> = s
            .points
            .iter()
            .map(|q| x.place(q.0).zip(y.place(q.1)))
            .collect();
        let visible: Vec<_> = placed
            .iter()
            .flatten()
            .filter(|&&q| clip((q, q), bx, by).is_some())
            .copied()
            .collect();
        for q in &visible {
            crowd[usize::from(q.0 > (bx.0 + bx.1) / 2.0)
                + 2 * usize::from(q.1 < (by.0 + by.1) / 2.0)] += 1;
        }
        // Whole polylines, without repeated pixels (plotters' bitmap rasteriser turns a
        // zero-length step of a wide line into a stroke to the image's corner); in a bitmap a
        // solid line goes segment by segment, as its joins spike where the line turns back.
        let px = |q: &(f64, f64)| chart.backend_coord(q);
        let mut paths = runs(&placed, bx, by);
        paths
            .iter_mut()
            .for_each(|r| r.dedup_by(|b, a| px(a) == px(b)));
        paths.retain(|r| r.len() > 1);
        if !joined && s.style == Style::Line {
            paths = paths
                .iter()
                .flat_map(|r| r.windows(2).map(<[_]>::to_vec))
                .collect();
        }
        let dot = |q| Circle::new(q, 4, fill);
        let anno = match s.style {
            Style::Line | Style::Dashed if visible.len() == 1 => {
                let dash = |q: &(f64, f64)| {
                    EmptyElement::at(*q) + PathElement::new([(-18, 0), (18, 0)], line)
                };
                chart.draw_series(visible.iter().map(dash))
            }
            Style::Line => chart.draw_series(paths.into_iter().map(|r| PathElement::new(r, line))),
            Style::Dashed => {
                let dashed = |r| DashedPathElement::new(r, 8, 5, line);
                chart.draw_series(paths.into_iter().map(dashed))
            }
            Style::Markers => chart.draw_series(visible.into_iter().map(dot)),
            Style::ErrorBars => {
                let bars = s.points.iter().zip(&s.sigma).filter_map(|(q, e)| {
                    let (at, lo, hi) = (
                        x.place(q.0)?,
                        y.place(q.1 - e.abs())?,
                        y.place(q.1 + e.abs())?,
                    );
                    let (a, b) = clip(((at, lo), (at, hi)), bx, by)?;
                    Some(PathElement::new([a, b], color.stroke_width(1)))
                });
                chart.draw_series(bars).map_err(err)?;
                chart.draw_series(visible.into_iter().map(dot))
            }
        }
        .map_err(err)?;
        if s.name.is_empty() {
            continue;
        }
        let anno = anno.label(&s.name);
        match s.style {
            Style::Line => anno.legend(move |(x, y)| PathElement::new([(x, y), (x + 24, y)], line)),
            Style::Dashed => {
                anno.legend(move |(x, y)| DashedPathElement::new([(x, y), (x + 24, y)], 8, 5, line))
            }
            _ => anno.legend(move |(x, y)| Circle::new((x + 12, y), 4, fill)),
        };
    }
    if p.series.iter().any(|s| !s.name.is_empty()) {
        use SeriesLabelPosition::*;
        let emptiest = (0..4).min_by_key(|&k| (crowd[k], k));
        chart
            .configure_series_labels()
            .position(
                vec![UpperLeft, UpperRight, LowerLeft, LowerRight]
                    .swap_remove(emptiest.unwrap_or(0)),
            )
            .margin(10)
            .legend_area_size(30)
            .label_font((FONT, 16))
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(170, 170, 170))
            .draw()
            .map_err(err)?;
    }
    Ok(())
}
