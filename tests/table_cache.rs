//! The table cache: tables read back give the same forces to the bit; a corrupt, truncated,
//! stale or foreign entry is found, reported and rebuilt; concurrent writers leave a valid
//! entry; the bounds hold; a cache that is off writes nothing. Every cache lives in a
//! temporary folder given through the API.

use std::path::{Path, PathBuf};
use std::process::Command;

use hdi_tribology::analysis::{touchdown_power, StaticOptions};
use hdi_tribology::cache::{CacheReport, TableCache, FORMAT_VERSION};
use hdi_tribology::force::Gaps;
use hdi_tribology::model::SliderModel;
use hdi_tribology::scene::Scene;

/// Every interface value the model gives on a grid over and beyond its table range, as text
/// (Rust prints each number so that it reads back to the same bits).
fn fingerprint(model: &SliderModel) -> String {
    let f = model.forces();
    let (lo, hi) = f.table_range();
    let mut out = format!("{} nodes;", f.table_nodes());
    for i in 0..=600 {
        let d = lo - 0.05 * (hi - lo) + 1.1 * (hi - lo) * f64::from(i) / 600.0;
        let g = Gaps {
            bulge: d,
            pad: d + 0.2e-9,
        };
        out += &format!(
            "{:?}{:?}{:?}{:?};",
            f.evaluate(g),
            f.values(g, 0.3),
            f.breakdown(g, 0.3),
            f.real_contact_area(g)
        );
    }
    out
}

/// A fresh folder for one test's cache.
fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("hdi-table-cache-{name}-"))
        .tempdir()
        .expect("a temporary folder")
}

fn cached(scene: &Scene, cache: &TableCache) -> (SliderModel, CacheReport) {
    SliderModel::from_scene_with_cache(scene, Some(cache)).expect("the model builds")
}

/// The one entry of `cache`.
fn only_entry(cache: &TableCache) -> PathBuf {
    let e = cache.entries();
    assert_eq!(e.len(), 1, "{e:?}");
    e[0].clone()
}

/// Builds once (cold), damages the entry with `damage`, builds again: the damage must be
/// reported with `says` in the notice, the model must be the fresh one, and the rewritten entry
/// must then be read cleanly.
fn damaged_entry_is_rebuilt(name: &str, damage: impl Fn(&Path), says: &str) {
    let dir = temp_dir(name);
    let cache = TableCache::in_dir(dir.path());
    let scene = Scene::paper();
    let fresh = fingerprint(&SliderModel::from_scene(&scene).unwrap());
    let (_, cold) = cached(&scene, &cache);
    assert!(!cold.hit && cold.notices.is_empty(), "{cold:?}");
    let path = only_entry(&cache);
    damage(&path);
    let (model, report) = cached(&scene, &cache);
    assert!(!report.hit, "{name}: a damaged entry was used");
    assert_eq!(report.notices.len(), 1, "{report:?}");
    assert!(
        report.notices[0].contains(says) && report.notices[0].contains("rebuilt"),
        "{name}: {}",
        report.notices[0]
    );
    assert_eq!(fingerprint(&model), fresh, "{name}");
    let (again, report) = cached(&scene, &cache);
    assert!(
        report.hit && report.notices.is_empty(),
        "{name}: {report:?}"
    );
    assert_eq!(fingerprint(&again), fresh, "{name}");
}

/// The offset of `needle` in `hay`.
fn find(hay: &[u8], needle: &[u8]) -> usize {
    hay.windows(needle.len())
        .position(|w| w == needle)
        .expect("the bytes are there")
}

