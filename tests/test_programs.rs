//! The files of `tests/` are built as a few test programs (Cargo.toml: `autotests = false` and
//! one `[[test]]` per `tests/suites/<name>.rs`, which names its files as modules). A file that no
//! program names is never built: every file must be named by exactly one program, and every
//! program must be listed in Cargo.toml.

use std::collections::BTreeMap;
use std::path::Path;

/// The names of the `.rs` files directly in `dir`, sorted.
fn rust_files(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".rs"))
        .collect();
    names.sort();
    names
}

#[test]
fn every_test_file_is_in_exactly_one_test_program() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let manifest: toml::Table =
        toml::from_str(&std::fs::read_to_string(root.join("Cargo.toml")).unwrap()).unwrap();
    assert_eq!(
        manifest["package"]
            .get("autotests")
            .and_then(|v| v.as_bool()),
        Some(false),
        "Cargo.toml lists the test programs"
    );
    let mut listed: Vec<String> = manifest["test"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["path"].as_str().unwrap().to_string())
        .collect();
    listed.sort();
    let suites: Vec<String> = rust_files(&root.join("tests/suites"))
        .into_iter()
        .map(|n| format!("tests/suites/{n}"))
        .collect();
    assert_eq!(
        listed, suites,
        "every tests/suites/*.rs is a [[test]] of Cargo.toml"
    );

    let mut named: BTreeMap<String, Vec<&str>> = BTreeMap::new();
    for suite in &suites {
        let text = std::fs::read_to_string(root.join(suite)).unwrap();
        for line in text.lines() {
            if let Some(file) = line
                .trim()
                .strip_prefix("#[path = \"../")
                .and_then(|rest| rest.strip_suffix("\"]"))
            {
                named.entry(file.to_string()).or_default().push(suite);
            }
        }
    }
    for file in rust_files(&root.join("tests")) {
        match named.remove(&file).as_deref() {
            Some([_]) => {}
            Some(several) => panic!("tests/{file} is named more than once: {several:?}"),
            None => panic!("tests/{file} is in no test program (tests/suites/*.rs)"),
        }
    }
    assert!(named.is_empty(), "files named but missing: {named:?}");
}
