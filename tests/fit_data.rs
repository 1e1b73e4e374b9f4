//! Bad data files: each gives one error naming the file, the line and the column.

use hdi_tribology::fit::{fit, DataError, DataSet, FitOptions, FreeParameter};
use hdi_tribology::scene::Scene;
use hdi_tribology::Error;

fn path(name: &str) -> String {
    format!("{}/tests/data/fit/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn bad(name: &str) -> DataError {
    let e = DataSet::from_path(path(name)).expect_err(name);
    assert!(e.file.ends_with(name), "{e}");
    assert!(e.to_string().starts_with(&e.file), "{e}");
    e
}

#[test]
fn nan_is_refused_at_its_line_and_column() {
    let e = bad("nan_value.csv");
    assert_eq!((e.line, e.column), (Some(3), Some(2)), "{e}");
    assert_eq!(e.column_name.as_deref(), Some("touchdown_power_mw"));
    assert!(
        e.reason.contains("finite") && e.reason.contains("nan"),
        "{e}"
    );
}

#[test]
fn a_unit_the_reader_does_not_know_is_named_with_the_known_ones() {
    let e = bad("unknown_unit.csv");
    // The comment line counts: the header is line 2.
    assert_eq!((e.line, e.column), (Some(2), Some(2)), "{e}");
    assert!(
        e.reason.contains("unknown unit `kw`") && e.reason.contains("mw"),
        "{e}"
    );
}

#[test]
fn missing_columns_are_named() {
    let e = bad("missing_column.csv");
    assert_eq!((e.line, e.column), (Some(1), Some(2)), "{e}");
    assert!(
        e.reason.contains("unknown column") && e.reason.contains("touchdown_power_mw"),
        "{e}"
    );
    let e = bad("no_x_column.csv");
    assert_eq!(e.line, Some(1), "{e}");
    assert!(
        e.reason.contains("missing column") && e.reason.contains("dc_voltage_v"),
        "{e}"
    );
    let e = bad("short_row.csv");
    assert_eq!(e.line, Some(3), "{e}");
    assert!(e.reason.contains("1 fields, the header has 2"), "{e}");
}

#[test]
fn duplicate_x_values_name_both_lines() {
    let e = bad("duplicate_x.csv");
    assert_eq!((e.line, e.column), (Some(5), Some(1)), "{e}");
    assert!(
        e.reason.contains("duplicate") && e.reason.contains("first at line 3"),
        "{e}"
    );
}

#[test]
fn text_in_a_number_field_is_quoted() {
    let e = bad("not_a_number.csv");
    assert_eq!((e.line, e.column), (Some(3), Some(2)), "{e}");
    assert!(e.reason.contains("`74.3 mW`"), "{e}");
}

#[test]
fn too_few_points_for_the_parameters_is_refused_before_any_model_runs() {
    let d = DataSet::from_path(path("too_few_points.csv")).unwrap();
    let free = [
        FreeParameter::new("contact_potential_v"),
        FreeParameter::new("efficiency_nm_per_mw"),
    ];
    match fit(&Scene::paper(), &[d], &free, &FitOptions::default()) {
        Err(Error::Data(e)) => {
            assert!(e.file.ends_with("too_few_points.csv"), "{e}");
            assert!(
                e.reason.contains("2 measured values for 2 free parameters"),
                "{e}"
            );
        }
        other => panic!("expected a data error, got {other:?}"),
    }
}

#[test]
fn a_missing_file_names_the_file() {
    let e = DataSet::from_path(path("no_such_file.csv")).unwrap_err();
    assert!(
        e.file.ends_with("no_such_file.csv") && e.line.is_none(),
        "{e}"
    );
}

#[test]
fn units_are_converted_and_uncertainties_read() {
    let d = DataSet::from_csv_str(
        "ac_amplitude_mv,takeoff_power_w,takeoff_power_err_uw\n100,0.068,50\n300,0.0679,60\n",
        "x.csv",
    )
    .unwrap();
    assert_eq!(d.x, vec![0.1, 0.3]);
    assert!(d.is_dynamic());
    let o = &d.observed[0];
    assert_eq!(o.values, vec![0.068, 0.0679]);
    let errs = o.errors.as_ref().unwrap();
    assert!((errs[0] - 5e-5).abs() < 1e-18 && (errs[1] - 6e-5).abs() < 1e-18);
    let e = DataSet::from_csv_str("dc_voltage_v,takeoff_power_err_mw\n0,1\n", "y.csv").unwrap_err();
    assert!(e.reason.contains("missing column"), "{e}");
    let e = DataSet::from_csv_str(
        "dc_voltage_v,touchdown_power_mw,touchdown_power_err_mw\n0,74,0\n",
        "z.csv",
    )
    .unwrap_err();
    assert_eq!((e.line, e.column), (Some(2), Some(3)), "{e}");
}
