//! A disk cache of the force tables: a warm start for programs that build a scene's model again
//! and again (each `hdi` run, a script run per point).
//!
//! Building a [`SliderModel`](crate::model::SliderModel) tabulates the scene's interface forces
//! (and the lubricant menisci) by quadrature: 0.1–0.4 s for the paper scene, far more than one
//! cycle takes. [`SliderModel::from_scene_with_cache`](crate::model::SliderModel::from_scene_with_cache)
//! reads them from a [`TableCache`] instead when an entry for the same inputs is there, and
//! writes one when it is not. The tables read back are the tables built, to the bit, so every
//! result is the same.
//!
//! # Keys
//!
//! An entry's key is a text naming exactly what the tables depend on: the scene fields that the
//! tabulated terms are built from (the `[intermolecular]`, `[electrostatic]` (without its contact
//! potential), `[contact]` and `[lubricant]` sections, the surface statistics they use), the
//! table range and options; plus the format version of entries ([`FORMAT_VERSION`]), the
//! crate's version and a digest of the crate's sources and lock file taken when it was built (so
//! that a changed build never reads tables of another). The entry's file name is the first 128
//! bits of the SHA-256 of the key, in hexadecimal, with `.tbl` after it.
//!
//! # Entries
//!
//! One file per key, little-endian throughout:
//!
//! | bytes | what |
//! |---|---|
//! | 8 | the magic `HDITBLC` and a newline |
//! | 4 | [`FORMAT_VERSION`] |
//! | 8 + k | the key's length `k`, then the key (UTF-8) |
//! | 8 | the payload's length `n` |
//! | 32 | the SHA-256 of the payload |
//! | n | the payload: the tables, every number as its `f64` bit pattern |
//!
//! On reading, the magic, version, key, length and checksum must all agree, and the payload must
//! decode into tables whose every look-up stays inside them: otherwise the entry is corrupt,
//! truncated or stale, the tables are built afresh and written over it, and the
//! [`CacheReport`] says so (`hdi` prints it as a warning). An entry is never trusted on less.
//!
//! Writes go to a temporary file in the cache directory, which is then renamed over the entry:
//! a reader sees the old entry or the new one, never a mix, and two processes writing the same
//! entry at once leave one of their two (identical) entries. A path that is not a regular file is
//! never read nor replaced. After a write the cache keeps its newest entries (by last use) within
//! [`TableCache::with_limits`]'s bounds, [`DEFAULT_MAX_ENTRIES`] entries and
//! [`DEFAULT_MAX_BYTES`] bytes by default, and removes the rest.
//!
//! ```
//! use hdi_tribology::{cache::TableCache, model::SliderModel, scene::Scene};
//! # fn main() -> hdi_tribology::Result<()> {
//! let dir = std::env::temp_dir().join(format!("hdi-cache-doc-{}", std::process::id()));
//! let cache = TableCache::in_dir(&dir);
//! let scene = Scene::paper();
//! let (cold, first) = SliderModel::from_scene_with_cache(&scene, Some(&cache))?;
//! let (warm, second) = SliderModel::from_scene_with_cache(&scene, Some(&cache))?;
//! assert!(!first.hit && second.hit && second.notices.is_empty());
//! assert_eq!(cold.forces().table_nodes(), warm.forces().table_nodes());
//! # std::fs::remove_dir_all(&dir).ok();
//! # Ok(()) }
//! ```

pub(crate) mod codec;
pub(crate) mod sha256;

use std::ffi::OsString;
use std::fs;
use std::io::{ErrorKind, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, SystemTime};

use crate::{Error, Result};

/// The version of the entry layout and payload; entries of another version are stale.
pub const FORMAT_VERSION: u32 = 2;
/// Most entries a cache keeps by default.
pub const DEFAULT_MAX_ENTRIES: usize = 64;
/// Most bytes a cache keeps by default (256 MiB); an entry larger than the bound is not stored.
pub const DEFAULT_MAX_BYTES: u64 = 256 << 20;
/// The name of the cache's folder in the user's cache directory.
pub const DIR_NAME: &str = "hdi-tribology";

/// The first bytes of every entry.
const MAGIC: &[u8; 8] = b"HDITBLC\n";
/// The suffix of entry files.
const SUFFIX: &str = "tbl";
/// The suffix of temporary files being written.
const TEMP_SUFFIX: &str = "tbl-tmp";
/// Age past which a temporary file is a leftover of a writer that died, and removed.
const STALE_TEMP: Duration = Duration::from_secs(600);
/// A digest of the crate's sources and lock file, computed by the build script.
const SOURCE_DIGEST: &str = env!("HDI_SOURCE_DIGEST");

