//! `hdi` keeps what it is given: output paths that are links, FIFOs or existing files, one
//! permission rule, every output checked before the computation, a closed pipe, and bad inputs
//! named as the user wrote them. Everything happens in scratch directories; no real device is
//! ever given as an output.
#![cfg(all(feature = "cli", unix))]

use std::io::Read;
use std::os::unix::fs::{FileTypeExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const HDI: &str = env!("CARGO_BIN_EXE_hdi");

fn hdi(args: &[&str]) -> Output {
    Command::new(HDI)
        .args(args)
        .output()
        .expect("the hdi binary runs")
}

/// `hdi` under a given umask (set by the shell that starts it).
fn hdi_umask(umask: &str, args: &[&str]) -> Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!("umask {umask} && exec \"$0\" \"$@\""))
        .arg(HDI)
        .args(args)
        .output()
        .expect("sh runs")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn assert_ok(out: &Output) {
    assert!(out.status.success(), "{}", stderr(out));
}

/// The one line on stderr of a failed run with exit code 1.
fn failure(out: &Output) -> String {
    assert_eq!(out.status.code(), Some(1), "{}", stderr(out));
    let e = stderr(out);
    assert_eq!(e.lines().count(), 1, "one line: {e}");
    e
}

/// A fresh directory of this test's own.
fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("cli_trust_{name}_{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A short command file for `hdi drive` (two periods' worth of heater levels).
fn commands(dir: &Path) -> PathBuf {
    let p = dir.join("commands.csv");
    std::fs::write(&p, "time_s,heater_mw,voltage_dc_v\n0,60,0\n0.001,65,0\n").unwrap();
    p
}

fn mode(p: &Path) -> u32 {
    std::fs::metadata(p).unwrap().permissions().mode() & 0o7777
}

#[test]
fn a_symlink_as_output_is_written_through_and_stays_a_link() {
    let dir = scratch("symlink");
    let target = dir.join("target.csv");
    std::fs::write(&target, "old\n").unwrap();
    let link = dir.join("link.csv");
    std::os::unix::fs::symlink("target.csv", &link).unwrap();
    assert_ok(&hdi(&[
        "cycle",
        "--paper",
        "--no-refine",
        "--csv",
        s(&link),
    ]));
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(std::fs::read_link(&link).unwrap(), Path::new("target.csv"));
    let text = std::fs::read_to_string(&target).unwrap();
    assert!(text.starts_with("t_s,power_w,d_m"), "{}", &text[..20]);
    // no temporary file left beside either
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(names, ["link.csv", "target.csv"]);

    // drive --out through a link that dangles: the target is created, the link kept
    let cmds = commands(&dir);
    let dangling = dir.join("sensors.csv");
    std::os::unix::fs::symlink("made/by/link.csv", &dangling).unwrap();
    std::fs::create_dir_all(dir.join("made/by")).unwrap();
    assert_ok(&hdi(&[
        "drive",
        "--paper",
        "--flat-disk",
        "--commands",
        s(&cmds),
        "--out",
        s(&dangling),
    ]));
    assert!(std::fs::symlink_metadata(&dangling)
        .unwrap()
        .file_type()
        .is_symlink());
    let text = std::fs::read_to_string(dir.join("made/by/link.csv")).unwrap();
    assert!(text.starts_with("time_s,heater_mw"), "{text}");
}

#[test]
fn a_link_loop_is_refused_before_the_computation() {
    let dir = scratch("loop");
    std::os::unix::fs::symlink("b.csv", dir.join("a.csv")).unwrap();
    std::os::unix::fs::symlink("a.csv", dir.join("b.csv")).unwrap();
    let e = failure(&hdi(&["cycle", "--paper", "--csv", s(&dir.join("a.csv"))]));
    assert!(e.contains("--csv") && e.contains("symbolic links"), "{e}");
}

/// Makes a FIFO with mkfifo(1).
fn mkfifo(p: &Path) {
    let ok = Command::new("mkfifo").arg(p).status().unwrap().success();
    assert!(ok, "mkfifo {}", p.display());
}

/// Runs `hdi args` while a thread reads `fifo`; returns hdi's output and what the reader got.
/// Bounded: hdi is killed after 120 s, and a reader still waiting is released.
fn through_fifo(fifo: &Path, args: &[&str]) -> (Output, Vec<u8>) {
    let (tx, rx) = std::sync::mpsc::channel();
    let path = fifo.to_path_buf();
    std::thread::spawn(move || {
        let mut got = Vec::new();
        let r = std::fs::File::open(&path).and_then(|mut f| f.read_to_end(&mut got));
        tx.send(r.map(|_| got)).ok();
    });
    let mut child = Command::new(HDI)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let deadline = Instant::now() + Duration::from_secs(120);
    while child.try_wait().unwrap().is_none() {
        if Instant::now() > deadline {
            child.kill().ok();
            panic!("hdi did not finish writing into the FIFO within 120 s");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().unwrap();
    let got = match rx.recv_timeout(Duration::from_secs(2)) {
        Ok(r) => r.unwrap(),
        Err(_) => {
            // hdi never opened the FIFO: release the reader, which then reads nothing
            drop(std::fs::OpenOptions::new().write(true).open(fifo));
            rx.recv_timeout(Duration::from_secs(10)).unwrap().unwrap()
        }
    };
    (out, got)
}

#[test]
fn a_fifo_as_output_is_written_into_not_replaced() {
    let dir = scratch("fifo");
    let fifo = dir.join("pipe.csv");
    mkfifo(&fifo);
    let (out, got) = through_fifo(
        &fifo,
        &["cycle", "--paper", "--no-refine", "--csv", s(&fifo)],
    );
    assert_ok(&out);
    assert!(std::fs::symlink_metadata(&fifo)
        .unwrap()
        .file_type()
        .is_fifo());
    let text = String::from_utf8(got).unwrap();
    assert!(text.starts_with("t_s,power_w,d_m"), "{text:.40}");
    assert!(text.lines().count() > 100);

    // drive --out likewise; the JSON summary still goes to standard output
    let cmds = commands(&dir);
    let (out, got) = through_fifo(
        &fifo,
        &[
            "drive",
            "--paper",
            "--flat-disk",
            "--commands",
            s(&cmds),
            "--out",
            s(&fifo),
        ],
    );
    assert_ok(&out);
    assert!(std::fs::symlink_metadata(&fifo)
        .unwrap()
        .file_type()
        .is_fifo());
    assert!(String::from_utf8(got).unwrap().starts_with("time_s,"));
    let _: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
}

#[test]
fn a_socket_or_directory_as_output_is_refused_before_the_computation() {
    let dir = scratch("socket");
    let sock = dir.join("s.csv");
    let _listener = std::os::unix::net::UnixListener::bind(&sock).unwrap();
    let t = Instant::now();
    let e = failure(&hdi(&["cycle", "--paper", "--csv", s(&sock)]));
    assert!(e.contains("--csv") && e.contains("a socket"), "{e}");
    assert!(std::fs::symlink_metadata(&sock)
        .unwrap()
        .file_type()
        .is_socket());
    let e = failure(&hdi(&["cycle", "--paper", "--csv", s(&dir)]));
    assert!(e.contains("is a directory"), "{e}");
    // refused before the refined cycle (seconds) ran
    assert!(t.elapsed() < Duration::from_secs(60));
}

#[test]
fn one_permission_rule_for_every_output() {
    let dir = scratch("perm");
    let cmds = commands(&dir);
    for (umask, want) in [("022", 0o644), ("077", 0o600), ("002", 0o664)] {
        let csv = dir.join(format!("cycle_{umask}.csv"));
        assert_ok(&hdi_umask(
            umask,
            &["cycle", "--paper", "--no-refine", "--csv", s(&csv)],
        ));
        assert_eq!(mode(&csv), want, "cycle --csv under umask {umask}");
        let out = dir.join(format!("drive_{umask}.csv"));
        assert_ok(&hdi_umask(
            umask,
            &[
                "drive",
                "--paper",
                "--flat-disk",
                "--commands",
                s(&cmds),
                "--out",
                s(&out),
            ],
        ));
        assert_eq!(mode(&out), want, "drive --out under umask {umask}");
    }
    // a file that exists keeps its permissions, whatever the umask
    let kept = dir.join("kept.csv");
    std::fs::write(&kept, "old\n").unwrap();
    std::fs::set_permissions(&kept, std::fs::Permissions::from_mode(0o640)).unwrap();
    assert_ok(&hdi_umask(
        "077",
        &["cycle", "--paper", "--no-refine", "--csv", s(&kept)],
    ));
    assert_eq!(mode(&kept), 0o640);
    assert!(std::fs::read_to_string(&kept).unwrap().starts_with("t_s,"));
}

#[test]
fn fit_plot_onto_a_file_fails_before_the_fit() {
    let dir = scratch("fitplot");
    let file = dir.join("plots");
    std::fs::write(&file, "not a folder\n").unwrap();
    // The data file does not exist: a check after reading the data would name it instead.
    let missing = dir.join("missing.csv");
    let e = failure(&hdi(&[
        "fit",
        "--paper",
        "--data",
        s(&missing),
        "--free",
        "height_sigma_nm",
        "--plot",
        s(&file),
    ]));
    assert!(
        e.contains("--plot") && e.contains("is a file") && !e.contains("missing"),
        "{e}"
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "not a folder\n");
    let under = file.join("sub");
    let e = failure(&hdi(&[
        "fit",
        "--paper",
        "--data",
        s(&missing),
        "--free",
        "height_sigma_nm",
        "--plot",
        s(&under),
    ]));
    assert!(e.contains("--plot") && e.contains("not a folder"), "{e}");
}

#[test]
fn a_closed_pipe_ends_quietly() {
    for args in [
        &["scene", "--paper"][..],
        &["forces", "--paper", "--gaps-nm", "1,2,3"][..],
    ] {
        let mut child = Command::new(HDI)
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // The reader goes before hdi writes anything.
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        assert_eq!(out.status.code(), Some(0), "{args:?}: {}", stderr(&out));
        assert_eq!(stderr(&out), "", "{args:?}");
    }
}

/// The shipped paper scene with `key = …` (the first line that starts so) set to `value`.
fn paper_with(key: &str, value: &str) -> String {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/paper.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let mut done = false;
    let lines: Vec<String> = text
        .lines()
        .map(|l| {
            if !done && l.starts_with(&format!("{key} = ")) {
                done = true;
                value.to_string()
            } else {
                l.to_string()
            }
        })
        .collect();
    assert!(done, "no {key} in the paper scene");
    lines.join("\n")
}

#[test]
fn absurd_scene_values_are_refused_naming_the_field_as_written() {
    let dir = scratch("scenes");
    let cases = [
        (
            "stiffness_n_per_m",
            "stiffness_n_per_m = 1e300",
            "static",
            "air_bearing.stiffness_n_per_m: is 1e300 N/m, above 1e10 N/m",
        ),
        (
            "nominal_clearance_m",
            "nominal_clearance_m = 1e300",
            "static",
            "nominal_clearance_m: must lie between 1e-10 m and 1e-6 m, got 1e300 m",
        ),
        (
            "nominal_clearance_m",
            "nominal_clearance_nm = 1e-8",
            "static",
            "nominal_clearance_nm: must lie between 0.1 nm and 1000 nm, got 1e-8 nm",
        ),
        (
            "rtol",
            "rtol = 1e-20",
            "static",
            "solver.rtol: must lie in [2.2e-14, 1)",
        ),
        (
            "method",
            "method = \"euler\"",
            "scene",
            "solver.method: unknown method \"euler\", expected one of",
        ),
    ];
    for (i, (key, line, cmd, want)) in cases.into_iter().enumerate() {
        let path = dir.join(format!("bad{i}.toml"));
        std::fs::write(&path, paper_with(key, line)).unwrap();
        let e = failure(&hdi(&[cmd, s(&path)]));
        assert!(e.contains(want), "{line}: {e}");
    }
}

#[test]
fn command_line_values_have_the_bounds_of_scenes() {
    let cases = [
        (
            &["cycle", "--paper", "--v-ac", "1e6"][..],
            "'--v-ac <V>': must be at most 1000 V",
        ),
        (
            &["sweep", "--paper", "--v-ac", "0,2000"][..],
            "entry 2: must be at most 1000 V",
        ),
        (
            &["calibrate", "--paper", "--dither-v", "1001"][..],
            "'--dither-v <V>': must be at most 1000 V",
        ),
        // a range error, as for --step-mw -1, not a parse error
        (
            &["cycle", "--paper", "--rtol", "-1"][..],
            "invalid value '-1' for '--rtol <R>': must lie in [2.2e-14, 1)",
        ),
        (
            &["calibrate", "--paper", "--step-mw", "-1"][..],
            "invalid value '-1' for '--step-mw <MW>': must be > 0",
        ),
        // the refined runs tighten tenfold: the last one must stay in range too
        (
            &["cycle", "--paper", "--rtol", "1e-11"][..],
            "--rtol 1e-11 with --max-runs 5 tightens to rtol 1e-15 in the last run",
        ),
    ];
    for (args, want) in cases {
        let out = hdi(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(want), "{args:?}: {}", stderr(&out));
    }
    // --help states the same range
    let help = String::from_utf8(hdi(&["cycle", "--help"]).stdout).unwrap();
    assert!(help.contains("in [2.2e-14, 1)"), "{help}");
}

#[test]
fn bad_command_files_are_refused_naming_file_line_and_column() {
    let dir = scratch("commands");
    let cases = [
        (
            "time_s,heater_mw,voltage_dc_v,voltage_ac\n0,60,0,1\n0.001,60,0,1\n",
            "line 1, column 4 `voltage_ac`: is not a command column",
        ),
        (
            "time_s,heater_mw,voltage_dc_v\n0,60,0\n0.001,1065,0\n0.002,60,0\n",
            "line 3, heater_mw: must be in [0, 1000] mW (far above any fly-height heater), got \
             1065 mW",
        ),
        (
            "time_s,heater_mw,voltage_dc_v\n0,60,0\n0.001,x,0\n",
            "line 3, heater_mw: `x` is not a number (mW)",
        ),
        (
            "time_s,heater_mw,voltage_dc_v\n0,60,0\n0.001,60\n",
            "line 3: has 2 fields, the header 3",
        ),
        (
            "time_s,heater_mw\n0,60\n0.001,60\n",
            "line 1: the column voltage_dc_v (V) is missing",
        ),
        (
            "time_s,heater_mw,voltage_dc_v\n0,60,0\n0.001,,0\n",
            "line 3, heater_mw: is empty (mW)",
        ),
        (
            "time_s,heater_mw,voltage_dc_v,voltage_ac_v\n0,60,0,2000\n0.001,60,0,0\n",
            "line 2, voltage_ac_v: must be in [0, 1000] V",
        ),
        (
            "time_s,heater_mw,voltage_dc_v\n0,60,0\n0.00102,60,0\n",
            "the last row's time_s: 0.00102 s is 20.4 periods of 50 µs, not a whole number: end \
             at 0.001 s or 0.00105 s",
        ),
    ];
    for (i, (text, want)) in cases.into_iter().enumerate() {
        let path = dir.join(format!("c{i}.csv"));
        std::fs::write(&path, text).unwrap();
        let e = failure(&hdi(&["drive", "--paper", "--commands", s(&path)]));
        assert!(
            e.contains(&format!("c{i}.csv")) && e.contains(want),
            "{text:?}: {e}"
        );
        assert!(!e.contains("CSV") && !e.contains("deserialize"), "{e}");
    }
}

#[test]
fn a_high_pass_take_off_without_dither_is_flagged() {
    let flags = |dither: &str, detector: &str| {
        let out = hdi(&[
            "calibrate",
            "--paper",
            "--detector",
            detector,
            "--dither-v",
            dither,
        ]);
        assert_ok(&out);
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (v["flags"].clone(), stderr(&out))
    };
    let (f, e) = flags("0", "ae");
    assert_eq!(f, serde_json::json!(["takeoff_without_dither"]), "{e}");
    assert!(
        e.contains("is not a take-off") && e.contains("--detector mean"),
        "{e}"
    );
    // with a dither, and with the mean detector, nothing to flag
    assert_eq!(flags("0.5", "ae").0, serde_json::json!([]));
    assert_eq!(flags("0", "mean").0, serde_json::json!([]));
}

#[test]
fn static_without_take_off_reports_touchdown_and_a_null_take_off() {
    let dir = scratch("no_takeoff");
    // Ten times the paper's Hamaker constant: adhesion holds the head down to zero power.
    let path = dir.join("sticky.toml");
    std::fs::write(
        &path,
        paper_with("hamaker_attractive_j", "hamaker_attractive_j = 1e-18"),
    )
    .unwrap();
    let out = hdi(&["static", s(&path)]);
    assert_ok(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let td = v["touchdown"]["power_w"].as_f64().unwrap();
    assert!(td > 0.0 && td < 0.1, "{td}");
    assert!(v["takeoff"].is_null() && v["hysteresis_w"].is_null(), "{v}");
    assert_eq!(v["status"], "converged");
    assert_eq!(v["flags"], serde_json::json!(["no_takeoff"]));
    assert!(
        stderr(&out).contains("adhesion holds it"),
        "{}",
        stderr(&out)
    );
}

/// A command file of 8 s: 160000 periods at 20 kHz, several seconds of `hdi drive` even on a
/// fast machine (progress shows after one).
fn long_commands(dir: &Path) -> PathBuf {
    let p = dir.join("long.csv");
    std::fs::write(&p, "time_s,heater_mw,voltage_dc_v\n0,60,0\n8,65,0\n").unwrap();
    p
}

#[test]
fn no_progress_when_stderr_is_not_a_terminal() {
    let dir = scratch("progress_pipe");
    let cmds = long_commands(&dir);
    let t = Instant::now();
    let out = hdi(&[
        "drive",
        "--paper",
        "--commands",
        s(&cmds),
        "--out",
        s(&dir.join("d.csv")),
    ]);
    assert_ok(&out);
    assert!(
        t.elapsed() > Duration::from_secs(1),
        "the run is long enough to show progress"
    );
    assert_eq!(stderr(&out), "");
}

/// `hdi args` on a pseudo-terminal made by script(1); what the terminal showed, or None when
/// script(1) is not installed.
fn on_a_terminal(dir: &Path, args: &[&str]) -> Option<String> {
    let log = dir.join("terminal.txt");
    let line = std::iter::once(HDI)
        .chain(args.iter().copied())
        .map(|a| format!("'{a}'"))
        .collect::<Vec<_>>()
        .join(" ");
    let status = Command::new("script")
        .args(["-q", "-e", "-c", &format!("{line} >/dev/null"), s(&log)])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .status()
        .ok()?;
    assert!(status.success());
    Some(String::from_utf8_lossy(&std::fs::read(&log).unwrap()).into_owned())
}

#[test]
fn progress_on_a_terminal_and_quiet_silences_it() {
    let dir = scratch("progress_tty");
    let cmds = long_commands(&dir);
    let out = dir.join("d.csv");
    let args = ["drive", "--paper", "--commands", s(&cmds), "--out", s(&out)];
    let Some(shown) = on_a_terminal(&dir, &args) else {
        eprintln!("script(1) is not installed: the terminal case is not checked");
        return;
    };
    assert!(shown.contains("/160001 lines"), "{shown}");
    let quiet: Vec<&str> = args.iter().copied().chain(["--quiet"]).collect();
    let shown = on_a_terminal(&dir, &quiet).unwrap();
    assert!(!shown.contains("lines"), "{shown}");
}
