//! The numbers the documentation quotes, regenerated from the code (docs/architecture.md,
//! "Numbers in the docs").
//!
//!     cargo run --release --example docs_numbers -- [--write | --check] [--slow]
//!
//! Runs every source of quoted numbers: the static analyses (`static.…`, also checked by
//! `tests/docs_numbers.rs`), the paper example (`paper.…`, docs/analyses.md) and the clearance
//! calibration example (`clearance.…`, docs/clearance.md), and with `--slow` the dynamic fits of
//! the fitting example (`fit.…`, docs/fit.md: a few minutes). Without a flag it prints each
//! number and what the docs quote; `--write` puts the values into the marked spans of
//! `README.md` and `docs/*.md` (keeping each span's decimals); `--check` exits with an error
//! when a quoted number drifted beyond its tolerance, or when a span's key has no number (the
//! `fit.…` spans are checked only with `--slow`). The paper example's sweeps take most of the
//! time: about 8 s of CPU without `--slow`.

// Each example included below carries its own copy of `common/doc_numbers.rs` (its test
// checks the docs with it); `adopt!` turns their numbers into this copy's.
#![allow(clippy::duplicate_mod)]

use std::collections::BTreeMap;

#[path = "common/doc_numbers.rs"]
#[allow(dead_code)]
mod doc_numbers;
#[path = "common/static_numbers.rs"]
#[allow(dead_code)]
mod static_numbers;

#[path = "firmware_clearance.rs"]
#[allow(dead_code)]
mod firmware_clearance;
#[path = "fit_synthetic.rs"]
#[allow(dead_code)]
mod fit_synthetic;
#[path = "paper.rs"]
#[allow(dead_code)]
mod paper;

use doc_numbers::Quoted;

type Res<T> = Result<T, Box<dyn std::error::Error>>;

/// The same number from another copy of this module (each example includes its own).
macro_rules! adopt {
    ($numbers:expr) => {
        $numbers
            .into_iter()
            .map(|q| Quoted {
                key: q.key,
                value: q.value,
                power_of_ten: q.power_of_ten,
                tol: q.tol,
            })
            .collect::<Vec<Quoted>>()
    };
}

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let known = ["--write", "--check", "--slow"];
    if let Some(a) = args.iter().find(|a| !known.contains(&a.as_str())) {
        return Err(format!("unknown argument {a:?} (known: {})", known.join(", ")).into());
    }
    let flag = |f: &str| args.iter().any(|a| a == f);
    let (write, check, slow) = (flag("--write"), flag("--check"), flag("--slow"));
    if write && check {
        return Err("--write and --check exclude each other".into());
    }
    let root = doc_numbers::repository_root();

    let mut numbers = static_numbers::numbers()?;
    let dir = tempfile::tempdir()?;
    let summary = paper::run(&paper::Options::default(), dir.path())?;
    numbers.extend(adopt!(paper::doc_numbers(&summary)));
    let (statics, rows) = firmware_clearance::run()?;
    numbers.extend(adopt!(firmware_clearance::doc_numbers(&statics, &rows)));
    if slow {
        let setup = fit_synthetic::Setup::new();
        let opts = hdi_tribology::fit::FitOptions::default();
        for (which, run) in [
            ("dynamic", "dynamic"),
            ("dynamic-direct", "direct"),
            ("dynamic-from-truth", "from_truth"),
        ] {
            let (r, stage1, truth) = setup.dynamic(which, &opts)?;
            numbers.extend(adopt!(fit_synthetic::doc_numbers(run, &r, stage1, &truth)));
        }
    }
    let mut keys = BTreeMap::new();
    for q in &numbers {
        if keys.insert(q.key.clone(), q).is_some() {
            return Err(format!("two sources give the number {}", q.key).into());
        }
    }

    println!("\n# Numbers the docs quote");
    let spans = doc_numbers::spans(&root)?;
    for span in &spans {
        let now = keys
            .get(&span.key)
            .map_or("(not computed)".to_string(), |q| q.text_like(&span.text));
        println!(
            "{}:{} {} = {} (code: {now})",
            span.file.display(),
            span.line,
            span.key,
            span.text
        );
    }
    // A span no source gave a number for: a misspelt key, or a `fit.…` one without --slow.
    let missing: Vec<String> = spans
        .iter()
        .filter(|s| !keys.contains_key(&s.key))
        .filter(|s| slow || !s.key.starts_with("fit."))
        .map(|s| format!("{}:{} {}", s.file.display(), s.line, s.key))
        .collect();
    if write {
        let changed = doc_numbers::write(&root, &numbers)?;
        println!("\n{} span(s) rewritten:", changed.len());
        for c in &changed {
            println!("  {c}");
        }
    }
    if check {
        let report = doc_numbers::check(&root, &numbers)?;
        println!(
            "\n{} quoted numbers agree, {} drifted",
            report.agreed,
            report.drifted.len()
        );
        for d in &report.drifted {
            println!("  {d}");
        }
        if !report.drifted.is_empty() {
            return Err(
                "numbers in the docs drifted from the code: `cargo run --release \
                        --example docs_numbers -- --write` regenerates them (then read the \
                        prose around each)"
                    .into(),
            );
        }
    }
    if !missing.is_empty() {
        return Err(format!(
            "no source gives the number of these spans:\n  {}",
            missing.join("\n  ")
        )
        .into());
    }
    Ok(())
}
