//! Fuzzing the scene reader with proptest: arbitrary bytes, arbitrary edits of a valid scene
//! (values replaced by extreme numbers, strings, arrays; keys removed or duplicated; text cut),
//! and arbitrary structured scenes. The reader must never panic: it returns a scene that
//! validates, or a typed error on one line that names the field (input errors) or the line
//! (parse errors). Accepted scenes must also survive building their interface terms and
//! evaluating them: finite forces or a typed error.
//!
//! The case count is `HDI_FUZZ_CASES` (default 300 per property, for CI time); a long run is done
//! by hand with a large count and its failures are kept in `tests/regressions_fuzz.rs`.

#[path = "common/seeded.rs"]
mod seeded;

use hdi_tribology::force::TermForce;
use hdi_tribology::scene::Scene;
use hdi_tribology::Error;
use proptest::prelude::*;

fn cases() -> u32 {
    std::env::var("HDI_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(300)
}

/// What the reader must give: a valid scene, or an error that is typed and fits on one line.
fn check_outcome(r: hdi_tribology::Result<Scene>) -> Result<(), TestCaseError> {
    match r {
        Ok(scene) => {
            prop_assert!(scene.validate().is_ok());
            // Build and evaluate the enabled terms at a few gaps: finite, or a typed error.
            if let Ok(terms) = scene.interface_terms() {
                let (lo, hi) = scene.table_range();
                for d in [lo, 0.5 * (lo + hi), hi] {
                    for t in &terms {
                        if let Ok(TermForce { value: f, slope: s }) = t.force(d) {
                            prop_assert!(
                                f.is_finite() && s.is_finite(),
                                "{} at {d}: {f} {s}",
                                t.name()
                            );
                        }
                    }
                }
            }
        }
        Err(e) => {
            let msg = e.to_string();
            prop_assert!(!msg.contains('\n'), "error spans lines: {msg}");
            match e {
                Error::InvalidInput { field, .. } => prop_assert!(!field.is_empty()),
                Error::Scene { reason, .. } => prop_assert!(!reason.is_empty()),
                other => prop_assert!(false, "unexpected error kind: {other:?}"),
            }
        }
    }
    Ok(())
}

fn paper_toml() -> String {
    Scene::paper().to_toml_string().unwrap()
}

fn paper_engineering_toml() -> String {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/paper_engineering.toml");
    std::fs::read_to_string(path).unwrap()
}

/// Replacement values for a `key = value` line: extremes, wrong types, garbage.
fn value() -> impl Strategy<Value = String> {
    prop_oneof![
        any::<f64>().prop_map(|x| format!("{x:e}")),
        Just("nan".to_string()),
        Just("inf".to_string()),
        Just("-inf".to_string()),
        Just("0.0".to_string()),
        Just("-0.0".to_string()),
        Just("1e308".to_string()),
        Just("-1e-308".to_string()),
        Just("5e-324".to_string()),
        any::<i64>().prop_map(|x| x.to_string()),
        Just("18446744073709551615".to_string()),
        Just("\"\"".to_string()),
        "\"[a-z_]{0,12}\"".prop_map(|s| s),
        Just("[]".to_string()),
        Just("[[0.0, 0.06]]".to_string()),
        Just("[[1.0, 0.06], [0.0, 0.07]]".to_string()),
        Just("{}".to_string()),
        Just("true".to_string()),
        "[ -~]{0,20}".prop_map(|s| s),
    ]
}

proptest! {
    #![proptest_config(seeded::config(cases()))]

    /// Arbitrary bytes (lossily decoded) as TOML and JSON.
    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..512)) {
        let text = String::from_utf8_lossy(&bytes);
        check_outcome(Scene::from_toml_str(&text))?;
        check_outcome(Scene::from_json_str(&text))?;
    }

    /// One line of the paper scene (in SI or in engineering units) with its value replaced,
    /// removed, duplicated or cut short, or its key given an engineering-unit suffix.
    #[test]
    fn edited_paper_scene_is_accepted_or_rejected_by_field(
        engineering in any::<bool>(),
        line in any::<prop::sample::Index>(),
        v in value(),
        how in 0..5u8,
        cut in any::<prop::sample::Index>(),
        suffix in prop::sample::select(&["_nm", "_mw", "_khz", "_gpa", "_ms", "_per_um2", "_um2"][..]),
    ) {
        let text = if engineering { paper_engineering_toml() } else { paper_toml() };
        let lines: Vec<&str> = text.lines().collect();
        let i = line.index(lines.len());
        let mut out: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
        match how {
            0 => {
                if let Some((k, _)) = lines[i].split_once(" = ") {
                    out[i] = format!("{k} = {v}");
                }
            }
            1 => {
                out.remove(i);
            }
            2 => {
                let dup = out[i].clone();
                out.insert(i, dup);
            }
            3 => {
                if let Some((k, rest)) = lines[i].split_once(" = ") {
                    let stem = k.rsplit_once('_').map_or(k, |(stem, _)| stem);
                    out[i] = format!("{stem}{suffix} = {rest}");
                }
            }
            _ => {
                let joined = out.join("\n");
                let at = cut.index(joined.len() + 1);
                let at = (0..=at).rev().find(|&k| joined.is_char_boundary(k)).unwrap_or(0);
                out = vec![joined[..at].to_string()];
            }
        }
        check_outcome(Scene::from_toml_str(&out.join("\n")))?;
    }

    /// One value of the paper scene as JSON replaced by an extreme number, a wrong type or
    /// garbage, or the text cut short.
    #[test]
    fn edited_paper_json_is_accepted_or_rejected_by_field(
        line in any::<prop::sample::Index>(),
        v in value(),
        cut in proptest::option::of(any::<prop::sample::Index>()),
    ) {
        let text = Scene::paper().to_json_string().unwrap();
        let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
        let i = line.index(lines.len());
        if let Some((k, rest)) = lines[i].clone().split_once("\": ") {
            let comma = if rest.ends_with(',') { "," } else { "" };
            // JSON has no nan/inf literals: those edits are parse errors, as they should be.
            lines[i] = format!("{k}\": {v}{comma}");
        }
        let mut out = lines.join("\n");
        if let Some(c) = cut {
            let at = c.index(out.len() + 1);
            let at = (0..=at).rev().find(|&k| out.is_char_boundary(k)).unwrap_or(0);
            out.truncate(at);
        }
        check_outcome(Scene::from_json_str(&out))?;
    }

    /// Several numeric fields of the paper scene replaced at once by arbitrary numbers.
    #[test]
    fn many_numeric_edits(
        edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<f64>()), 1..6),
    ) {
        let text = paper_toml();
        let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
        let numeric: Vec<usize> = (0..lines.len())
            .filter(|&i| lines[i].split_once(" = ").is_some_and(|(_, v)| v.parse::<f64>().is_ok()))
            .collect();
        for (idx, x) in edits {
            let i = numeric[idx.index(numeric.len())];
            let k = lines[i].split_once(" = ").map(|(k, _)| k.to_string()).unwrap_or_default();
            lines[i] = format!("{k} = {x:e}");
        }
        check_outcome(Scene::from_toml_str(&lines.join("\n")))?;
    }
}
