//! Dependency-free SVG line and marker plots for figures and run reports.
//!
//! Output is plain SVG 1.1 that browsers, Inkscape and LaTeX toolchains
//! (via conversion) read alike. Points that cannot be placed — non-finite,
//! or non-positive on a log axis — are skipped and break the line there, so
//! gaps in the data stay visible instead of being bridged.

use std::ffi::OsString;
use std::fmt::Write as _;
use std::fs;
use std::io::{self, Write as _};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    Line,
    Dashed,
    Markers,
    LineMarkers,
}

impl Style {
    fn has_line(self) -> bool {
        !matches!(self, Style::Markers)
    }

    fn has_markers(self) -> bool {
        matches!(self, Style::Markers | Style::LineMarkers)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend entry; series with an empty name are left out of the legend.
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub style: Style,
}

impl Series {
    pub fn new(name: impl Into<String>, points: Vec<(f64, f64)>, style: Style) -> Self {
        Self {
            name: name.into(),
            points,
            style,
        }
    }
}

/// A reference line across the whole plot, e.g. a literature value.
#[derive(Clone, Debug, PartialEq)]
pub struct RefLine {
    pub value: f64,
    pub label: String,
}

impl RefLine {
    pub fn new(value: f64, label: impl Into<String>) -> Self {
        Self {
            value,
            label: label.into(),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Plot {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_log: bool,
    pub y_log: bool,
    pub series: Vec<Series>,
    /// Axis limits; `None` fits the data (whole decades on log axes). Limits
    /// that are not finite, or not positive on a log axis, are ignored.
    pub x_range: Option<(f64, f64)>,
    pub y_range: Option<(f64, f64)>,
    /// Vertical lines at fixed x.
    pub v_lines: Vec<RefLine>,
    /// Horizontal lines at fixed y.
    pub h_lines: Vec<RefLine>,
    /// Light grid at the major ticks.
    pub grid: bool,
    /// Size in px.
    pub width: f64,
    pub height: f64,
}

impl Default for Plot {
    fn default() -> Self {
        Self {
            title: String::new(),
            x_label: String::new(),
            y_label: String::new(),
            x_log: false,
            y_log: false,
            series: Vec::new(),
            x_range: None,
            y_range: None,
            v_lines: Vec::new(),
            h_lines: Vec::new(),
            grid: true,
            width: 640.0,
            height: 480.0,
        }
    }
}

/// Okabe–Ito colours: distinguishable with the common colour-vision
/// deficiencies and in greyscale print.
const COLORS: [&str; 8] = [
    "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#F0E442",
];
const DASHES: [&str; 4] = ["7 4", "2 3", "9 3 2 3", "4 4"];
const MARKERS: [Marker; 5] = [
    Marker::Circle,
    Marker::Square,
    Marker::TriangleUp,
    Marker::Diamond,
    Marker::TriangleDown,
];

const FONT: f64 = 14.0;
const TICK_FONT: f64 = 12.0;
const TITLE_FONT: f64 = 16.0;
const MARKER_RADIUS: f64 = 3.5;
/// Rough advance of a character in units of the font size, for layout.
const CHAR_WIDTH: f64 = 0.6;

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
            ..Self::default()
        }
    }

