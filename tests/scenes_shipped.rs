//! Every scene shipped in `scenes/` runs `hdi static`, or fails with the reason its own file
//! states: a comment line `# hdi static: fails: <text>`, where `<text>` is
//! part of the error `hdi` prints (docs/scene_format.md, "Shipped scenes"). The extreme scenes
//! of `scenes/extreme/` have their expected outcomes in `tests/extreme_scenes.rs`.
#![cfg(feature = "cli")]

use std::path::{Path, PathBuf};
use std::process::Command;

/// The comment that states why `hdi static` fails on a scene.
const FAILS: &str = "# hdi static: fails: ";

fn shipped() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut files = Vec::new();
    // (`scenes/bearing/` holds slider geometries for `hdi bearing`, not scenes.)
    for e in std::fs::read_dir(&root).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "toml") {
            files.push(p);
        }
    }
    files.sort();
    files
}

#[test]
fn every_shipped_scene_runs_static_or_fails_with_its_stated_reason() {
    let files = shipped();
    assert!(files.len() >= 9, "{files:?}");
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        let reason = text
            .lines()
            .find_map(|l| l.strip_prefix(FAILS))
            .map(str::trim);
        let out = Command::new(env!("CARGO_BIN_EXE_hdi"))
            .arg("static")
            .arg(&file)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        let name = file.display();
        match reason {
            None => {
                assert!(
                    out.status.success(),
                    "{name}: `hdi static` fails: {stderr}\n(a scene that cannot run states why: \
                     `{FAILS}<part of the error>`)"
                );
                let json: serde_json::Value = serde_json::from_slice(&out.stdout)
                    .unwrap_or_else(|e| panic!("{name}: not JSON: {e}"));
                assert!(json.is_object(), "{name}");
            }
            Some(reason) => {
                assert!(!reason.is_empty(), "{name}: an empty reason");
                assert!(
                    !out.status.success(),
                    "{name}: states that `hdi static` fails ({reason}), but it runs"
                );
                assert!(
                    stderr.contains(reason),
                    "{name}: fails with\n{stderr}\nnot with the stated reason {reason:?}"
                );
            }
        }
    }
}