#[test]
fn tables_read_back_give_the_same_forces_and_results_to_the_bit() {
    let dir = temp_dir("round-trip");
    let cache = TableCache::in_dir(dir.path());
    // The paper scene (one fused table) and one with the intermolecular term on the pad gap
    // (separate tables, summed ones) and a given cutoff.
    let mut pad = Scene::paper();
    let m = pad.intermolecular.as_mut().unwrap();
    m.gap = hdi_tribology::force::GapReference::Pad;
    m.cutoff_m = Some(0.3e-9);
    for scene in [Scene::paper(), pad] {
        let fresh = SliderModel::from_scene(&scene).unwrap();
        let (cold, first) = cached(&scene, &cache);
        let (warm, second) = cached(&scene, &cache);
        assert!(!first.hit && first.notices.is_empty(), "{first:?}");
        assert!(second.hit && second.notices.is_empty(), "{second:?}");
        assert_eq!(first.path, second.path);
        assert!(second.path.as_ref().unwrap().starts_with(dir.path()));
        let expected = fingerprint(&fresh);
        assert_eq!(fingerprint(&cold), expected);
        assert_eq!(fingerprint(&warm), expected);
        // An analysis on the tables read back: the same root, to the bit.
        let opts = StaticOptions::new(scene.detector.contact_threshold_n);
        let a = touchdown_power(&fresh, &opts).unwrap();
        let b = touchdown_power(&warm, &opts).unwrap();
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
    }
    assert_eq!(cache.entries().len(), 2);
}

#[test]
fn the_interface_alone_reads_the_same_entry() {
    let dir = temp_dir("interface");
    let cache = TableCache::in_dir(dir.path());
    let scene = Scene::paper();
    let (_, cold) = cached(&scene, &cache);
    let (forces, report) = scene.build_interface_cached(&cache).unwrap();
    assert!(report.hit && report.path == cold.path);
    let fresh = scene.build_interface().unwrap();
    for i in 0..200 {
        let g = Gaps::same(-3e-9 + 1.6e-10 * f64::from(i));
        assert_eq!(
            format!("{:?}", forces.breakdown(g, 0.5)),
            format!("{:?}", fresh.breakdown(g, 0.5))
        );
    }
}

#[test]
fn a_corrupted_byte_is_found_and_rebuilt() {
    // In the payload: its checksum no longer matches.
    damaged_entry_is_rebuilt(
        "payload-byte",
        |p| {
            let mut b = std::fs::read(p).unwrap();
            let n = b.len();
            b[n - 1000] ^= 0x10;
            std::fs::write(p, b).unwrap();
        },
        "checksum",
    );
    // In the stored checksum itself.
    damaged_entry_is_rebuilt(
        "checksum-byte",
        |p| {
            let mut b = std::fs::read(p).unwrap();
            let at = find(&b, b"\ninputs ") + 8;
            let key_end = at + find(&b[at..], b"}\n") + 2;
            b[key_end + 8 + 5] ^= 0x01; // after the payload's length
            std::fs::write(p, b).unwrap();
        },
        "checksum",
    );
    // In the magic.
    damaged_entry_is_rebuilt(
        "magic-byte",
        |p| {
            let mut b = std::fs::read(p).unwrap();
            b[2] ^= 0x20;
            std::fs::write(p, b).unwrap();
        },
        "not a table cache entry",
    );
}

#[test]
fn a_truncated_or_lengthened_entry_is_found_and_rebuilt() {
    for keep in [0usize, 5, 60, 4000] {
        damaged_entry_is_rebuilt(
            &format!("truncated-{keep}"),
            |p| {
                let b = std::fs::read(p).unwrap();
                std::fs::write(p, &b[..keep.min(b.len())]).unwrap();
            },
            "truncated",
        );
    }
    damaged_entry_is_rebuilt(
        "one-byte-short",
        |p| {
            let b = std::fs::read(p).unwrap();
            std::fs::write(p, &b[..b.len() - 1]).unwrap();
        },
        "truncated",
    );
    damaged_entry_is_rebuilt(
        "one-byte-long",
        |p| {
            let mut b = std::fs::read(p).unwrap();
            b.push(0);
            std::fs::write(p, b).unwrap();
        },
        "wrong length",
    );
}