    pub fn to_svg(&self) -> String {
        let xs = self
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.0));
        let ys = self
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.1));
        let x_axis = Axis::new(
            self.x_range,
            xs.chain(self.v_lines.iter().map(|l| l.value)),
            self.x_log,
        );
        let y_axis = Axis::new(
            self.y_range,
            ys.chain(self.h_lines.iter().map(|l| l.value)),
            self.y_log,
        );
        let x_ticks = ticks(&x_axis);
        let y_ticks = ticks(&y_axis);

        let legend: Vec<(usize, &Series)> = self
            .series
            .iter()
            .enumerate()
            .filter(|(_, s)| !s.name.is_empty())
            .collect();
        let legend_width = legend
            .iter()
            .map(|(_, s)| s.name.chars().count() as f64 * CHAR_WIDTH * TICK_FONT + 50.0)
            .fold(0.0, f64::max);
        let widest_y_label = y_ticks
            .iter()
            .filter(|t| t.major)
            .map(|t| t.label.width())
            .fold(0.0, f64::max);
        let left = 20.0 + widest_y_label + if self.y_label.is_empty() { 0.0 } else { 24.0 };
        let top = if self.title.is_empty() { 15.0 } else { 40.0 };
        // Room for half of the last x label, which is centred on the frame.
        let last_x_label = x_ticks
            .iter()
            .rev()
            .find(|t| t.major)
            .map_or(0.0, |t| 0.5 * t.label.width());
        let right = (last_x_label + 8.0).max(20.0 + legend_width);
        let bottom = if self.x_label.is_empty() { 30.0 } else { 55.0 };
        let area = Rect {
            x0: left,
            y0: top,
            x1: (self.width - right).max(left + 10.0),
            y1: (self.height - bottom).max(top + 10.0),
        };
        let map_x = |v: f64| x_axis.frac(v).map(|t| area.x0 + t * (area.x1 - area.x0));
        let map_y = |v: f64| y_axis.frac(v).map(|t| area.y1 - t * (area.y1 - area.y0));

        let mut svg = String::new();
        let (w, h) = (self.width, self.height);
        let _ = writeln!(svg, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
        let _ = writeln!(
            svg,
            r#"<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="Helvetica, Arial, sans-serif" font-size="{FONT}">"#
        );
        let _ = writeln!(svg, r#"<rect width="{w}" height="{h}" fill="white"/>"#);

        // Grid and ticks.
        let _ = writeln!(svg, r#"<g class="axes" stroke="black" stroke-width="1">"#);
        for t in &x_ticks {
            let Some(x) = map_x(t.value) else { continue };
            if self.grid && t.major {
                let _ = writeln!(
                    svg,
                    r##"<line x1="{x:.2}" y1="{:.2}" x2="{x:.2}" y2="{:.2}" stroke="#e0e0e0"/>"##,
                    area.y0, area.y1
                );
            }
            let len = if t.major { 6.0 } else { 3.0 };
            let _ = writeln!(
                svg,
                r#"<line x1="{x:.2}" y1="{:.2}" x2="{x:.2}" y2="{:.2}"/>"#,
                area.y1,
                area.y1 + len
            );
        }
        for t in &y_ticks {
            let Some(y) = map_y(t.value) else { continue };
            if self.grid && t.major {
                let _ = writeln!(
                    svg,
                    r##"<line x1="{:.2}" y1="{y:.2}" x2="{:.2}" y2="{y:.2}" stroke="#e0e0e0"/>"##,
                    area.x0, area.x1
                );
            }
            let len = if t.major { 6.0 } else { 3.0 };
            let _ = writeln!(
                svg,
                r#"<line x1="{:.2}" y1="{y:.2}" x2="{:.2}" y2="{y:.2}"/>"#,
                area.x0 - len,
                area.x0
            );
        }
        let _ = writeln!(
            svg,
            r#"<rect class="frame" x="{:.2}" y="{:.2}" width="{:.2}" height="{:.2}" fill="none"/>"#,
            area.x0,
            area.y0,
            area.x1 - area.x0,
            area.y1 - area.y0
        );
        let _ = writeln!(svg, "</g>");

        // Tick labels.
        let _ = writeln!(
            svg,
            r#"<g class="tick-labels" font-size="{TICK_FONT}" fill="black">"#
        );
        for t in x_ticks.iter().filter(|t| t.major) {
            if let Some(x) = map_x(t.value) {
                let _ = writeln!(
                    svg,
                    r#"<text x="{x:.2}" y="{:.2}" text-anchor="middle">{}</text>"#,
                    area.y1 + 8.0 + TICK_FONT,
                    t.label.svg()
                );
            }
        }
        for t in y_ticks.iter().filter(|t| t.major) {
            if let Some(y) = map_y(t.value) {
                let _ = writeln!(
                    svg,
                    r#"<text x="{:.2}" y="{:.2}" text-anchor="end">{}</text>"#,
                    area.x0 - 9.0,
                    y + 0.35 * TICK_FONT,
                    t.label.svg()
                );
            }
        }
        let _ = writeln!(svg, "</g>");

        // Title and axis labels.
        if !self.title.is_empty() {
            let _ = writeln!(
                svg,
                r#"<text class="title" x="{:.2}" y="{:.2}" text-anchor="middle" font-size="{TITLE_FONT}">{}</text>"#,
                0.5 * (area.x0 + area.x1),
                top - 14.0,
                escape(&self.title)
            );
        }
        if !self.x_label.is_empty() {
            let _ = writeln!(
                svg,
                r#"<text class="x-label" x="{:.2}" y="{:.2}" text-anchor="middle">{}</text>"#,
                0.5 * (area.x0 + area.x1),
                self.height - 14.0,
                escape(&self.x_label)
            );
        }
        if !self.y_label.is_empty() {
            let _ = writeln!(
                svg,
                r#"<text class="y-label" transform="translate({:.2},{:.2}) rotate(-90)" text-anchor="middle">{}</text>"#,
                16.0,
                0.5 * (area.y0 + area.y1),
                escape(&self.y_label)
            );
        }

        // Reference lines.
        let _ = writeln!(
            svg,
            r##"<g class="ref-lines" stroke="#555555" stroke-dasharray="3 3" font-size="{TICK_FONT}">"##
        );
        for l in &self.v_lines {
            let Some(x) = map_x(l.value).filter(|x| area.contains_x(*x)) else {
                continue;
            };
            let _ = writeln!(
                svg,
                r#"<line x1="{x:.2}" y1="{:.2}" x2="{x:.2}" y2="{:.2}"/>"#,
                area.y0, area.y1
            );
            if !l.label.is_empty() {
                let _ = writeln!(
                    svg,
                    r##"<text x="{:.2}" y="{:.2}" stroke="none" fill="#555555">{}</text>"##,
                    x + 3.0,
                    area.y0 + TICK_FONT + 2.0,
                    escape(&l.label)
                );
            }
        }
        for l in &self.h_lines {
            let Some(y) = map_y(l.value).filter(|y| area.contains_y(*y)) else {
                continue;
            };
            let _ = writeln!(
                svg,
                r#"<line x1="{:.2}" y1="{y:.2}" x2="{:.2}" y2="{y:.2}"/>"#,
                area.x0, area.x1
            );
            if !l.label.is_empty() {
                let _ = writeln!(
                    svg,
                    r##"<text x="{:.2}" y="{:.2}" text-anchor="end" stroke="none" fill="#555555">{}</text>"##,
                    area.x1 - 3.0,
                    y - 4.0,
                    escape(&l.label)
                );
            }
        }
        let _ = writeln!(svg, "</g>");

        // Data.
        for (i, s) in self.series.iter().enumerate() {
            let color = COLORS[i % COLORS.len()];
            let pts: Vec<Option<(f64, f64)>> = s
                .points
                .iter()
                .map(|&(x, y)| Some((map_x(x)?, map_y(y)?)))
                .map(|p| p.filter(|(x, y)| x.is_finite() && y.is_finite()))
                .collect();
            let _ = writeln!(svg, r#"<g class="series">"#);
            if s.style.has_line() {
                let dash = match s.style {
                    Style::Dashed => format!(r#" stroke-dasharray="{}""#, DASHES[i % DASHES.len()]),
                    _ => String::new(),
                };
                let _ = writeln!(
                    svg,
                    r#"<path class="series-line" d="{}" fill="none" stroke="{color}" stroke-width="1.5" stroke-linejoin="round"{dash}/>"#,
                    line_path(&pts, &area.grown(1.0))
                );
            }
            if s.style.has_markers() {
                let marker = MARKERS[i % MARKERS.len()];
                let mut d = String::new();
                let visible = area.grown(MARKER_RADIUS);
                for &(x, y) in pts.iter().flatten() {
                    if visible.contains_x(x) && visible.contains_y(y) {
                        marker.path(&mut d, x, y, MARKER_RADIUS);
                    }
                }
                let _ = writeln!(
                    svg,
                    r#"<path class="series-markers" d="{}" fill="{color}" stroke="{color}" stroke-width="0.8"/>"#,
                    d.trim_end()
                );
            }
            let _ = writeln!(svg, "</g>");
        }

        // Legend, right of the plot area.
        if !legend.is_empty() {
            let x = area.x1 + 15.0;
            let _ = writeln!(svg, r#"<g class="legend" font-size="{TICK_FONT}">"#);
            for (row, (i, s)) in legend.iter().enumerate() {
                let y = area.y0 + 10.0 + 20.0 * row as f64;
                let color = COLORS[i % COLORS.len()];
                if s.style.has_line() {
                    let dash = match s.style {
                        Style::Dashed => {
                            format!(r#" stroke-dasharray="{}""#, DASHES[i % DASHES.len()])
                        }
                        _ => String::new(),
                    };
                    let _ = writeln!(
                        svg,
                        r#"<line x1="{x:.2}" y1="{y:.2}" x2="{:.2}" y2="{y:.2}" stroke="{color}" stroke-width="1.5"{dash}/>"#,
                        x + 28.0
                    );
                }
                if s.style.has_markers() {
                    let mut d = String::new();
                    MARKERS[i % MARKERS.len()].path(&mut d, x + 14.0, y, MARKER_RADIUS);
                    let _ = writeln!(
                        svg,
                        r#"<path d="{}" fill="{color}" stroke="{color}" stroke-width="0.8"/>"#,
                        d.trim_end()
                    );
                }
                let _ = writeln!(
                    svg,
                    r#"<text x="{:.2}" y="{:.2}">{}</text>"#,
                    x + 36.0,
                    y + 0.35 * TICK_FONT,
                    escape(&s.name)
                );
            }
            let _ = writeln!(svg, "</g>");
        }
        svg.push_str("</svg>\n");
        svg
    }

    /// Writes the SVG atomically: a reader never sees a half-written figure,
    /// and a failed write leaves any previous file in place.
    pub fn save(&self, path: impl AsRef<Path>) -> io::Result<()> {
        write_atomic(path.as_ref(), self.to_svg().as_bytes())
    }
}

/// Writes to a temporary file next to `path`, then renames it over `path`;
/// rename within one directory is atomic on POSIX file systems.
fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path.file_name().ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} has no file name", path.display()),
        )
    })?;
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut tmp_name = OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(
        ".{}-{}.tmp",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let tmp = dir.join(tmp_name);
    let result = fs::File::create(&tmp)
        .and_then(|mut f| {
            f.write_all(bytes)?;
            f.sync_all()
        })
        .and_then(|()| fs::rename(&tmp, path));
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// Escapes text for XML content and attributes, dropping control characters
/// that XML 1.0 cannot represent at all.
fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\t' | '\n' | '\r' => out.push(' '),
            c if c.is_control() => {}
            c => out.push(c),
        }
    }
    out
}

