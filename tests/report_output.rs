//! The report writers: CSV read back by the csv crate, typed columns, errors naming the column,
//! nothing left behind on failure; charts with snapped ticks, a legend beside the plot, and
//! refusal of what they cannot draw.

use hdi_tribology::report::{write_file, CsvTable};

#[test]
fn csv_reads_back_exactly_with_typed_columns() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.csv");
    let reals = [0.1 + 0.2, -1.5e-9, 6.02214076e23, 0.0, 70.649e-3];
    CsvTable::new()
        .real("x_m", reals)
        .integer("steps", [1, 2849, 0, u64::MAX, 7])
        .flag("converged", [true, false, true, true, false])
        .optional(
            "hysteresis_w",
            [Some(1e-3), None, Some(-8.24e-4), None, Some(2.0)],
        )
        .write(&path)
        .unwrap();
    let mut rd = csv::Reader::from_path(&path).unwrap();
    assert_eq!(
        rd.headers().unwrap(),
        vec!["x_m", "steps", "converged", "hysteresis_w"]
    );
    let rows: Vec<csv::StringRecord> = rd.records().map(|r| r.unwrap()).collect();
    assert_eq!(rows.len(), 5);
    for (row, x) in rows.iter().zip(reals) {
        assert_eq!(row[0].parse::<f64>().unwrap(), x, "round trip of {x}");
    }
    assert_eq!(&rows[1][1], "2849");
    assert_eq!(&rows[3][1], u64::MAX.to_string());
    assert_eq!(&rows[1][2], "false");
    assert_eq!(&rows[1][3], "");
    assert_eq!(rows[2][3].parse::<f64>().unwrap(), -8.24e-4);
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "no temporary file left"
    );
}

#[test]
fn csv_quotes_headers_that_need_it() {
    let text = CsvTable::new().real("a, b", [1.0]).to_csv_string().unwrap();
    assert_eq!(text, "\"a, b\"\n1\n");
}

#[test]
fn ragged_columns_are_refused_by_name_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ragged.csv");
    let e = CsvTable::new()
        .real("t_s", [0.0, 1.0])
        .integer("steps", [1])
        .write(&path)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("steps") && e.contains("1 rows") && e.contains("t_s"),
        "{e}"
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn a_failed_write_leaves_the_old_file_and_no_temporary() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.csv");
    write_file(&path, "old\n").unwrap();
    // A directory where the file should go: the rename fails.
    let blocked = dir.path().join("blocked.csv");
    std::fs::create_dir(&blocked).unwrap();
    std::fs::write(blocked.join("keep"), "").unwrap();
    assert!(write_file(&blocked, "new\n").is_err());
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "old\n");
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 2, "{names:?}");
}

#[cfg(feature = "plot")]
mod charts {
    use hdi_tribology::report::{Chart, Marker, Series};

