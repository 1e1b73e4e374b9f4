//! The committed header is the one cbindgen generates from the sources now (build.rs writes it
//! to OUT_DIR on every build).

use std::path::Path;

#[test]
fn committed_header_is_generated() {
    let generated = include_str!(concat!(env!("OUT_DIR"), "/hdi.h"));
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("include/hdi.h");
    if std::env::var_os("HDI_BLESS_HEADER").is_some() {
        std::fs::write(&path, generated).expect("write include/hdi.h");
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    if committed != generated {
        let line = committed
            .lines()
            .zip(generated.lines())
            .position(|(a, b)| a != b)
            .map_or_else(|| "the end".to_string(), |i| format!("line {}", i + 1));
        panic!(
            "include/hdi.h differs from what cbindgen generates from src/lib.rs (first at \
             {line}); regenerate it: HDI_BLESS_HEADER=1 cargo test --manifest-path \
             capi/Cargo.toml --test header"
        );
    }
}