#[derive(Clone, Copy, Debug)]
struct Rect {
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
}

impl Rect {
    fn grown(&self, by: f64) -> Rect {
        Rect {
            x0: self.x0 - by,
            y0: self.y0 - by,
            x1: self.x1 + by,
            y1: self.y1 + by,
        }
    }

    fn contains_x(&self, x: f64) -> bool {
        x >= self.x0 - 1e-9 && x <= self.x1 + 1e-9
    }

    fn contains_y(&self, y: f64) -> bool {
        y >= self.y0 - 1e-9 && y <= self.y1 + 1e-9
    }

    /// Liang–Barsky clipping of the segment a→b; `None` if it misses.
    fn clip(&self, a: (f64, f64), b: (f64, f64)) -> Option<((f64, f64), (f64, f64))> {
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for (p, q) in [
            (-dx, a.0 - self.x0),
            (dx, self.x1 - a.0),
            (-dy, a.1 - self.y0),
            (dy, self.y1 - a.1),
        ] {
            if p == 0.0 {
                if q < 0.0 {
                    return None;
                }
            } else {
                let r = q / p;
                if p < 0.0 {
                    t0 = t0.max(r);
                } else {
                    t1 = t1.min(r);
                }
            }
        }
        (t0 <= t1).then_some((
            (a.0 + t0 * dx, a.1 + t0 * dy),
            (a.0 + t1 * dx, a.1 + t1 * dy),
        ))
    }
}

