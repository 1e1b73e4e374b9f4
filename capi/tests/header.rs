//! The committed header is the one cbindgen generates from the sources now.

use std::path::Path;

#[test]
fn committed_header_is_generated() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(dir.join("cbindgen.toml")).expect("cbindgen.toml");
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_config(config)
        .with_src(dir.join("src/lib.rs"))
        .generate()
        .expect("cbindgen generates the header")
        .write(&mut generated);
    let generated = String::from_utf8(generated).expect("UTF-8 header");
    let path = dir.join("include/hdi.h");
    if std::env::var_os("HDI_BLESS_HEADER").is_some() {
        std::fs::write(&path, &generated).expect("write include/hdi.h");
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    if committed != generated {
        let line = committed
            .lines()
            .zip(generated.lines())
            .position(|(a, b)| a != b)
            .map_or_else(|| "the length".to_string(), |i| format!("line {}", i + 1));
        panic!(
            "include/hdi.h differs from what cbindgen generates from src/lib.rs (first at {line}); \
             regenerate it: HDI_BLESS_HEADER=1 cargo test --manifest-path capi/Cargo.toml --test header"
        );
    }
}
