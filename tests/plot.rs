//! The figures of `output::plot`: SVG that an XML parser reads, with the title, axis labels, tick
//! labels, legend and every series; PNG that decodes at the panels' size with the series'
//! colours in it; the compression curve of `dustdem run`.

use dustdem::config::ExperimentKind;
use dustdem::output::plot::{panels_png, panels_svg, Plot, Series, Style, PALETTE};
use quick_xml::events::Event;
use quick_xml::Reader;

fn sample() -> Plot {
    let xs: Vec<f64> = (0..=40)
        .map(|i| 10f64.powf(2.0 + i as f64 / 10.0))
        .collect();
    let curve = |d: f64| {
        xs.iter()
            .map(|&x| (x, 0.15 + 0.4 / (1.0 + d / x)))
            .collect()
    };
    let mut errors = Series::new("error bars", curve(3e3), Style::ErrorBars);
    errors.points = errors.points.into_iter().step_by(5).collect();
    errors.sigma = vec![0.02; errors.points.len()];
    let mut plot = Plot::new("Compression <test> & check", "P [Pa]", "filling factor φ");
    plot.x_log = true;
    plot.series = vec![
        Series::new("line", curve(1e3), Style::Line),
        Series::new("dashed", curve(1e4), Style::Dashed),
        Series::new("markers", curve(1e5), Style::Markers),
        errors,
    ];
    plot
}

/// What an SVG holds: its text (unescaped), and per element name the `stroke` or `fill`
/// colour of each element. Panics unless the document is well formed.
struct Svg {
    texts: Vec<String>,
    shapes: Vec<(String, String)>,
}

impl Svg {
    fn parse(svg: &str) -> Svg {
        let mut reader = Reader::from_str(svg);
        reader.trim_text(true);
        let (mut texts, mut shapes, mut depth, mut buf) = (Vec::new(), Vec::new(), 0, Vec::new());
        loop {
            let event = reader.read_event(&mut buf).expect("well-formed SVG");
            match &event {
                Event::Start(e) | Event::Empty(e) => {
                    let name = String::from_utf8(e.name().to_vec()).unwrap();
                    let colour = e
                        .attributes()
                        .map(|a| a.unwrap())
                        .filter(|a| a.key == b"stroke" || a.key == b"fill")
                        .map(|a| String::from_utf8(a.value.to_vec()).unwrap())
                        .find(|v| v != "none")
                        .unwrap_or_default();
                    shapes.push((name, colour));
                    depth += matches!(event, Event::Start(_)) as i32;
                }
                Event::End(_) => depth -= 1,
                Event::Text(t) => texts.push(t.unescape_and_decode(&reader).unwrap()),
                Event::Eof => break,
                _ => {}
            }
            buf.clear();
        }
        assert_eq!(depth, 0, "every element closed");
        assert_eq!(shapes.first().map(|s| s.0.as_str()), Some("svg"));
        Svg { texts, shapes }
    }

    fn count(&self, name: &str, colour: &str) -> usize {
        self.shapes
            .iter()
            .filter(|s| s.0 == name && s.1 == colour)
            .count()
    }

    fn has_text(&self, text: &str) -> usize {
        self.texts.iter().filter(|t| t.as_str() == text).count()
    }
}

fn hex(c: u32) -> String {
    format!("#{c:06X}")
}