/// Path data for a polyline clipped to `clip`, broken at missing points.
fn line_path(pts: &[Option<(f64, f64)>], clip: &Rect) -> String {
    let mut d = String::new();
    let mut pen: Option<(f64, f64)> = None;
    let near = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).abs() < 1e-6 && (a.1 - b.1).abs() < 1e-6;
    for w in pts.windows(2) {
        let (Some(a), Some(b)) = (w[0], w[1]) else {
            pen = None;
            continue;
        };
        let Some((ca, cb)) = clip.clip(a, b) else {
            pen = None;
            continue;
        };
        if !pen.is_some_and(|p| near(p, ca)) {
            let _ = write!(d, "M{:.2} {:.2} ", ca.0, ca.1);
        }
        let _ = write!(d, "L{:.2} {:.2} ", cb.0, cb.1);
        pen = Some(cb);
    }
    d.truncate(d.trim_end().len());
    d
}

#[derive(Clone, Copy, Debug)]
enum Marker {
    Circle,
    Square,
    TriangleUp,
    Diamond,
    TriangleDown,
}

impl Marker {
    fn path(self, d: &mut String, x: f64, y: f64, r: f64) {
        let _ = match self {
            Marker::Circle => write!(
                d,
                "M{:.2} {y:.2} a{r} {r} 0 1 0 {} 0 a{r} {r} 0 1 0 {} 0 Z ",
                x - r,
                2.0 * r,
                -2.0 * r
            ),
            Marker::Square => {
                let s = 0.9 * r;
                write!(
                    d,
                    "M{:.2} {:.2} h{} v{} h{} Z ",
                    x - s,
                    y - s,
                    2.0 * s,
                    2.0 * s,
                    -2.0 * s
                )
            }
            Marker::Diamond => write!(
                d,
                "M{x:.2} {:.2} L{:.2} {y:.2} L{x:.2} {:.2} L{:.2} {y:.2} Z ",
                y - 1.2 * r,
                x + r,
                y + 1.2 * r,
                x - r
            ),
            Marker::TriangleUp | Marker::TriangleDown => {
                let sgn = if matches!(self, Marker::TriangleUp) {
                    1.0
                } else {
                    -1.0
                };
                let h = 1.2 * r;
                write!(
                    d,
                    "M{x:.2} {:.2} L{:.2} {:.2} L{:.2} {:.2} Z ",
                    y - sgn * h,
                    x + h * 0.866,
                    y + sgn * 0.5 * h,
                    x - h * 0.866,
                    y + sgn * 0.5 * h
                )
            }
        };
    }
}

