//! PNG charts: the files decode as PNGs of the documented size with more than one colour, and
//! bad data is an error that writes nothing.

use projfluid::Error;
use projfluid_lab::plot::{BarChart, HEIGHT, LineChart, Series, SeriesStyle, WIDTH};
use std::path::{Path, PathBuf};

/// A fresh directory under the target dir for this test's files.
fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("plot")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Decodes `path` and returns (width, height, number of distinct RGB colours).
fn decode(path: &Path) -> (u32, u32, usize) {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    let pixels = &buf[..info.buffer_size()];
    let mut colours: Vec<[u8; 3]> = pixels.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
    colours.sort_unstable();
    colours.dedup();
    (info.width, info.height, colours.len())
}

fn line_chart(series: Vec<Series>) -> LineChart {
    LineChart {
        title: "Surge front".into(),
        x_label: "T = t·√(2g/a)".into(),
        y_label: "Z = z/a".into(),
        series,
    }
}

fn series(label: &str, points: Vec<(f64, f64)>, style: SeriesStyle) -> Series {
    Series {
        label: label.into(),
        points,
        style,
    }
}

#[test]
fn line_chart_writes_a_png_of_the_chart_size() {
    let dir = scratch("line");
    let chart = line_chart(vec![
        series(
            "simulation",
            (0..50)
                .map(|i| (i as f64 * 0.1, (i as f64 * 0.1).sin()))
                .collect(),
            SeriesStyle::Line,
        ),
        series(
            "experiment",
            vec![(0.5, 0.4), (1.5, 0.9)],
            SeriesStyle::Markers,
        ),
        series(
            "both",
            vec![(0.0, -1.0), (4.0, 1.0)],
            SeriesStyle::LineMarkers,
        ),
    ]);
    // The extension does not decide the format.
    let path = dir.join("front.chart");
    chart.write_png(&path).unwrap();
    let (w, h, colours) = decode(&path);
    assert_eq!((w, h), (WIDTH, HEIGHT));
    assert_eq!((w, h), (800, 500));
    // White background, black axes and text, three series colours (plus anti-aliasing).
    assert!(colours >= 5, "only {colours} colours");
}

