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
}
