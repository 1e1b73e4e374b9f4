//! `examples/firmware_loop.c`, compiled with the system C compiler against the static library,
//! gives the Rust example's results to the bit (every period's sensors, and the printed
//! touchdown); under valgrind it leaks nothing and makes no invalid access. A small C program
//! of misuses (`tests/misuse.c`) gets a status for each, also under valgrind.
//!
//! The libraries and the Rust example are those cargo built for this test run, found beside
//! the test's own executable (`target/<profile>/`).

use std::path::{Path, PathBuf};
use std::process::Command;

/// `target/<profile>`: the test runs from `target/<profile>/deps`.
fn profile_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    exe.parent()
        .and_then(Path::parent)
        .expect("target/<profile>/deps")
        .to_path_buf()
}

fn manifest_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Compiles `source` (relative to capi/) against the static library into `out`.
fn compile(source: &str, out: &Path) {
    // The static library built for this test run sits beside the test in `deps`; `cargo build`
    // also copies it up to the profile folder.
    let lib = [
        profile_dir().join("deps").join("libhdi.a"),
        profile_dir().join("libhdi.a"),
    ]
    .into_iter()
    .find(|p| p.exists())
    .unwrap_or_else(|| {
        panic!(
            "libhdi.a is missing from {}/deps: cargo builds it with the crate (crate-type \
             staticlib)",
            profile_dir().display()
        )
    });
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let status = Command::new(&cc)
        .args([
            "-std=c99",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-pedantic",
            "-O2",
        ])
        // No fused multiply-adds: the controller's arithmetic is the Rust example's.
        .arg("-ffp-contract=off")
        .arg("-I")
        .arg(manifest_dir().join("include"))
        .arg(manifest_dir().join(source))
        .arg(&lib)
        .args(["-lm", "-lpthread", "-ldl", "-o"])
        .arg(out)
        .status()
        .unwrap_or_else(|e| {
            panic!(
                "cannot run the C compiler `{cc}` ({e}): install one (Debian: apt-get install gcc)"
            )
        });
    assert!(status.success(), "{cc} failed on {source}");
}