#[test]
fn svg_has_title_labels_decades_legend_and_every_series() {
    let svg = Svg::parse(&sample().to_svg().unwrap());
    for text in ["Compression <test> & check", "P [Pa]", "filling factor φ"] {
        assert_eq!(svg.has_text(text), 1, "{text}");
    }
    for name in ["line", "dashed", "markers", "error bars"] {
        assert_eq!(svg.has_text(name), 1, "legend entry {name}");
    }
    // Decades 10² … 10⁶ labelled once each, nothing beyond; y ticks in 0.1 steps.
    for decade in ["10²", "10³", "10⁴", "10⁵", "10⁶"] {
        assert_eq!(svg.has_text(decade), 1, "{decade}");
    }
    assert_eq!(svg.has_text("10¹") + svg.has_text("10⁷"), 0);
    for tick in ["0.1", "0.2", "0.3", "0.4", "0.5", "0.6"] {
        assert_eq!(svg.has_text(tick), 1, "{tick}");
    }
    let [line, dashed, markers, errors] = [0, 1, 2, 3].map(|k| hex(PALETTE[k]));
    // One unbroken polyline and its legend sample; the dashed line in many pieces.
    assert_eq!(svg.count("polyline", &line), 2);
    assert!(svg.count("polyline", &dashed) > 20);
    // A marker per point plus one in the legend; error bars with their markers.
    assert_eq!(svg.count("circle", &markers), 41 + 1);
    assert_eq!(svg.count("circle", &errors), 9 + 1);
    assert_eq!(svg.count("polyline", &errors), 9);
}

#[test]
fn ticks_thin_many_decades_and_write_signs_and_large_numbers() {
    let texts = |x_range: (f64, f64), y_range: (f64, f64)| {
        let mut plot = Plot::new("", "", "");
        (plot.x_log, plot.x_range, plot.y_range) = (true, Some(x_range), Some(y_range));
        Svg::parse(&plot.to_svg().unwrap()).texts
    };
    let wide = texts((1e-100, 1e100), (-1e7, 1e7));
    let decades = wide.iter().filter(|t| t.starts_with("10")).count();
    assert!((5..=11).contains(&decades), "{wide:?}");
    assert!(wide.contains(&"10⁻¹⁰⁰".to_string()), "{wide:?}");
    for tick in ["−1.0e7", "0", "5.0e6"] {
        assert!(wide.contains(&tick.to_string()), "{tick}: {wide:?}");
    }
    let few = texts((1e-3, 1e2), (0.1, 0.6));
    for tick in ["10⁻³", "10⁻¹", "10⁰", "10²", "0.1", "0.6"] {
        assert!(few.contains(&tick.to_string()), "{tick}: {few:?}");
    }
    // Less than a decade is widened to whole decades.
    let narrow = texts((2e3, 3e3), (0.0, 1.0));
    assert!(narrow.contains(&"10³".to_string()) && narrow.contains(&"10⁴".to_string()));
}

#[test]
fn unplaceable_points_break_the_line_and_are_left_out() {
    let mut plot = Plot::new("", "x", "y");
    (plot.x_log, plot.y_log, plot.y_range) = (true, true, Some((1.0, 1e5)));
    let nan = f64::NAN;
    let points = vec![
        (1.0, 1.0),
        (10.0, 10.0),
        (nan, 3.0),
        (100.0, 100.0),
        (1000.0, 1000.0),
        (-1.0, 5.0),
        (0.0, 5.0),
        (5.0, f64::INFINITY),
        (f64::NEG_INFINITY, 1.0),
        (1e4, 1e4),
        (1e5, 1e300),
    ];
    plot.series = vec![Series::new("gappy", points.clone(), Style::Line)];
    let text = plot.to_svg().unwrap();
    for bad in ["NaN", "inf"] {
        assert!(!text.contains(bad), "{bad}");
    }
    // Three runs (1–10, 100–1000, 1e4 towards the clipped 1e300) and the legend sample.
    assert_eq!(Svg::parse(&text).count("polyline", &hex(PALETTE[0])), 3 + 1);
    // Markers only where a point lies inside the frame: 1, 10, 100, 1000, 1e4.
    plot.series = vec![Series::new("gappy", points, Style::Markers)];
    assert_eq!(
        Svg::parse(&plot.to_svg().unwrap()).count("circle", &hex(PALETTE[0])),
        5 + 1
    );
}

