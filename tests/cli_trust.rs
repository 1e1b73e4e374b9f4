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
    let e = failure(&hdi(&[
        "cycle",
        "--paper",
        "--csv",
        s(&dir.join("a.csv")),
    ]));
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
    let (out, got) = through_fifo(&fifo, &["cycle", "--paper", "--no-refine", "--csv", s(&fifo)]);
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
    assert!(std::fs::read_to_string(&kept)
        .unwrap()
        .starts_with("t_s,"));
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
