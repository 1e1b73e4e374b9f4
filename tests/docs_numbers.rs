//! The numbers the docs quote (docs/architecture.md, "Numbers in the docs"): every marked span
//! is well formed and names a source; the cheap numbers (the paper scene's static analyses) are
//! computed here and must agree with every span that quotes them. The paper and clearance
//! examples' tests check the numbers of their own runs; `cargo run --release --example
//! docs_numbers -- --check --slow` checks all, the fits included.

// `static_numbers` names it `crate::doc_numbers`: the test program re-exports it at its root.
#[path = "../examples/common/doc_numbers.rs"]
#[allow(dead_code)]
pub(crate) mod doc_numbers;
#[path = "../examples/common/static_numbers.rs"]
mod static_numbers;

/// The sources of quoted numbers, by the prefix of their keys.
const SOURCES: [&str; 4] = [static_numbers::PREFIX, "paper.", "clearance.", "fit."];

#[test]
fn every_span_is_well_formed_and_names_a_source() {
    let root = doc_numbers::repository_root();
    let spans = doc_numbers::spans(&root).expect("every span is closed and has a key");
    assert!(spans.len() > 50, "the docs quote their numbers in spans");
    for s in &spans {
        assert!(
            SOURCES.iter().any(|p| s.key.starts_with(p)),
            "{}:{} {}: no source has this key's prefix ({SOURCES:?})",
            s.file.display(),
            s.line,
            s.key
        );
        let parsed: Option<f64> = s.text.replace('\u{2212}', "-").parse().ok();
        assert!(
            parsed.is_some_and(f64::is_finite),
            "{}:{} {}: {:?} is not a number",
            s.file.display(),
            s.line,
            s.key,
            s.text
        );
        assert!(
            !s.text.trim().starts_with('-'),
            "{}:{}: a quoted minus is U+2212",
            s.file.display(),
            s.line
        );
    }
}

#[test]
fn the_static_numbers_the_docs_quote_are_the_codes() {
    let root = doc_numbers::repository_root();
    let numbers = static_numbers::numbers().expect("the paper scene's static analyses run");
    let agreed = doc_numbers::assert_quoted(&root, &numbers);
    // Every static span has its number (a misspelt key would go unchecked).
    let report = doc_numbers::check(&root, &numbers).unwrap();
    let unknown: Vec<String> = report
        .unchecked
        .iter()
        .filter(|s| s.key.starts_with(static_numbers::PREFIX))
        .map(|s| format!("{}:{} {}", s.file.display(), s.line, s.key))
        .collect();
    assert!(
        unknown.is_empty(),
        "no static number has these keys: {unknown:?}"
    );
    // Every static number is quoted somewhere.
    let spans = doc_numbers::spans(&root).unwrap();
    for q in &numbers {
        assert!(
            spans.iter().any(|s| s.key == q.key),
            "{} is computed but quoted nowhere",
            q.key
        );
    }
    assert!(agreed >= numbers.len());
}

/// The check catches a drift beyond one unit of the last printed digit, and `write` keeps a
/// span's decimals.
#[test]
fn a_drifted_number_is_caught_and_rewritten_with_its_decimals() {
    use doc_numbers::Quoted;
    let q = Quoted::new("static.x", 74.3244);
    assert_eq!(q.disagrees("74.324"), None);
    assert_eq!(q.disagrees("74.325"), None, "one unit of the last digit");
    assert!(q.disagrees("74.326").is_some());
    assert!(q.disagrees("74.4").is_none() && q.disagrees("74.5").is_some());
    assert!(q.disagrees("seventy").is_some());
    assert_eq!(q.text_like("74.30"), "74.32");
    assert_eq!(
        Quoted::new("k", -0.2749).text_like("\u{2212}0.3"),
        "\u{2212}0.3"
    );
    let p = Quoted::power_of_ten("k", 1.0000000000000002e-8);
    assert_eq!(p.disagrees("1e-8"), None);
    assert!(p.disagrees("1e-7").is_some());
    assert!(Quoted::new("k", 3.0).within(0.5).disagrees("3.4").is_none());
    assert_eq!(doc_numbers::last_digit_unit("\u{2212}1.004"), 1e-3);
    assert_eq!(doc_numbers::last_digit_unit("12"), 1.0);

    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("docs")).unwrap();
    let text = "at <!-- num:static.x -->74.30<!-- /num --> mW and \
                <!-- num:static.y -->1<!-- /num -->\n";
    std::fs::write(dir.path().join("README.md"), text).unwrap();
    std::fs::write(dir.path().join("docs/a.md"), "none\n").unwrap();
    let report = doc_numbers::check(dir.path(), std::slice::from_ref(&q)).unwrap();
    assert_eq!(report.drifted.len(), 1, "{:?}", report.drifted);
    assert_eq!(report.unchecked.len(), 1);
    let changed = doc_numbers::write(dir.path(), &[q]).unwrap();
    assert_eq!(changed.len(), 1);
    assert_eq!(
        std::fs::read_to_string(dir.path().join("README.md")).unwrap(),
        "at <!-- num:static.x -->74.32<!-- /num --> mW and <!-- num:static.y -->1<!-- /num -->\n"
    );
    let bad = "<!-- num:static.x -->74.3\n<!-- /num -->";
    assert!(doc_numbers::spans_of(std::path::Path::new("b.md"), bad).is_err());
}