/// A folder of table-cache entries and its bounds. Off unless a caller gives one: the library
/// builds tables afresh by default; `hdi` uses [`TableCache::from_env`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TableCache {
    dir: PathBuf,
    max_entries: usize,
    max_bytes: u64,
}

/// What a cached build did, for the caller to show.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct CacheReport {
    /// Whether the tables were read from the cache (else they were built).
    pub hit: bool,
    /// The entry's file (read, or written), `None` without a cache.
    pub path: Option<PathBuf>,
    /// Each problem met, one sentence each: an entry found corrupt, truncated or stale (and
    /// rebuilt), or one that could not be written. Empty when all went well; meant to be shown
    /// as warnings.
    pub notices: Vec<String>,
}

impl TableCache {
    /// A cache in `dir` (made when first written), with the default bounds.
    ///
    /// ```
    /// use hdi_tribology::cache::{TableCache, DEFAULT_MAX_ENTRIES};
    /// let c = TableCache::in_dir("/tmp/hdi-cache");
    /// assert_eq!(c.dir(), std::path::Path::new("/tmp/hdi-cache"));
    /// assert_eq!(c.max_entries(), DEFAULT_MAX_ENTRIES);
    /// ```
    pub fn in_dir(dir: impl Into<PathBuf>) -> Self {
        TableCache {
            dir: dir.into(),
            max_entries: DEFAULT_MAX_ENTRIES,
            max_bytes: DEFAULT_MAX_BYTES,
        }
    }

    /// The same cache keeping at most `max_entries` entries (≥ 1) and `max_bytes` bytes (≥ 1).
    ///
    /// ```
    /// use hdi_tribology::cache::TableCache;
    /// let c = TableCache::in_dir("/tmp/hdi-cache").with_limits(4, 1 << 20)?;
    /// assert_eq!((c.max_entries(), c.max_bytes()), (4, 1 << 20));
    /// assert!(TableCache::in_dir("/tmp/hdi-cache").with_limits(0, 1).is_err());
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn with_limits(self, max_entries: usize, max_bytes: u64) -> Result<Self> {
        if max_entries == 0 {
            return Err(Error::invalid("max_entries", "must be at least 1, got 0"));
        }
        if max_bytes == 0 {
            return Err(Error::invalid("max_bytes", "must be at least 1, got 0"));
        }
        Ok(TableCache {
            max_entries,
            max_bytes,
            ..self
        })
    }

    /// The cache of the process's environment, as `hdi` uses it: `None` when `HDI_CACHE` is
    /// `off` (or `0`), else in `HDI_CACHE_DIR` if set, else in `$XDG_CACHE_HOME/hdi-tribology`
    /// (an absolute `XDG_CACHE_HOME` only), else `~/.cache/hdi-tribology` (`%LOCALAPPDATA%`
    /// on Windows); `None` when there is no home either. See [`TableCache::from_vars`].
    pub fn from_env() -> Result<Option<Self>> {
        Self::from_vars(|name| std::env::var_os(name))
    }