#[test]
fn empty_and_degenerate_plots_still_have_axes() {
    for log in [false, true] {
        let mut plot = Plot::new("", "x label", "y label");
        (plot.x_log, plot.y_log) = (log, log);
        let svg = Svg::parse(&plot.to_svg().unwrap());
        assert_eq!(svg.has_text("x label") + svg.has_text("y label"), 2);
        assert!(svg.texts.len() >= 6, "{:?}", svg.texts);
        assert!(!svg.texts.iter().any(|t| t.contains("NaN")));
    }
    let mut one = Plot::new("one point", "x", "y");
    one.series = vec![Series::new("", vec![(2.0, 2.0)], Style::Line)];
    one.x_range = Some((3.0, 3.0));
    let svg = Svg::parse(&one.to_svg().unwrap());
    // A single point of a line is drawn as a short dash.
    assert_eq!(svg.count("polyline", &hex(PALETTE[0])), 1);
}

#[test]
fn panels_png_decodes_at_the_panels_size_with_the_series_colours() {
    let mut a = sample();
    (a.width, a.height) = (560, 420);
    let mut b = Plot::new("categories", "", "v [m/s]");
    b.x_range = Some((0.5, 2.5));
    b.x_ticks = vec![(1.0, "measured".into()), (2.0, "model".into())];
    b.series = vec![Series::new("", vec![(2.0, 1.2)], Style::Line).color(0xD55E00)];
    (b.width, b.height) = (300, 400);
    let bytes = panels_png(&[a, b]).unwrap();
    let mut reader = png::Decoder::new(bytes.as_slice()).read_info().unwrap();
    assert_eq!((reader.info().width, reader.info().height), (860, 420));
    let mut rgb = vec![0; reader.output_buffer_size()];
    reader.next_frame(&mut rgb).unwrap();
    let count = |c: u32, x0: usize, x1: usize| {
        let want = [(c >> 16) as u8, (c >> 8) as u8, c as u8];
        rgb.chunks(3)
            .enumerate()
            .filter(|(k, px)| (x0..x1).contains(&(k % 860)) && *px == want)
            .count()
    };
    assert!(
        count(PALETTE[0], 0, 560) > 500,
        "{}",
        count(PALETTE[0], 0, 560)
    );
    assert!(
        count(0xD55E00, 560, 860) >= 2 * 24,
        "the dash of the second panel"
    );
}

#[test]
fn png_lines_that_repeat_points_and_turn_back_stay_inside_the_frame() {
    // Noisy pressure: the curve steps back and forth and repeats points. plotters' bitmap
    // rasteriser draws a zero-length step of a wide line to the image's corner and spikes at
    // sharp turns; neither may show outside the frame.
    let points: Vec<(f64, f64)> = (0..400)
        .map(|i| {
            let p = 10f64.powf(2.0 + (i / 2) as f64 / 100.0) * if i % 4 < 2 { 1.0 } else { 30.0 };
            (p, 0.1 + 0.001 * (i / 2) as f64)
        })
        .collect();
    let plot = dustdem::job::curve_plot(ExperimentKind::Omni, &points);
    let bytes = panels_png(&[plot]).unwrap();
    let mut reader = png::Decoder::new(bytes.as_slice()).read_info().unwrap();
    let mut rgb = vec![0; reader.output_buffer_size()];
    reader.next_frame(&mut rgb).unwrap();
    // The raw rows (light grey) and the envelope (blue): both drawn, neither outside.
    for (want, what) in [
        ([0xC8, 0xC8, 0xC8], "raw rows"),
        ([0x00, 0x72, 0xB2], "envelope"),
    ] {
        let columns: Vec<usize> = rgb
            .chunks(3)
            .enumerate()
            .filter(|(_, px)| *px == want)
            .map(|(k, _)| k % 640)
            .collect();
        assert!(
            columns.len() > 500,
            "the {what} are drawn: {}",
            columns.len()
        );
        // The frame spans about x = 86..614 (y-label area 74 px and margins of 12 and 26 px).
        let outside = columns.iter().filter(|&&x| !(80..620).contains(&x)).count();
        assert_eq!(outside, 0, "pixels of the {what} outside the frame");
    }
}