    fn svg(chart: &Chart) -> hdi_tribology::Result<String> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.svg");
        chart.to_svg(&path, 800, 500)?;
        Ok(std::fs::read_to_string(path).unwrap())
    }

    /// Text elements of an SVG, with their x position.
    fn texts(svg: &str) -> Vec<(f64, String)> {
        svg.split("<text")
            .skip(1)
            .filter_map(|t| {
                let x = t.split("x=\"").nth(1)?.split('"').next()?.parse().ok()?;
                let body = t.split('>').nth(1)?.split('<').next()?.trim().to_string();
                Some((x, body))
            })
            .collect()
    }

    #[test]
    fn ticks_near_zero_read_zero_and_the_legend_sits_right_of_the_plot() {
        // A parabola symmetric about 0, as Fig. 2(b): the tick arithmetic lands near 0.
        let pts: Vec<(f64, f64)> = (-10..=10)
            .map(|i| {
                let v = i as f64 * 0.1;
                (v, -v * v)
            })
            .collect();
        let s = svg(&Chart {
            title: "t",
            x_label: "V",
            y_label: "nm",
            series: vec![
                Series::line("fit", pts.clone()),
                Series::markers("model", pts).marker(Marker::Square),
            ],
            ..Chart::default()
        })
        .unwrap();
        let texts = texts(&s);
        assert!(
            texts.iter().all(|(_, t)| !t.contains("e-1")),
            "unsnapped tick: {texts:?}"
        );
        assert!(texts.iter().any(|(_, t)| t == "0"));
        let legend_x = texts.iter().find(|(_, t)| t == "model").unwrap().0;
        let rightmost_tick = texts
            .iter()
            .filter(|(_, t)| t == "1")
            .map(|(x, _)| *x)
            .fold(f64::NEG_INFINITY, f64::max);
        assert!(
            legend_x > rightmost_tick,
            "legend at {legend_x}, x axis ends at {rightmost_tick}"
        );
    }

    #[test]
    fn unusable_charts_are_refused() {
        let empty = Chart {
            title: "nothing",
            series: vec![Series::line("nan", vec![(f64::NAN, 1.0)])],
            ..Chart::default()
        };
        assert!(svg(&empty)
            .unwrap_err()
            .to_string()
            .contains("no finite points"));
        let log2 = Chart {
            title: "log",
            series: vec![Series::line("y2", vec![(1.0, 1.0), (2.0, 3.0)]).on_secondary()],
            log: (true, false),
            ..Chart::default()
        };
        assert!(svg(&log2)
            .unwrap_err()
            .to_string()
            .contains("second y axis"));
    }

    #[test]
    fn a_second_axis_gets_its_own_label() {
        let s = svg(&Chart {
            title: "dual",
            y_label: "force (mN)",
            y2_label: "spacing (nm)",
            series: vec![
                Series::line("F", vec![(0.0, -1.0), (1.0, 1.0)]),
                Series::line("d", vec![(0.0, 3.0), (1.0, 4.0)]).on_secondary(),
            ],
            ..Chart::default()
        })
        .unwrap();
        assert!(s.contains("spacing (nm)") && s.contains("force (mN)"));
    }

    /// Font sizes of the text elements, in the SVG's own pixels.
    fn font_sizes(svg: &str) -> Vec<f64> {
        svg.split("font-size=\"")
            .skip(1)
            .filter_map(|t| t.split('"').next()?.parse().ok())
            .collect()
    }

    #[test]
    fn charts_are_set_for_print() {
        // A parabola across zero, as Fig. 2(b), drawn 1050 px wide: one column (3.5 in) at
        // 300 dpi, so 8 pt is 1050/252·8 = 33.3 px of the canvas before it is scaled down.
        let pts: Vec<(f64, f64)> = (0..=200)
            .map(|i| {
                let v = -1.0 + i as f64 * 0.01;
                (v, 10.0 - 3.0 * (v - 0.1) * (v - 0.1))
            })
            .collect();
        let chart = Chart {
            title: "a title for the caption only",
            x_label: "V_{dc} (V)",
            y_label: "clearance (nm)",
            series: vec![Series::line("model", pts)],
            print_width_in: Some(3.5),
            ..Chart::default()
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.svg");
        chart.to_svg(&path, 1050, 700).unwrap();
        if let Ok(keep) = std::env::var("HDI_KEEP_CHART") {
            std::fs::copy(&path, keep).unwrap();
        }
        let s = std::fs::read_to_string(&path).unwrap();
        // Shown at 1050 × 700, drawn on a canvas four times finer.
        assert!(
            s.contains(r#"width="1050" height="700" viewBox="0 0 4200 2800""#),
            "{}",
            &s[..200]
        );
        let sizes = font_sizes(&s);
        let eight_pt = 4.0 * 1050.0 / 252.0 * 8.0;
        assert!(
            !sizes.is_empty() && sizes.iter().all(|&f| f >= eight_pt - 1e-9),
            "{sizes:?}"
        );
        // No title in the plot; real minus signs on the ticks; a real subscript.
        assert!(!s.contains("a title for the caption only"));
        let texts = texts(&s);
        assert!(
            texts.iter().any(|(_, t)| t.starts_with('\u{2212}')),
            "{texts:?}"
        );
        assert!(texts.iter().all(|(_, t)| !t.starts_with('-')), "{texts:?}");
        assert!(s.contains(r#"V<tspan baseline-shift="sub" font-size="75%">dc</tspan> (V)"#));
        // The curve's points are placed finer than whole pixels of the figure.
        let ys: Vec<i64> = s
            .split("<polyline")
            .skip(1)
            .map(|poly| {
                poly.split("points=\"")
                    .nth(1)
                    .unwrap()
                    .split('"')
                    .next()
                    .unwrap()
                    .split_whitespace()
                    .filter_map(|p| p.split(',').nth(1)?.parse().ok())
                    .collect::<Vec<i64>>()
            })
            .max_by_key(Vec::len)
            .unwrap();
        assert!(ys.len() > 100, "{}", ys.len());
        assert!(ys.iter().any(|y| y % 4 != 0), "points on whole pixels only");
    }
}