    /// [`TableCache::from_env`] with the variables read through `var` (for tests, or to take
    /// them from elsewhere).
    ///
    /// ```
    /// use hdi_tribology::cache::TableCache;
    /// use std::{ffi::OsString, path::Path};
    /// let vars = |pairs: &'static [(&'static str, &'static str)]| {
    ///     move |k: &str| pairs.iter().find(|(n, _)| *n == k).map(|(_, v)| OsString::from(v))
    /// };
    /// let c = TableCache::from_vars(vars(&[("HOME", "/home/u")]))?.unwrap();
    /// assert_eq!(c.dir(), Path::new("/home/u/.cache/hdi-tribology"));
    /// let c = TableCache::from_vars(vars(&[("HOME", "/home/u"), ("XDG_CACHE_HOME", "/c")]))?;
    /// assert_eq!(c.unwrap().dir(), Path::new("/c/hdi-tribology"));
    /// let c = TableCache::from_vars(vars(&[("HOME", "/home/u"), ("HDI_CACHE_DIR", "/x")]))?;
    /// assert_eq!(c.unwrap().dir(), Path::new("/x"));
    /// assert!(TableCache::from_vars(vars(&[("HOME", "/home/u"), ("HDI_CACHE", "off")]))?.is_none());
    /// assert!(TableCache::from_vars(vars(&[("HDI_CACHE", "maybe")])).is_err());
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn from_vars(var: impl Fn(&str) -> Option<OsString>) -> Result<Option<Self>> {
        let set = |name: &str| var(name).filter(|v| !v.is_empty());
        if let Some(v) = set("HDI_CACHE") {
            match v.to_str().map(str::to_ascii_lowercase).as_deref() {
                Some("off" | "0" | "false" | "no") => return Ok(None),
                Some("on" | "1" | "true" | "yes") => {}
                _ => {
                    return Err(Error::invalid(
                        "HDI_CACHE",
                        format!("must be on or off, got {:?}", v.to_string_lossy()),
                    ))
                }
            }
        }
        if let Some(dir) = set("HDI_CACHE_DIR") {
            return Ok(Some(Self::in_dir(dir)));
        }
        let xdg = set("XDG_CACHE_HOME")
            .map(PathBuf::from)
            .filter(|p| p.is_absolute());
        let base = xdg
            .or_else(|| {
                if cfg!(windows) {
                    set("LOCALAPPDATA").map(PathBuf::from)
                } else {
                    None
                }
            })
            .or_else(|| set("HOME").map(|h| PathBuf::from(h).join(".cache")));
        Ok(base.map(|b| Self::in_dir(b.join(DIR_NAME))))
    }

    /// The cache's folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Most entries kept.
    pub fn max_entries(&self) -> usize {
        self.max_entries
    }

    /// Most bytes kept.
    pub fn max_bytes(&self) -> u64 {
        self.max_bytes
    }

    /// The entry files now in the cache (none when its folder does not exist).
    pub fn entries(&self) -> Vec<PathBuf> {
        let Ok(list) = fs::read_dir(&self.dir) else {
            return Vec::new();
        };
        let mut out: Vec<PathBuf> = list
            .flatten()
            .map(|e| e.path())
            .filter(|p| has_suffix(p, SUFFIX) && is_regular(p))
            .collect();
        out.sort();
        out
    }

    /// Removes every entry (and leftover temporary file); returns how many entries were removed.
    pub fn clear(&self) -> Result<usize> {
        let list = match fs::read_dir(&self.dir) {
            Ok(l) => l,
            Err(e) if e.kind() == ErrorKind::NotFound => return Ok(0),
            Err(e) => return Err(io_error(&self.dir, e)),
        };
        let mut n = 0;
        for p in list.flatten().map(|e| e.path()) {
            let entry = has_suffix(&p, SUFFIX);
            if (entry || has_suffix(&p, TEMP_SUFFIX)) && is_regular(&p) {
                match fs::remove_file(&p) {
                    Ok(()) => n += usize::from(entry),
                    Err(e) if e.kind() == ErrorKind::NotFound => {}
                    Err(e) => return Err(io_error(&p, e)),
                }
            }
        }
        Ok(n)
    }

    /// The value of `key` (a description of exactly what `build` depends on): read from the
    /// cache with `decode` when a valid entry is there, else built with `build` and stored with
    /// `encode`. A bad entry is rebuilt and said in the report, never used; failing to read or
    /// write the cache never fails the build.
    pub(crate) fn get_or_build<T>(
        &self,
        key: &str,
        decode: impl FnOnce(&[u8]) -> Result<T>,
        build: impl FnOnce() -> Result<T>,
        encode: impl FnOnce(&T) -> Vec<u8>,
    ) -> Result<(T, CacheReport)> {
        let key = full_key(key);
        let path = self.dir.join(format!(
            "{}.{SUFFIX}",
            &sha256::hex(&sha256::digest(key.as_bytes()))[..32]
        ));
        let mut report = CacheReport {
            path: Some(path.clone()),
            ..CacheReport::default()
        };
        let mut writable = true;
        match self.read(&path, &key) {
            Read::Payload(payload) => match decode(&payload) {
                Ok(value) => {
                    report.hit = true;
                    touch(&path);
                    return Ok((value, report));
                }
                Err(e) => report.notices.push(format!(
                    "table cache entry {} is corrupt ({e}); the tables were rebuilt",
                    path.display()
                )),
            },
            Read::Missing => {}
            Read::Bad(why) => report.notices.push(format!(
                "table cache entry {} is {why}; the tables were rebuilt",
                path.display()
            )),
            Read::Unusable(why) => {
                writable = false;
                report.notices.push(format!(
                    "table cache entry {} {why}; the tables were built without the cache",
                    path.display()
                ));
            }
        }
        let value = build()?;
        if writable {
            let payload = encode(&value);
            if let Err(why) = self.write(&path, &key, &payload) {
                report.notices.push(format!(
                    "could not write table cache entry {}: {why}",
                    path.display()
                ));
            } else {
                self.evict(&path);
            }
        }
        Ok((value, report))
    }

