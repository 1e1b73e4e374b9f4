//! Cancelling running integrations from outside: a flag that every integration step on the
//! threads watching it polls, so that a long computation (a sweep, a fit, a replay) stops soon
//! after it is asked to, with [`OdeError::Cancelled`](super::OdeError::Cancelled).

use std::cell::RefCell;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

thread_local! {
    static WATCHED: RefCell<Option<Cancel>> = const { RefCell::new(None) };
}

/// A cancellation flag, shared by its clones.
///
/// ```
/// use hdi_tribology::ode::Cancel;
/// let c = Cancel::new();
/// assert!(!c.is_cancelled());
/// let seen = c.watch(|| {
///     c.cancel();
///     Cancel::requested()
/// });
/// assert!(seen && !Cancel::requested());
/// ```
#[derive(Clone, Debug, Default)]
pub struct Cancel(Arc<AtomicBool>);

impl Cancel {
    /// A flag not yet raised.
    pub fn new() -> Self {
        Self::default()
    }

    /// Raises the flag: integrations watching it stop at their next step.
    pub fn cancel(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// Whether the flag is raised.
    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    /// Runs `work` with this flag watched by every integration step on the current thread
    /// (the flag watched before is watched again afterwards).
    pub fn watch<T>(&self, work: impl FnOnce() -> T) -> T {
        struct Restore(Option<Cancel>);
        impl Drop for Restore {
            fn drop(&mut self) {
                let before = self.0.take();
                WATCHED.with(|w| *w.borrow_mut() = before);
            }
        }
        let before = WATCHED.with(|w| w.borrow_mut().replace(self.clone()));
        let _restore = Restore(before);
        work()
    }

    /// The flag watched on the current thread, to watch on threads it hands work to.
    pub fn current() -> Option<Cancel> {
        WATCHED.with(|w| w.borrow().clone())
    }

    /// Runs `work` watching `cancel` when there is one: how work handed to another thread
    /// keeps watching the flag of the thread that handed it over ([`Cancel::current`]).
    pub fn carry<T>(cancel: &Option<Cancel>, work: impl FnOnce() -> T) -> T {
        match cancel {
            Some(c) => c.watch(work),
            None => work(),
        }
    }

    /// Whether the flag watched on the current thread (if any) is raised.
    pub fn requested() -> bool {
        WATCHED.with(|w| w.borrow().as_ref().is_some_and(Cancel::is_cancelled))
    }
}