fn run(cmd: &mut Command) -> String {
    let out = cmd.output().expect("run");
    assert!(
        out.status.success(),
        "{cmd:?} failed ({}):\n{}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("UTF-8 output")
}

/// The printed lines, the wall-clock time taken out.
fn printed(stdout: &str) -> Vec<String> {
    stdout
        .lines()
        .map(|l| match l.find(") in ") {
            Some(i) => l[..i + 1].to_string(),
            None => l.to_string(),
        })
        .collect()
}

/// Every cell of a CSV, numbers as their bits.
fn cells(path: &Path) -> (String, Vec<Vec<u64>>) {
    let text = std::fs::read_to_string(path).expect("trace");
    let mut lines = text.lines();
    let header = lines.next().expect("header").to_string();
    let rows = lines
        .map(|l| {
            l.split(',')
                .map(|c| {
                    c.parse::<f64>()
                        .unwrap_or_else(|_| panic!("{}: not a number: {c}", path.display()))
                        .to_bits()
                })
                .collect()
        })
        .collect();
    (header, rows)
}

#[test]
fn c_example_equals_the_rust_example_to_the_bit() {
    let dir = tempfile::tempdir().expect("temp dir");
    let c_exe = dir.path().join("firmware_loop_c");
    compile("examples/firmware_loop.c", &c_exe);
    let rust_exe = profile_dir().join("examples").join("firmware_loop");
    assert!(
        rust_exe.exists(),
        "{} is missing: cargo test builds the examples",
        rust_exe.display()
    );
    for seed in ["1", "2"] {
        let (c_csv, r_csv) = (dir.path().join("c.csv"), dir.path().join("r.csv"));
        let c_out = run(Command::new(&c_exe).args([seed, "--trace"]).arg(&c_csv));
        let r_out = run(Command::new(&rust_exe).args([seed, "--trace"]).arg(&r_csv));
        assert_eq!(
            printed(&c_out),
            printed(&r_out),
            "seed {seed}: printed lines"
        );
        assert!(c_out.contains("AE touchdown at"), "{c_out}");
        let (c_head, c_rows) = cells(&c_csv);
        let (r_head, r_rows) = cells(&r_csv);
        assert_eq!(c_head, r_head);
        // Ramp from 70 mW at 1 mW/ms to touchdown near 74.3 mW, then 200 periods of hold.
        assert!(c_rows.len() > 300, "seed {seed}: {} periods", c_rows.len());
        assert_eq!(c_rows.len(), r_rows.len(), "seed {seed}: periods");
        for (i, (c, r)) in c_rows.iter().zip(&r_rows).enumerate() {
            assert_eq!(c, r, "seed {seed}: period {} differs", i + 1);
        }
    }
}

/// Runs `exe` under valgrind's memcheck, when valgrind is on the machine.
fn valgrind(exe: &Path, args: &[&str]) -> bool {
    if Command::new("valgrind").arg("--version").output().is_err() {
        // Past the test harness's capture: the skip shows in the run's output.
        use std::io::Write;
        let _ = writeln!(
            std::io::stderr(),
            "valgrind is not installed: memory check of {} SKIPPED (Debian: apt-get install valgrind)",
            exe.display()
        );
        return false;
    }
    let out = Command::new("valgrind")
        .args([
            "--error-exitcode=1",
            "--leak-check=full",
            "--errors-for-leak-kinds=definite,indirect",
            "--quiet",
        ])
        .arg(exe)
        .args(args)
        .output()
        .expect("run valgrind");
    assert!(
        out.status.success(),
        "valgrind found errors in {}:\n{}",
        exe.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    true
}

#[test]
fn c_example_is_clean_under_valgrind() {
    let dir = tempfile::tempdir().expect("temp dir");
    let exe = dir.path().join("firmware_loop_c");
    compile("examples/firmware_loop.c", &exe);
    let trace = dir.path().join("trace.csv");
    valgrind(&exe, &["3", "--trace", trace.to_str().expect("UTF-8 path")]);
}

#[test]
fn misuse_gets_a_status_and_is_clean_under_valgrind() {
    let dir = tempfile::tempdir().expect("temp dir");
    let exe = dir.path().join("misuse");
    compile("tests/misuse.c", &exe);
    let scene = dir.path().join("bad.toml");
    let text = hdi_tribology::scene::Scene::paper()
        .to_toml_string()
        .expect("paper scene as TOML");
    assert!(text.contains("nominal_clearance_m = 1e-8"), "{text}");
    let text = text.replace("nominal_clearance_m = 1e-8", "nominal_clearance_nm = -3");
    std::fs::write(&scene, text).expect("write scene");
    let path = scene.to_str().expect("UTF-8 path");
    let out = run(Command::new(&exe).arg(path));
    assert!(out.ends_with("misuse: all checks passed\n"), "{out}");
    valgrind(&exe, &[path]);
}

/// The closed loop of docs/firmware.md compiles, runs, and finds the example's touchdown.
#[test]
fn the_loop_in_the_docs_runs() {
    let doc = std::fs::read_to_string(manifest_dir().join("../docs/firmware.md")).expect("docs");
    let start = doc.find("```c\n").expect("a C block") + 5;
    let end = start + doc[start..].find("```").expect("its end");
    let dir = tempfile::tempdir().expect("temp dir");
    let source = dir.path().join("loop.c");
    std::fs::write(&source, &doc[start..end]).expect("write loop.c");
    let exe = dir.path().join("loop");
    compile(source.to_str().expect("UTF-8 path"), &exe);
    let out = run(&mut Command::new(&exe));
    // With --trace the Rust example stops after its loop.
    let rust = run(
        Command::new(profile_dir().join("examples").join("firmware_loop"))
            .args(["1", "--trace"])
            .arg(dir.path().join("rust.csv")),
    );
    let td = |text: &str, key: &str| {
        let i = text.find(key).unwrap_or_else(|| panic!("{key} in {text}")) + key.len();
        text[i..].split(' ').next().unwrap().to_string()
    };
    assert_eq!(
        td(&out, "touchdown at "),
        td(&rust, "AE touchdown at "),
        "{out}"
    );
}