    /// The payload of the entry at `path` for `key`, or why there is none.
    fn read(&self, path: &Path, key: &str) -> Read {
        let meta = match fs::symlink_metadata(path) {
            Ok(m) => m,
            Err(e) if e.kind() == ErrorKind::NotFound => return Read::Missing,
            Err(e) => return Read::Unusable(format!("cannot be read: {e}")),
        };
        if !meta.file_type().is_file() {
            return Read::Unusable("is not a regular file (left alone)".into());
        }
        if meta.len() > self.max_bytes {
            return Read::Bad(format!(
                "larger than the cache's bound ({} bytes)",
                meta.len()
            ));
        }
        let bytes = match fs::read(path) {
            Ok(b) => b,
            Err(e) if e.kind() == ErrorKind::NotFound => return Read::Missing,
            Err(e) => return Read::Unusable(format!("cannot be read: {e}")),
        };
        match parse(&bytes, key) {
            Ok(payload) => Read::Payload(payload.to_vec()),
            Err(why) => Read::Bad(why),
        }
    }

    /// Writes the entry of `key` at `path`: to a temporary file beside it, then renamed over it.
    fn write(&self, path: &Path, key: &str, payload: &[u8]) -> std::result::Result<(), String> {
        let mut bytes = Vec::with_capacity(payload.len() + key.len() + 64);
        bytes.extend_from_slice(MAGIC);
        bytes.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        bytes.extend_from_slice(&(key.len() as u64).to_le_bytes());
        bytes.extend_from_slice(key.as_bytes());
        bytes.extend_from_slice(&(payload.len() as u64).to_le_bytes());
        bytes.extend_from_slice(&sha256::digest(payload));
        bytes.extend_from_slice(payload);
        if bytes.len() as u64 > self.max_bytes {
            return Err(format!(
                "{} bytes, more than the cache's bound of {} bytes",
                bytes.len(),
                self.max_bytes
            ));
        }
        fs::create_dir_all(&self.dir).map_err(|e| format!("{}: {e}", self.dir.display()))?;
        let temp = self.dir.join(format!(
            ".{}.{}.{}.{TEMP_SUFFIX}",
            path.file_stem().and_then(|s| s.to_str()).unwrap_or("entry"),
            std::process::id(),
            unique()
        ));
        let written = (|| -> std::io::Result<()> {
            let mut f = fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(&temp)?;
            f.write_all(&bytes)?;
            f.sync_data()
        })();
        let renamed = written.and_then(|()| {
            // A path that is there but not a regular file is never replaced.
            match fs::symlink_metadata(path) {
                Ok(m) if !m.file_type().is_file() => Err(std::io::Error::other(
                    "the entry's path is not a regular file (left alone)",
                )),
                _ => fs::rename(&temp, path),
            }
        });
        renamed.map_err(|e| {
            fs::remove_file(&temp).ok();
            e.to_string()
        })
    }

    /// Keeps the newest entries (by last use) within the bounds, `keep` among them, and removes
    /// temporary files left by writers that died. Best effort: another process may be doing the
    /// same.
    fn evict(&self, keep: &Path) {
        let Ok(list) = fs::read_dir(&self.dir) else {
            return;
        };
        let now = SystemTime::now();
        let mut entries: Vec<(SystemTime, u64, PathBuf)> = Vec::new();
        for e in list.flatten() {
            let p = e.path();
            let Ok(meta) = fs::symlink_metadata(&p) else {
                continue;
            };
            if !meta.file_type().is_file() {
                continue;
            }
            let modified = meta.modified().unwrap_or(SystemTime::UNIX_EPOCH);
            if has_suffix(&p, TEMP_SUFFIX) {
                if now
                    .duration_since(modified)
                    .is_ok_and(|age| age > STALE_TEMP)
                {
                    fs::remove_file(&p).ok();
                }
            } else if has_suffix(&p, SUFFIX) {
                entries.push((modified, meta.len(), p));
            }
        }
        // Newest first; the entry just written first of all.
        entries.sort_by(|a, b| (b.2 == keep).cmp(&(a.2 == keep)).then(b.0.cmp(&a.0)));
        let mut bytes = 0u64;
        for (i, (_, len, p)) in entries.iter().enumerate() {
            bytes = bytes.saturating_add(*len);
            if i > 0 && (i >= self.max_entries || bytes > self.max_bytes) {
                fs::remove_file(p).ok();
            }
        }
    }
}

