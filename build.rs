//! Fingerprints the crate's sources and lock file for the table cache: a build whose code differs
//! never reads tables written by another (`src/cache/mod.rs`, "Keys").

use std::fs;
use std::path::{Path, PathBuf};

#[allow(dead_code)]
#[path = "src/cache/sha256.rs"]
mod sha256;

/// Every file under `dir`, recursively.
fn files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(list) = fs::read_dir(dir) else {
        return;
    };
    for e in list.flatten() {
        let p = e.path();
        if p.is_dir() {
            files(&p, out);
        } else {
            out.push(p);
        }
    }
}

fn main() {
    let root = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let mut all = Vec::new();
    files(&root.join("src"), &mut all);
    all.push(root.join("Cargo.lock"));
    all.sort();
    let mut h = sha256::Sha256::new();
    for p in &all {
        // The path relative to the crate, its length and its contents: no two trees alike.
        let name = p
            .strip_prefix(&root)
            .unwrap_or(p)
            .to_string_lossy()
            .replace('\\', "/");
        let body = fs::read(p).unwrap_or_default();
        for part in [name.as_bytes(), &body] {
            h.update(&(part.len() as u64).to_le_bytes());
            h.update(part);
        }
    }
    println!(
        "cargo:rustc-env=HDI_SOURCE_DIGEST={}",
        sha256::hex(&h.finish())
    );
    println!("cargo:rerun-if-changed=src");
    println!("cargo:rerun-if-changed=Cargo.lock");
    println!("cargo:rerun-if-changed=build.rs");
}
