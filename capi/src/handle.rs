//! Handles: boxed Rust values behind opaque pointers, a registry of the live ones, and the
//! access rules (shared for scenes and models, exclusive for drives).
//!
//! A pointer is dereferenced only while the registry lists it as a live handle of the expected
//! kind, so a freed, foreign or wrong-kind handle is refused without reading its memory. The
//! registry lock is held while a call takes its access (a count of shared users, or the
//! exclusive mark), and `free` takes the exclusive mark under the same lock: a handle in use
//! cannot be freed, and a freed one cannot be used.

use crate::error::Failure;
use crate::HdiStatus;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

/// The kinds of handle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    Scene,
    Model,
    Drive,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::Scene => "scene",
            Kind::Model => "model",
            Kind::Drive => "drive",
        }
    }
}

/// Addresses of the live handles and their kinds.
static LIVE: Mutex<BTreeMap<usize, Kind>> = Mutex::new(BTreeMap::new());

fn live() -> std::sync::MutexGuard<'static, BTreeMap<usize, Kind>> {
    // Nothing panics while holding the lock; a poisoned lock still holds a consistent map.
    LIVE.lock().unwrap_or_else(|e| e.into_inner())
}

/// `users` when a call holds the handle exclusively.
const EXCLUSIVE: usize = usize::MAX;

/// The part every handle starts with.
#[derive(Debug, Default)]
pub(crate) struct Header {
    /// Calls using the handle now (shared), or `EXCLUSIVE`.
    users: AtomicUsize,
    /// A call on this handle panicked while holding it exclusively: its state may be broken.
    poisoned: AtomicBool,
}

/// A Rust value behind a handle.
pub(crate) trait Handle: Sized {
    const KIND: Kind;
    fn header(&self) -> &Header;
}

/// Boxes `value` and registers it as a live handle.
pub(crate) fn register<H: Handle>(value: H) -> *mut H {
    let p = Box::into_raw(Box::new(value));
    live().insert(p as usize, H::KIND);
    p
}

/// How a call uses a handle.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Access {
    /// Reads only: any number of calls at once, on any threads.
    Shared,
    /// Changes it: one call at a time.
    Exclusive,
}

/// A handle taken by a call; gives the access back when dropped (also when unwinding).
pub(crate) struct Guard<'a, H: Handle> {
    handle: &'a H,
    access: Access,
}

impl<H: Handle> Guard<'_, H> {
    pub(crate) fn get(&self) -> &H {
        self.handle
    }
}

impl<H: Handle> Drop for Guard<'_, H> {
    fn drop(&mut self) {
        let h = self.handle.header();
        match self.access {
            Access::Shared => {
                h.users.fetch_sub(1, Ordering::Release);
            }
            Access::Exclusive => {
                if std::thread::panicking() {
                    h.poisoned.store(true, Ordering::Relaxed);
                }
                h.users.store(0, Ordering::Release);
            }
        }
    }
}

/// Checks that `p` (the argument `arg`) is a live handle of kind `H` and takes it.
pub(crate) fn acquire<'a, H: Handle>(
    p: *const H,
    arg: &str,
    access: Access,
) -> Result<Guard<'a, H>, Failure> {
    if p.is_null() {
        return Err(Failure::new(
            HdiStatus::NullPointer,
            format!("{arg}: a null {} handle", H::KIND.name()),
        ));
    }
    let live = live();
    check_kind::<H>(&live, p as usize, arg)?;
    // SAFETY: the registry lists `p` as a live handle of kind `H`: it came from `register::<H>`
    // and has not been freed (a free removes it under this lock first).
    let handle: &'a H = unsafe { &*p };
    let h = handle.header();
    if h.poisoned.load(Ordering::Relaxed) {
        return Err(Failure::new(
            HdiStatus::Panic,
            format!(
                "{arg}: an earlier call on this {} failed with an internal error and left it \
                 unusable; free it",
                H::KIND.name()
            ),
        ));
    }
    let taken = match access {
        Access::Shared => h
            .users
            .fetch_update(Ordering::Acquire, Ordering::Relaxed, |n| {
                (n != EXCLUSIVE && n < EXCLUSIVE - 1).then_some(n + 1)
            })
            .is_ok(),
        Access::Exclusive => h
            .users
            .compare_exchange(0, EXCLUSIVE, Ordering::Acquire, Ordering::Relaxed)
            .is_ok(),
    };
    drop(live);
    if !taken {
        return Err(busy::<H>(arg));
    }
    Ok(Guard { handle, access })
}

fn busy<H: Handle>(arg: &str) -> Failure {
    Failure::new(
        HdiStatus::Busy,
        format!(
            "{arg}: this {} is in use by a call on another thread (a drive takes one call at a \
             time; a scene or model cannot be freed while a call reads it)",
            H::KIND.name()
        ),
    )
}

fn check_kind<H: Handle>(
    live: &BTreeMap<usize, Kind>,
    addr: usize,
    arg: &str,
) -> Result<(), Failure> {
    match live.get(&addr) {
        None => Err(Failure::new(
            HdiStatus::InvalidHandle,
            format!(
                "{arg}: not a live {} handle (already freed, or not made by this library)",
                H::KIND.name()
            ),
        )),
        Some(&k) if k != H::KIND => Err(Failure::new(
            HdiStatus::WrongHandleType,
            format!(
                "{arg}: a {} handle where a {} handle is expected",
                k.name(),
                H::KIND.name()
            ),
        )),
        Some(_) => Ok(()),
    }
}

/// Frees the handle `p` (the argument `arg`); a null pointer is a no-op.
pub(crate) fn free<H: Handle>(p: *mut H, arg: &str) -> Result<(), Failure> {
    if p.is_null() {
        return Ok(());
    }
    let mut live = live();
    check_kind::<H>(&live, p as usize, arg)?;
    // SAFETY: live handle of kind `H` (see `acquire`).
    let h = unsafe { &*p }.header();
    if h.users
        .compare_exchange(0, EXCLUSIVE, Ordering::Acquire, Ordering::Relaxed)
        .is_err()
    {
        return Err(busy::<H>(arg));
    }
    live.remove(&(p as usize));
    drop(live);
    // SAFETY: `p` came from `Box::into_raw` in `register`, no call holds it (the exclusive mark
    // was free), and it is no longer listed, so no later call can reach it.
    drop(unsafe { Box::from_raw(p) });
    Ok(())
}