#[test]
fn compression_curve_shows_simulation_and_reference_over_seven_decades() {
    let points: Vec<(f64, f64)> = (0..200)
        .map(|i| (10f64.powf(1.5 + i as f64 / 40.0), 0.12 + 0.0018 * i as f64))
        .collect();
    let plot = dustdem::job::curve_plot(ExperimentKind::Omni, &points);
    let svg = Svg::parse(&plot.to_svg().unwrap());
    for text in [
        "Compressive strength",
        "pressure P [Pa]",
        "filling factor φ",
        "every row (top wall)",
        "simulation (first passage, median of 9 rows)",
        "Güttler et al. 2009 (Eq. 13)",
    ] {
        assert_eq!(svg.has_text(text), 1, "{text}");
    }
    for k in ["¹", "²", "³", "⁴", "⁵", "⁶", "⁷"] {
        assert_eq!(svg.has_text(&format!("10{k}")), 1, "10{k}");
    }
    assert_eq!(svg.count("polyline", &hex(PALETTE[0])), 2);
    let dir = std::env::temp_dir().join(format!("dustdem-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("curve.svg");
    std::fs::write(&path, "old").unwrap();
    plot.save(&path).unwrap();
    assert_eq!(
        std::fs::read_to_string(&path).unwrap(),
        plot.to_svg().unwrap()
    );
    assert_eq!(
        std::fs::read_dir(&dir).unwrap().count(),
        1,
        "no temporary left"
    );
    assert!(plot.save(dir.join("missing").join("curve.svg")).is_err());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_curve_draws_first_passage_of_the_median_not_single_spikes() {
    // 100 rows at 100 Pa while φ rises from 0.15 to 0.25, one row spiking to 10⁶ Pa at
    // φ ≈ 0.2 (a jammed contact chain), then a steady rise to 10⁵ Pa by φ = 0.45.
    let mut rows: Vec<(f64, f64)> = (0..100)
        .map(|i| (if i == 50 { 1e6 } else { 100.0 }, 0.15 + 0.001 * i as f64))
        .collect();
    rows.extend((1..=100).map(|i| {
        (
            100.0 * 10f64.powf(3.0 * i as f64 / 100.0),
            0.25 + 0.002 * i as f64,
        )
    }));
    let plot = dustdem::job::curve_plot(ExperimentKind::Omni, &rows);
    let raw = &plot.series[0];
    let drawn = &plot.series[1];
    assert!(
        raw.points.iter().any(|&(p, _)| p == 1e6),
        "the spike stays visible behind"
    );
    // The median of 9 rows never sees a single spike: 10⁶ Pa is not reached before φ = 0.45.
    assert!(
        drawn
            .points
            .iter()
            .all(|&(p, phi)| p < 1.01e5 || phi > 0.44),
        "{:?}",
        drawn.points
    );
    // First passage: pressures rise strictly along the drawn curve, and φ never falls.
    for w in drawn.points.windows(2) {
        assert!(w[1].0 > w[0].0 && w[1].1 >= w[0].1, "{w:?}");
    }
    // It reaches 10⁵ Pa (the last rows) within the median's half-window of the end.
    let (p_end, phi_end) = *drawn.points.last().unwrap();
    assert!(
        p_end > 0.8e5 && (phi_end - 0.45).abs() < 0.011,
        "{p_end} {phi_end}"
    );
}

/// Seven 640×480 panels read at page width: rows of three (1920 px), the last row holding one.
#[test]
fn many_panels_wrap_into_rows_of_three_in_png_and_svg() {
    let panels: Vec<Plot> = (0..7)
        .map(|k| {
            let mut p = sample();
            p.title = format!("panel {k}");
            p
        })
        .collect();
    let bytes = panels_png(&panels).unwrap();
    let reader = png::Decoder::new(bytes.as_slice()).read_info().unwrap();
    assert_eq!((reader.info().width, reader.info().height), (1920, 1440));
    let svg = panels_svg(&panels).unwrap();
    assert!(svg.contains("width=\"1920\"") && svg.contains("height=\"1440\""));
    for k in 0..7 {
        assert!(svg.contains(&format!("panel {k}")), "title of panel {k}");
    }
}