/// Axis limits and the value → [0, 1] map.
#[derive(Clone, Copy, Debug)]
struct Axis {
    lo: f64,
    hi: f64,
    log: bool,
}

impl Axis {
    fn new(range: Option<(f64, f64)>, values: impl Iterator<Item = f64>, log: bool) -> Axis {
        let usable = |v: f64| v.is_finite() && (!log || v > 0.0);
        if let Some((a, b)) = range.filter(|&(a, b)| usable(a) && usable(b) && a != b) {
            return Axis {
                lo: a.min(b),
                hi: a.max(b),
                log,
            };
        }
        let (min, max) = values
            .filter(|&v| usable(v))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
        if min > max {
            let (lo, hi) = if log { (1.0, 10.0) } else { (0.0, 1.0) };
            return Axis { lo, hi, log };
        }
        if log {
            let lo = min.log10().floor();
            let hi = max.log10().ceil().max(lo + 1.0);
            // Keep the decades representable.
            let lo = lo.max(-307.0);
            let hi = hi.min(308.0).max(lo + 1.0);
            Axis {
                lo: 10f64.powf(lo),
                hi: 10f64.powf(hi),
                log,
            }
        } else {
            let (min, max) = if min == max {
                let pad = if min == 0.0 { 1.0 } else { 0.1 * min.abs() };
                (min - pad, max + pad)
            } else {
                (min, max)
            };
            let step = nice_step((max - min) / 6.0);
            let lo = multiple((min / step).floor(), step);
            let hi = multiple((max / step).ceil(), step);
            if lo.is_finite() && hi.is_finite() && lo < hi {
                Axis { lo, hi, log }
            } else {
                Axis {
                    lo: min,
                    hi: max,
                    log,
                }
            }
        }
    }

    fn frac(&self, v: f64) -> Option<f64> {
        let t = if self.log {
            if v.is_nan() || v <= 0.0 {
                return None;
            }
            (v.log10() - self.lo.log10()) / (self.hi.log10() - self.lo.log10())
        } else {
            (v - self.lo) / (self.hi - self.lo)
        };
        t.is_finite().then_some(t)
    }
}

/// k·step, exact for decimal steps below 1 (6 × 0.1 is not 0.6 in binary).
fn multiple(k: f64, step: f64) -> f64 {
    if step < 1.0 {
        k / (1.0 / step).round()
    } else {
        k * step
    }
}

/// Smallest of 1, 2, 5 × 10^k not below `raw`.
fn nice_step(raw: f64) -> f64 {
    if !(raw > 0.0 && raw.is_finite()) {
        return 1.0;
    }
    let mag = 10f64.powf(raw.log10().floor());
    let norm = raw / mag;
    let m = if norm <= 1.0 {
        1.0
    } else if norm <= 2.0 {
        2.0
    } else if norm <= 5.0 {
        5.0
    } else {
        10.0
    };
    m * mag
}

#[derive(Clone, Debug, PartialEq)]
enum Label {
    None,
    Text(String),
    /// 10^k.
    Decade(i32),
}

impl Label {
    fn svg(&self) -> String {
        match self {
            Label::None => String::new(),
            Label::Text(s) => escape(s),
            Label::Decade(k) => format!(
                r#"10<tspan dy="-0.5em" font-size="75%">{}</tspan>"#,
                minus(&k.to_string())
            ),
        }
    }

    fn width(&self) -> f64 {
        let chars = match self {
            Label::None => 0.0,
            Label::Text(s) => s.chars().count() as f64,
            Label::Decade(k) => 2.0 + 0.75 * k.to_string().len() as f64,
        };
        chars * CHAR_WIDTH * TICK_FONT
    }
}

/// Typographic minus sign for tick labels.
fn minus(s: &str) -> String {
    s.replace('-', "\u{2212}")
}

#[derive(Clone, Debug, PartialEq)]
struct Tick {
    value: f64,
    major: bool,
    label: Label,
}

fn ticks(axis: &Axis) -> Vec<Tick> {
    if axis.log {
        log_ticks(axis.lo, axis.hi)
    } else {
        linear_ticks(axis.lo, axis.hi)
    }
}

/// Multiples of a 1-2-5 step, about six intervals across the range.
fn linear_ticks(lo: f64, hi: f64) -> Vec<Tick> {
    let step = nice_step((hi - lo) / 6.0);
    let first = (lo / step - 1e-9).ceil() as i64;
    let last = (hi / step + 1e-9).floor() as i64;
    if last < first || last - first > 100 {
        return Vec::new();
    }
    let biggest = lo.abs().max(hi.abs());
    (first..=last)
        .map(|k| {
            let value = multiple(k as f64, step);
            Tick {
                value,
                major: true,
                label: Label::Text(format_tick(value, step, biggest)),
            }
        })
        .collect()
}