#[test]
fn an_entry_of_another_version_is_stale_and_rebuilt() {
    // Another format version (the four bytes after the magic).
    damaged_entry_is_rebuilt(
        "format",
        |p| {
            let mut b = std::fs::read(p).unwrap();
            assert_eq!(b[8..12], FORMAT_VERSION.to_le_bytes());
            b[8..12].copy_from_slice(&(FORMAT_VERSION + 1).to_le_bytes());
            std::fs::write(p, b).unwrap();
        },
        "stale (entry format",
    );
    // Another crate version in the key (same length, so only the key differs).
    damaged_entry_is_rebuilt(
        "crate-version",
        |p| {
            let mut b = std::fs::read(p).unwrap();
            let line = format!("version {}\n", env!("CARGO_PKG_VERSION"));
            let at = find(&b, line.as_bytes()) + 8;
            for x in &mut b[at..at + line.len() - 9] {
                if x.is_ascii_digit() {
                    *x = if *x == b'9' { b'0' } else { *x + 1 };
                }
            }
            std::fs::write(p, b).unwrap();
        },
        "stale (written by hdi-tribology",
    );
    // Another build of the same version (the digest of its sources).
    damaged_entry_is_rebuilt(
        "sources",
        |p| {
            let mut b = std::fs::read(p).unwrap();
            let at = find(&b, b"\nsources ") + 9;
            b[at] = if b[at] == b'0' { b'1' } else { b'0' };
            std::fs::write(p, b).unwrap();
        },
        "key differs",
    );
}

#[test]
fn an_entry_for_other_inputs_is_never_used() {
    // The entry of one scene put at the path of another's: its key differs.
    let dir = temp_dir("wrong-key");
    let cache = TableCache::in_dir(dir.path());
    let paper = Scene::paper();
    let mut other = Scene::paper();
    other.table.rel_tol = 1e-8;
    let (_, a) = cached(&paper, &cache);
    let (_, b) = cached(&other, &cache);
    let (pa, pb) = (a.path.unwrap(), b.path.unwrap());
    assert_ne!(pa, pb);
    std::fs::copy(&pb, &pa).unwrap();
    let (model, report) = cached(&paper, &cache);
    assert!(!report.hit);
    assert!(
        report.notices.len() == 1 && report.notices[0].contains("key differs"),
        "{report:?}"
    );
    let fresh = SliderModel::from_scene(&paper).unwrap();
    assert_eq!(fingerprint(&model), fingerprint(&fresh));
    // A change that the tables do not depend on shares the entry.
    let mut volts = Scene::paper();
    volts.voltage.dc_v = 2.0;
    volts.electrostatic.as_mut().unwrap().contact_potential_v = 0.3;
    let (_, shared) = cached(&volts, &cache);
    assert!(shared.hit && shared.path.as_deref() == Some(pa.as_path()));
}

#[test]
fn a_path_that_is_not_a_regular_file_is_left_alone() {
    let dir = temp_dir("not-a-file");
    let cache = TableCache::in_dir(dir.path());
    let scene = Scene::paper();
    let (_, cold) = cached(&scene, &cache);
    let path = cold.path.unwrap();
    std::fs::remove_file(&path).unwrap();
    std::fs::create_dir(&path).unwrap();
    let (model, report) = cached(&scene, &cache);
    assert!(!report.hit && report.notices.len() == 1, "{report:?}");
    assert!(report.notices[0].contains("not a regular file"));
    assert!(path.is_dir(), "the folder was replaced");
    assert_eq!(
        fingerprint(&model),
        fingerprint(&SliderModel::from_scene(&scene).unwrap())
    );
}