/// The RGB pixels of the PNG at `path`, row by row.
fn pixels(path: &Path) -> Vec<[u8; 3]> {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf[..info.buffer_size()]
        .chunks(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect()
}

/// A series that drops and jumps within a few samples (a gauge as the first water arrives)
/// stays inside the plotting area: nothing of the series' colour (blue: the first series)
/// below the x axis, where only the tick labels and the axis title are drawn.
#[test]
fn a_jagged_line_stays_inside_the_chart() {
    let dir = scratch("jagged");
    let drop_and_jump = [
        0.0082, 0.0073, 0.0066, 0.0061, 0.0061, 0.0070, 0.0092, 0.0135, 0.0202, 0.0260, 0.0290,
        0.0292, 0.0200, 0.0101, 0.0060, 0.0047, 0.0047, 0.0058, 0.0096, 0.0852, 0.0833, 0.0733,
        0.0684, 0.0668, 0.0656, 0.0642, 0.0620, 0.0595, 0.0572, 0.0559,
    ];
    let mut points: Vec<(f64, f64)> = (0..600).map(|i| (i as f64 * 0.002, 0.0016)).collect();
    points.extend(
        drop_and_jump
            .iter()
            .enumerate()
            .map(|(i, &h)| (1.2 + i as f64 * 0.0016, h)),
    );
    points.extend((0..400).map(|i| (1.25 + i as f64 * 0.002, 0.3)));
    let chart = LineChart {
        title: "Water height".into(),
        x_label: "t (s)".into(),
        y_label: "height (m)".into(),
        series: vec![series("simulation", points, SeriesStyle::Line)],
    };
    let path = dir.join("jagged.png");
    chart.write_png(&path).unwrap();
    let image = pixels(&path);
    let blue = |p: &[u8; 3]| p[2] as i32 > p[0] as i32 + 60;
    assert!(image.iter().any(blue), "the series is drawn in blue");
    // The x axis's tick labels and title take the bottom 57 rows (margin and label area).
    let below_axis = &image[(WIDTH * (HEIGHT - 50)) as usize..];
    let stray = below_axis.iter().filter(|p| blue(p)).count();
    assert_eq!(stray, 0, "{stray} blue pixels below the x axis");
}

#[test]
fn a_single_point_still_makes_a_chart() {
    let dir = scratch("single");
    let chart = line_chart(vec![series("one", vec![(2.0, 2.0)], SeriesStyle::Markers)]);
    chart.write_png(&dir.join("one.png")).unwrap();
    assert!(decode(&dir.join("one.png")).2 > 2);
}

#[test]
fn bar_chart_writes_a_png_of_the_chart_size() {
    let dir = scratch("bar");
    let chart = BarChart {
        title: "Time per step".into(),
        y_label: "ms".into(),
        categories: ["chebyshev", "jacobi1", "cg", "ldlt"]
            .map(String::from)
            .to_vec(),
        series: vec![
            ("30k".into(), vec![12.0, 20.0, 15.5, 40.0]),
            ("88k".into(), vec![-3.0, 60.0, 45.0, 130.0]),
        ],
    };
    let path = dir.join("bars.png");
    chart.write_png(&path).unwrap();
    let (w, h, colours) = decode(&path);
    assert_eq!((w, h), (800, 500));
    assert!(colours >= 4, "only {colours} colours");
}

#[test]
fn empty_or_non_finite_data_is_an_error_and_writes_nothing() {
    let dir = scratch("bad");
    let path = dir.join("bad.png");
    let field = |e: Error| match e {
        Error::InvalidArgument { field, .. } => field,
        other => panic!("expected an invalid-argument error, got {other:?}"),
    };

    let none = line_chart(vec![]);
    assert_eq!(field(none.write_png(&path).unwrap_err()), "series");
    let empty = line_chart(vec![series("a", vec![], SeriesStyle::Line)]);
    assert_eq!(
        field(empty.write_png(&path).unwrap_err()),
        "series[0].points"
    );
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let chart = line_chart(vec![
            series("a", vec![(0.0, 1.0)], SeriesStyle::Line),
            series("b", vec![(0.0, 1.0), (1.0, bad)], SeriesStyle::Line),
        ]);
        assert_eq!(
            field(chart.write_png(&path).unwrap_err()),
            "series[1].points[1]"
        );
    }
    let huge = line_chart(vec![series(
        "a",
        vec![(0.0, -1e308), (1.0, 1e308)],
        SeriesStyle::Line,
    )]);
    assert_eq!(field(huge.write_png(&path).unwrap_err()), "y");

    let bars = |categories: Vec<String>, series: Vec<(String, Vec<f64>)>| BarChart {
        title: "t".into(),
        y_label: "y".into(),
        categories,
        series,
    };
    let cats = vec!["a".to_string(), "b".to_string()];
    let e = bars(vec![], vec![("s".into(), vec![])]).write_png(&path);
    assert_eq!(field(e.unwrap_err()), "categories");
    let e = bars(cats.clone(), vec![]).write_png(&path);
    assert_eq!(field(e.unwrap_err()), "series");
    let e = bars(cats.clone(), vec![("s".into(), vec![1.0])]).write_png(&path);
    assert_eq!(field(e.unwrap_err()), "series[0]");
    let e = bars(cats, vec![("s".into(), vec![1.0, f64::NAN])]).write_png(&path);
    assert_eq!(field(e.unwrap_err()), "series[0][1]");

    assert!(!path.exists(), "a rejected chart must not write a file");
}

#[test]
fn an_unwritable_path_is_an_io_error() {
    let dir = scratch("unwritable");
    let chart = line_chart(vec![series("a", vec![(0.0, 1.0)], SeriesStyle::Line)]);
    let err = chart
        .write_png(&dir.join("missing").join("x.png"))
        .unwrap_err();
    match err {
        Error::Io(msg) => assert!(msg.contains("x.png"), "{msg}"),
        other => panic!("expected an I/O error, got {other:?}"),
    }
}
