//! The slider's geometry as data: the file formats and the typed errors for bad geometry and
//! bad operating conditions.

use hdi_tribology::bearing::BearingSpec;
use hdi_tribology::Error;

fn example() -> BearingSpec {
    BearingSpec::from_path(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/bearing/two_rail_taper_flat.toml"
    ))
    .unwrap()
}

fn invalid(spec: &BearingSpec) -> (String, String) {
    match spec.build() {
        Err(Error::InvalidInput { field, reason }) => (field, reason),
        other => panic!("expected an invalid input, got {other:?}"),
    }
}

#[test]
fn text_format_reads_back_what_it_writes() {
    let spec = example();
    let text = spec.to_text();
    let back = BearingSpec::from_text(&text).unwrap();
    let mut want = spec.clone();
    for r in &mut want.slider.regions {
        r.name = r.name.as_ref().map(|n| n.replace(' ', "_"));
    }
    assert_eq!(back, want);
    // The shipped text file describes the same slider as the TOML one.
    let shipped = BearingSpec::from_path(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/bearing/two_rail_taper_flat.abs"
    ))
    .unwrap();
    assert_eq!(shipped.build().unwrap().polygons.len(), 2);
    assert_eq!(shipped.slider.length_um, spec.slider.length_um);
}

#[test]
fn json_round_trip() {
    let spec = example();
    let json = serde_json::to_string(&spec).unwrap();
    assert_eq!(BearingSpec::from_json_str(&json).unwrap(), spec);
}

#[test]
fn an_open_polygon_is_named() {
    let mut s = example();
    s.slider.regions[1].polygon_um.pop();
    let (field, reason) = invalid(&s);
    assert!(field.contains("\"right rail\""), "{field}");
    assert!(reason.contains("open"), "{reason}");
}

#[test]
fn a_self_intersecting_polygon_is_named() {
    let mut s = example();
    s.slider.regions[0].name = None;
    s.slider.regions[0].polygon_um = vec![
        [0.0, 0.0],
        [2000.0, 400.0],
        [2000.0, 0.0],
        [0.0, 400.0],
        [0.0, 0.0],
    ];
    let (field, reason) = invalid(&s);
    assert!(field.contains("regions[0] #0"), "{field}");
    assert!(reason.contains("intersects itself"), "{reason}");
}

#[test]
fn a_rail_outside_the_slider_is_named() {
    let mut s = example();
    s.slider.regions[1].polygon_um[2] = [2100.0, 1600.0];
    let (field, reason) = invalid(&s);
    assert!(field.contains("\"right rail\".polygon_um[2]"), "{field}");
    assert!(reason.contains("outside the slider"), "{reason}");
}

#[test]
fn a_negative_etch_depth_is_named() {
    let mut s = example();
    s.slider.regions[0].depth_nm = -5.0;
    let (field, reason) = invalid(&s);
    assert!(field.ends_with("\"left rail\".depth_nm"), "{field}");
    assert!(reason.contains("-5 nm"), "{reason}");
}

#[test]
fn operating_conditions_are_checked() {
    let mut s = example();
    s.operating.skew_deg = 31.0;
    let (field, reason) = invalid(&s);
    assert_eq!(field, "operating.skew_deg");
    assert!(reason.contains("31°"), "{reason}");
    let mut s = example();
    s.operating.rpm = 0.0;
    let (field, reason) = invalid(&s);
    assert_eq!(field, "operating.rpm");
    assert!(reason.contains("speed"), "{reason}");
    let mut s = example();
    s.operating.preload_mn = -1.0;
    assert_eq!(invalid(&s).0, "operating.preload_mn");
    let mut s = example();
    s.operating.pivot_um = Some([3000.0, 10.0]);
    assert_eq!(invalid(&s).0, "operating.pivot_um");
    let mut s = example();
    s.slider.taper.as_mut().unwrap().angle_mrad = Some(-1.0);
    assert_eq!(invalid(&s).0, "slider.taper.angle_mrad");
}

#[test]
fn text_format_errors_name_the_line() {
    let e = BearingSpec::from_text("length_um 1000\nwidth_um x\n").unwrap_err();
    assert!(e.to_string().contains("line 2"), "{e}");
    let e = BearingSpec::from_text("length_um 1000\nregion a depth_nm 0\n0 0\n").unwrap_err();
    assert!(e.to_string().contains("no \"end\""), "{e}");
}