/// Label with as many decimals as the step needs; scientific notation for
/// very large or very small numbers.
fn format_tick(value: f64, step: f64, biggest: f64) -> String {
    if value.abs() < 1e-9 * step {
        return "0".to_string();
    }
    let step_exp = step.log10().floor() as i32;
    let s = if (1e-3..1e6).contains(&biggest) {
        format!("{:.*}", (-step_exp).max(0) as usize, value)
    } else {
        // Same mantissa digits on every label of the axis.
        let exp = biggest.log10().floor() as i32;
        format!("{:.*e}", (exp - step_exp).max(0) as usize, value)
    };
    minus(&s)
}

/// Decades labelled 10^k, thinned to at most about ten labels, with minor
/// ticks at 2…9 when there are few decades. Ranges that hold fewer than two
/// decades get labelled 1-2-5 mantissas instead.
fn log_ticks(lo: f64, hi: f64) -> Vec<Tick> {
    let (a, b) = (lo.log10(), hi.log10());
    let first = (a - 1e-9).ceil() as i32;
    let last = (b + 1e-9).floor() as i32;
    let inside = |v: f64| {
        let l = v.log10();
        l >= a - 1e-9 && l <= b + 1e-9
    };
    let decades = (last - first + 1).max(0);
    let mut ticks = Vec::new();
    if decades >= 2 {
        let stride = ((decades + 9) / 10).max(1);
        for k in first..=last {
            let labelled = (k - first) % stride == 0;
            ticks.push(Tick {
                value: 10f64.powi(k),
                major: labelled,
                label: if labelled {
                    Label::Decade(k)
                } else {
                    Label::None
                },
            });
        }
        if stride == 1 && decades <= 7 {
            for k in first - 1..=last {
                for m in 2..=9 {
                    let v = m as f64 * 10f64.powi(k);
                    if inside(v) {
                        ticks.push(Tick {
                            value: v,
                            major: false,
                            label: Label::None,
                        });
                    }
                }
            }
        }
        return ticks;
    }
    for k in (a.floor() as i32)..=(b.ceil() as i32) {
        for m in 1..=9 {
            let v = m as f64 * 10f64.powi(k);
            if !inside(v) {
                continue;
            }
            let major = matches!(m, 1 | 2 | 5);
            ticks.push(Tick {
                value: v,
                major,
                label: if major {
                    Label::Text(format_tick(v, 10f64.powi(k), v))
                } else {
                    Label::None
                },
            });
        }
    }
    if ticks.iter().filter(|t| t.major).count() < 2 {
        // Less than a factor of ~2.5: linear ticks read better.
        return linear_ticks(lo, hi)
            .into_iter()
            .filter(|t| t.value > 0.0)
            .collect();
    }
    ticks
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Minimal XML check: balanced, properly nested tags under one root, and
    /// no stray `<` or unescaped `&` in text.
    fn check_well_formed(svg: &str) -> Result<(), String> {
        let mut stack: Vec<&str> = Vec::new();
        let mut roots = 0;
        let mut rest = svg;
        while let Some(start) = rest.find('<') {
            check_text(&rest[..start])?;
            let after = &rest[start..];
            if let Some(body) = after.strip_prefix("<?") {
                let end = body.find("?>").ok_or("unterminated <?")?;
                rest = &body[end + 2..];
                continue;
            }
            if let Some(body) = after.strip_prefix("<!--") {
                let end = body.find("-->").ok_or("unterminated comment")?;
                rest = &body[end + 3..];
                continue;
            }
            let end = tag_end(after).ok_or("unterminated tag")?;
            let tag = &after[1..end];
            rest = &after[end + 1..];
            if let Some(name) = tag.strip_prefix('/') {
                let open = stack.pop().ok_or(format!("unexpected </{name}>"))?;
                if open != name.trim() {
                    return Err(format!("<{open}> closed by </{name}>"));
                }
                continue;
            }
            let name = tag
                .split(|c: char| c.is_whitespace() || c == '/')
                .next()
                .unwrap_or("");
            if name.is_empty() || tag.contains('<') {
                return Err(format!("bad tag <{tag}>"));
            }
            for (i, _) in tag.match_indices('&') {
                check_entity(&tag[i..])?;
            }
            if stack.is_empty() {
                roots += 1;
            }
            if !tag.ends_with('/') {
                stack.push(name);
            }
        }
        check_text(rest)?;
        match (stack.is_empty(), roots) {
            (true, 1) => Ok(()),
            (false, _) => Err(format!("unclosed {stack:?}")),
            (_, n) => Err(format!("{n} root elements")),
        }
    }

    /// End of a tag, skipping `>` inside quoted attribute values.
    fn tag_end(s: &str) -> Option<usize> {
        let mut quote = None;
        for (i, c) in s.char_indices() {
            match (quote, c) {
                (None, '"' | '\'') => quote = Some(c),
                (Some(q), c) if c == q => quote = None,
                (None, '>') => return Some(i),
                _ => {}
            }
        }
        None
    }

    fn check_text(text: &str) -> Result<(), String> {
        for (i, _) in text.match_indices('&') {
            check_entity(&text[i..])?;
        }
        Ok(())
    }

    fn check_entity(s: &str) -> Result<(), String> {
        let ok = ["&amp;", "&lt;", "&gt;", "&quot;", "&apos;"]
            .iter()
            .any(|e| s.starts_with(e));
        if ok {
            Ok(())
        } else {
            Err(format!("bare & in {:?}", &s[..s.len().min(12)]))
        }
    }

    fn sample() -> Plot {
        let xs: Vec<f64> = (0..=40)
            .map(|i| 10f64.powf(2.0 + i as f64 / 10.0))
            .collect();
        let curve = |d: f64| {
            xs.iter()
                .map(|&x| (x, 0.15 + 0.4 / (1.0 + (d / x))))
                .collect()
        };
        Plot {
            x_log: true,
            series: vec![
                Series::new("line", curve(1e3), Style::Line),
                Series::new("dashed", curve(1e4), Style::Dashed),
                Series::new("markers", curve(1e5), Style::Markers),
                Series::new("both", curve(3e3), Style::LineMarkers),
            ],
            v_lines: vec![RefLine::new(16667.0, "p_m")],
            h_lines: vec![RefLine::new(0.58, "φ₂")],
            ..Plot::new("Compression <test> & check", "P [Pa]", "φ")
        }
    }

    #[test]
    fn svg_is_well_formed() {
        let svg = sample().to_svg();
        check_well_formed(&svg).unwrap();
        assert!(svg.contains("Compression &lt;test&gt; &amp; check"));
        // The checker itself must catch the obvious defects.
        assert!(check_well_formed("<svg><g></svg>").is_err());
        assert!(check_well_formed("<svg>a & b</svg>").is_err());
        assert!(check_well_formed("<svg/><svg/>").is_err());
    }

    #[test]
    fn one_path_per_series() {
        let svg = sample().to_svg();
        assert_eq!(svg.matches(r#"<g class="series">"#).count(), 4);
        // Line, Dashed and LineMarkers have a line; Markers and LineMarkers markers.
        assert_eq!(svg.matches(r#"class="series-line""#).count(), 3);
        assert_eq!(svg.matches(r#"class="series-markers""#).count(), 2);
        assert_eq!(svg.matches("stroke-dasharray=\"7 4\"").count(), 0);
        assert!(svg.contains(r#"stroke-dasharray="2 3""#));
        for c in &COLORS[..4] {
            assert!(svg.contains(&format!(r#"stroke="{c}""#)), "{c}");
        }
        // Legend entry for each named series.
        for name in ["line", "dashed", "markers", "both"] {
            assert!(svg.contains(&format!(">{name}</text>")), "{name}");
        }
    }

    #[test]
    fn log_ticks_at_each_decade() {
        let svg = sample().to_svg();
        for k in 2..=6 {
            let label = format!(r#"10<tspan dy="-0.5em" font-size="75%">{k}</tspan>"#);
            assert_eq!(svg.matches(&label).count(), 1, "decade {k}");
        }
        assert!(!svg.contains(r#"font-size="75%">1<"#));
        assert!(!svg.contains(r#"font-size="75%">7<"#));

        let t = log_ticks(1e-3, 1e2);
        let decades: Vec<i32> = t
            .iter()
            .filter_map(|t| match t.label {
                Label::Decade(k) => Some(k),
                _ => None,
            })
            .collect();
        assert_eq!(decades, [-3, -2, -1, 0, 1, 2]);
        assert_eq!(t.iter().filter(|t| !t.major).count(), 5 * 8);
        assert!(Label::Decade(-3).svg().contains("\u{2212}3"));
        // Many decades: thinned labels, never more than about ten.
        let wide = log_ticks(1e-100, 1e100);
        let labelled = wide.iter().filter(|t| t.major).count();
        assert!((5..=11).contains(&labelled), "{labelled}");
        // Less than two decades: labelled mantissas.
        let narrow = log_ticks(2.0, 60.0);
        let labels: Vec<String> = narrow
            .iter()
            .filter_map(|t| match &t.label {
                Label::Text(s) => Some(s.clone()),
                _ => None,
            })
            .collect();
        assert_eq!(labels, ["2", "5", "10", "20", "50"]);
        assert!(log_ticks(3.0, 4.0).len() >= 2);
    }

    #[test]
    fn linear_ticks_use_1_2_5_steps() {
        assert_eq!(nice_step(0.13), 0.2);
        assert_eq!(nice_step(3.0), 5.0);
        assert_eq!(nice_step(7.0), 10.0);
        assert_eq!(nice_step(1.0), 1.0);
        let labels: Vec<String> = linear_ticks(0.1, 0.6)
            .into_iter()
            .map(|t| match t.label {
                Label::Text(s) => s,
                _ => unreachable!(),
            })
            .collect();
        assert_eq!(labels, ["0.1", "0.2", "0.3", "0.4", "0.5", "0.6"]);
        let labels: Vec<String> = linear_ticks(-1e7, 1e7)
            .into_iter()
            .map(|t| match t.label {
                Label::Text(s) => s,
                _ => unreachable!(),
            })
            .collect();
        assert_eq!(labels[0], "\u{2212}1.0e7");
        assert!(labels.contains(&"0".to_string()));
        let auto = Axis::new(None, [0.13, 0.57].into_iter(), false);
        assert_eq!((auto.lo, auto.hi), (0.1, 0.6));
    }

    #[test]
    fn unplaceable_points_are_skipped() {
        let plot = Plot {
            x_log: true,
            y_log: true,
            series: vec![Series::new(
                "gappy",
                vec![
                    (1.0, 1.0),
                    (10.0, 10.0),
                    (f64::NAN, 3.0),
                    (100.0, 100.0),
                    (1000.0, 1000.0),
                    (-1.0, 5.0),
                    (0.0, 5.0),
                    (5.0, f64::INFINITY),
                    (f64::NEG_INFINITY, 1.0),
                    (1e4, 1e4),
                    (1e5, 1e300),
                ],
                Style::LineMarkers,
            )],
            y_range: Some((1.0, 1e5)),
            ..Plot::default()
        };
        let svg = plot.to_svg();
        check_well_formed(&svg).unwrap();
        for bad in ["NaN", "inf", "e+"] {
            assert!(!svg.contains(bad), "{bad}");
        }
        let d = svg
            .split(r#"class="series-line" d=""#)
            .nth(1)
            .and_then(|s| s.split('"').next())
            .unwrap();
        // Three runs: 1–10, 100–1000, and 1e4 towards the clipped 1e300.
        assert_eq!(d.matches('M').count(), 3, "{d}");
        // Markers only for points inside the plot area.
        let m = svg
            .split(r#"class="series-markers" d=""#)
            .nth(1)
            .and_then(|s| s.split('"').next())
            .unwrap();
        assert_eq!(m.matches('M').count(), 5, "{m}");
    }

    #[test]
    fn empty_plot_still_has_axes() {
        for (x_log, y_log) in [(false, false), (true, true)] {
            let plot = Plot {
                x_log,
                y_log,
                ..Plot::new("", "x", "y")
            };
            let svg = plot.to_svg();
            check_well_formed(&svg).unwrap();
            assert!(svg.contains(r#"class="frame""#));
            assert!(svg.matches("<text").count() >= 4, "{svg}");
            assert!(!svg.contains(r#"class="legend""#));
        }
        // A single point or a degenerate range still renders.
        let one = Plot {
            series: vec![Series::new("", vec![(2.0, 2.0)], Style::Markers)],
            x_range: Some((3.0, 3.0)),
            ..Plot::default()
        };
        check_well_formed(&one.to_svg()).unwrap();
    }

    #[test]
    fn escaping_covers_markup_and_control_characters() {
        assert_eq!(
            escape("a<b>&\"c\"'d'\u{1}\n"),
            "a&lt;b&gt;&amp;&quot;c&quot;&apos;d&apos; "
        );
    }

    #[test]
    fn save_replaces_file_atomically() {
        let dir = std::env::temp_dir().join(format!("dustdem-plot-test-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let path = dir.join("fig.svg");
        fs::write(&path, "old").unwrap();
        let plot = sample();
        plot.save(&path).unwrap();
        assert_eq!(fs::read_to_string(&path).unwrap(), plot.to_svg());
        let leftovers: Vec<_> = fs::read_dir(&dir).unwrap().collect();
        assert_eq!(leftovers.len(), 1);
        assert!(plot.save(dir.join("missing").join("fig.svg")).is_err());
        assert!(plot.save(&dir).is_err());
        assert_eq!(fs::read_dir(&dir).unwrap().count(), 1);
        fs::remove_dir_all(&dir).unwrap();
    }
}