/// What reading an entry gave.
enum Read {
    /// A payload whose key, length and checksum agree.
    Payload(Vec<u8>),
    /// No entry.
    Missing,
    /// An entry that is corrupt, truncated or stale: rebuilt and written over.
    Bad(String),
    /// A path that cannot be used: neither read nor written.
    Unusable(String),
}

/// The key of the inputs `inputs` with the versions that also decide the tables.
fn full_key(inputs: &str) -> String {
    format!(
        "hdi-tribology force tables\nformat {FORMAT_VERSION}\nversion {}\nsources {SOURCE_DIGEST}\ninputs {inputs}\n",
        env!("CARGO_PKG_VERSION")
    )
}

/// The payload of an entry's `bytes` for `key`, or why they are not a valid entry for it.
fn parse<'a>(bytes: &'a [u8], key: &str) -> std::result::Result<&'a [u8], String> {
    let total = bytes.len();
    let truncated = |needed: usize| format!("truncated ({total} bytes, at least {needed} needed)");
    let mut at = 0usize;
    let mut take = |n: usize| -> std::result::Result<&'a [u8], String> {
        let end = at.checked_add(n).filter(|&e| e <= total);
        let Some(end) = end else {
            return Err(truncated(at.saturating_add(n)));
        };
        let s = &bytes[at..end];
        at = end;
        Ok(s)
    };
    if take(MAGIC.len())? != MAGIC {
        return Err("not a table cache entry (its first bytes differ)".into());
    }
    let version = u32::from_le_bytes(take(4)?.try_into().unwrap_or([0; 4]));
    if version != FORMAT_VERSION {
        return Err(format!(
            "stale (entry format {version}, this build reads format {FORMAT_VERSION})"
        ));
    }
    let key_len = u64::from_le_bytes(take(8)?.try_into().unwrap_or([0; 8]));
    let stored = take(usize::try_from(key_len).unwrap_or(usize::MAX))?;
    if stored != key.as_bytes() {
        let version_line = |k: &[u8]| {
            String::from_utf8_lossy(k)
                .lines()
                .find(|l| l.starts_with("version "))
                .map(str::to_string)
        };
        return Err(match (version_line(stored), version_line(key.as_bytes())) {
            (Some(a), Some(b)) if a != b => format!(
                "stale (written by hdi-tribology {}, this is {})",
                &a[8..],
                &b[8..]
            ),
            _ => "stale or for other inputs (its key differs)".into(),
        });
    }
    let len = u64::from_le_bytes(take(8)?.try_into().unwrap_or([0; 8]));
    let checksum = take(32)?;
    let payload = take(usize::try_from(len).unwrap_or(usize::MAX))?;
    if at != total {
        return Err(format!(
            "of the wrong length ({total} bytes, {at} expected)"
        ));
    }
    if sha256::digest(payload) != checksum {
        return Err("corrupt (its checksum does not match)".into());
    }
    Ok(payload)
}

/// Marks `path` as just used (best effort), for eviction by last use.
fn touch(path: &Path) {
    if let Ok(f) = fs::OpenOptions::new().append(true).open(path) {
        f.set_modified(SystemTime::now()).ok();
    }
}

/// Whether `p` names a regular file (not following a symbolic link).
fn is_regular(p: &Path) -> bool {
    fs::symlink_metadata(p).is_ok_and(|m| m.file_type().is_file())
}

/// Whether the file name of `p` ends in `.suffix`.
fn has_suffix(p: &Path, suffix: &str) -> bool {
    p.extension().is_some_and(|e| e == suffix)
}

/// A number unique within the process and unlikely to repeat across processes.
fn unique() -> u64 {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let nanos = SystemTime::now()
        .duration_since(SystemTime::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    (COUNTER.fetch_add(1, Ordering::Relaxed) << 32) | u64::from(nanos)
}

fn io_error(path: &Path, source: std::io::Error) -> Error {
    Error::Io {
        path: path.display().to_string(),
        source,
    }
}