#[test]
fn writers_at_once_leave_a_valid_entry() {
    let dir = temp_dir("threads");
    let scene = Scene::paper();
    let fresh = fingerprint(&SliderModel::from_scene(&scene).unwrap());
    let reports: Vec<CacheReport> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..4)
            .map(|_| {
                let (scene, dir) = (&scene, dir.path());
                s.spawn(move || cached(scene, &TableCache::in_dir(dir)).1)
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for r in &reports {
        assert!(r.notices.is_empty(), "{r:?}");
    }
    let cache = TableCache::in_dir(dir.path());
    only_entry(&cache);
    let (model, report) = cached(&scene, &cache);
    assert!(report.hit && report.notices.is_empty(), "{report:?}");
    assert_eq!(fingerprint(&model), fresh);
    // No temporary file is left behind.
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().flatten().collect();
    assert_eq!(names.len(), 1, "{names:?}");
}

/// Run by [`processes_writing_at_once_leave_a_valid_entry`] in child processes: builds the
/// paper scene's model through the cache in `HDI_TEST_CACHE_DIR` and fails on any notice.
#[test]
#[ignore = "a child of processes_writing_at_once_leave_a_valid_entry"]
fn child_writes_the_paper_tables() {
    let Some(dir) = std::env::var_os("HDI_TEST_CACHE_DIR") else {
        return;
    };
    let (_, report) = cached(&Scene::paper(), &TableCache::in_dir(dir));
    assert!(report.notices.is_empty(), "{report:?}");
}

#[test]
fn processes_writing_at_once_leave_a_valid_entry() {
    let dir = temp_dir("processes");
    let me = std::env::current_exe().unwrap();
    // The child's full name in this test program: `<file>::<test>`, this file being a module of
    // the program (module_path!() starts with the program's own name).
    let child = match module_path!().split_once("::") {
        Some((_, file)) => format!("{file}::child_writes_the_paper_tables"),
        None => "child_writes_the_paper_tables".to_string(),
    };
    let children: Vec<_> = (0..3)
        .map(|_| {
            Command::new(&me)
                .args(["--exact", child.as_str(), "--ignored", "--test-threads=1"])
                .env("HDI_TEST_CACHE_DIR", dir.path())
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    for c in children {
        let out = c.wait_with_output().unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success() && text.contains("1 passed"),
            "{text}{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let cache = TableCache::in_dir(dir.path());
    only_entry(&cache);
    let (model, report) = cached(&Scene::paper(), &cache);
    assert!(report.hit && report.notices.is_empty(), "{report:?}");
    assert_eq!(
        fingerprint(&model),
        fingerprint(&SliderModel::from_scene(&Scene::paper()).unwrap())
    );
}

#[test]
fn the_cache_keeps_within_its_bounds_evicting_the_least_recently_used() {
    let dir = temp_dir("bounds");
    let cache = TableCache::in_dir(dir.path())
        .with_limits(2, u64::MAX)
        .unwrap();
    let scene = |rel_tol: f64| {
        let mut s = Scene::paper();
        s.table.rel_tol = rel_tol;
        s
    };
    let path = |s: &Scene| cached(s, &cache).1.path.unwrap();
    let (a, b, c) = (scene(1e-6), scene(1e-7), scene(1e-8));
    let size = |p: &Path| std::fs::metadata(p).unwrap().len();
    let pa = path(&a);
    std::thread::sleep(std::time::Duration::from_millis(20));
    let pb = path(&b);
    let sizes = [size(&pa), size(&pb)];
    std::thread::sleep(std::time::Duration::from_millis(20));
    // Reading `a` again makes it the most recently used: `b` goes when `c` comes.
    assert!(cached(&a, &cache).1.hit);
    std::thread::sleep(std::time::Duration::from_millis(20));
    let pc = path(&c);
    let mut kept = cache.entries();
    kept.sort();
    let mut want = vec![pa, pc];
    want.sort();
    assert_eq!(kept, want);
    assert!(!pb.exists());
    // A byte bound: the entries kept, the one just written among them, stay within it.
    let bound = sizes[0].max(sizes[1]).max(size(&want[1])) + 1;
    let bytes = TableCache::in_dir(dir.path())
        .with_limits(10, bound)
        .unwrap();
    let (_, r) = cached(&b, &bytes);
    let kept = bytes.entries();
    assert!(
        kept.contains(&r.path.unwrap()) && kept.len() < 3,
        "{kept:?}"
    );
    assert!(kept.iter().map(|p| size(p)).sum::<u64>() <= bound);
    // An entry larger than the whole bound is not stored, and says so.
    let tiny = TableCache::in_dir(dir.path())
        .with_limits(10, 1000)
        .unwrap();
    let (_, r) = cached(&a, &tiny);
    assert!(!r.hit && r.notices.len() == 1 && r.notices[0].contains("bound"));
    assert_eq!(tiny.clear().unwrap(), 1);
    assert!(tiny.entries().is_empty());
}

#[test]
fn a_cache_that_is_off_writes_nothing() {
    let dir = temp_dir("off");
    let vars = |pairs: Vec<(&'static str, PathBuf)>| {
        move |k: &str| {
            pairs
                .iter()
                .find(|(n, _)| *n == k)
                .map(|(_, v)| v.clone().into_os_string())
        }
    };
    let home = dir.path().join("home");
    let given = dir.path().join("given");
    for off in ["off", "OFF", "0"] {
        let c = TableCache::from_vars(vars(vec![
            ("HOME", home.clone()),
            ("HDI_CACHE_DIR", given.clone()),
            ("HDI_CACHE", off.into()),
        ]))
        .unwrap();
        assert!(c.is_none(), "HDI_CACHE={off}");
        let (model, report) =
            SliderModel::from_scene_with_cache(&Scene::paper(), c.as_ref()).unwrap();
        assert_eq!(report, CacheReport::default());
        assert!(model.forces().table_nodes() > 0);
    }
    assert!(std::fs::read_dir(dir.path()).unwrap().next().is_none());
    // On: the folder given, else the user's cache folder under HOME.
    let on = TableCache::from_vars(vars(vec![
        ("HOME", home.clone()),
        ("HDI_CACHE_DIR", given.clone()),
        ("HDI_CACHE", "on".into()),
    ]))
    .unwrap()
    .unwrap();
    assert_eq!(on.dir(), given);
    let user = TableCache::from_vars(vars(vec![("HOME", home.clone())]))
        .unwrap()
        .unwrap();
    assert_eq!(user.dir(), home.join(".cache").join("hdi-tribology"));
    // A relative XDG_CACHE_HOME is ignored, as the XDG specification asks.
    let rel = TableCache::from_vars(vars(vec![
        ("HOME", home.clone()),
        ("XDG_CACHE_HOME", "relative".into()),
    ]))
    .unwrap()
    .unwrap();
    assert_eq!(rel.dir(), user.dir());
    let err = TableCache::from_vars(vars(vec![("HDI_CACHE", "sometimes".into())]))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("HDI_CACHE") && err.contains("sometimes"),
        "{err}"
    );
}

/// `hdi --no-cache` and `HDI_CACHE=off` write nothing; `hdi` otherwise writes one entry, reads
/// it on the next run, and prints the same results.
#[cfg(feature = "cli")]
#[test]
fn the_program_uses_the_cache_unless_told_not_to() {
    let dir = temp_dir("cli");
    let run = |args: &[&str], env: &[(&str, &str)]| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_hdi"));
        c.args(args).env("HDI_CACHE_DIR", dir.path());
        for (k, v) in env {
            c.env(k, v);
        }
        let out = c.output().unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(String::from_utf8_lossy(&out.stderr), "");
        out.stdout
    };
    let empty = || std::fs::read_dir(dir.path()).unwrap().next().is_none();
    let args = ["forces", "--paper", "--gaps-nm", "-1,0.5,2,7"];
    let fresh = run(
        &["--no-cache", "forces", "--paper", "--gaps-nm", "-1,0.5,2,7"],
        &[],
    );
    assert!(empty());
    assert_eq!(run(&args, &[("HDI_CACHE", "off")]), fresh);
    assert!(empty());
    assert_eq!(run(&args, &[]), fresh);
    let cache = TableCache::in_dir(dir.path());
    let entry = only_entry(&cache);
    let written = std::fs::read(&entry).unwrap();
    assert_eq!(run(&args, &[]), fresh);
    assert_eq!(std::fs::read(&entry).unwrap(), written);
    // A damaged entry: a warning, the same results, and the entry rewritten.
    std::fs::write(&entry, &written[..100]).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_hdi"))
        .args(args)
        .env("HDI_CACHE_DIR", dir.path())
        .output()
        .unwrap();
    assert!(out.status.success());
    assert_eq!(out.stdout, fresh);
    let warn = String::from_utf8_lossy(&out.stderr);
    assert!(
        warn.starts_with("hdi: warning: table cache entry") && warn.contains("truncated"),
        "{warn}"
    );
    assert_eq!(std::fs::read(&entry).unwrap(), written);
}
