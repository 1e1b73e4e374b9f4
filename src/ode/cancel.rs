//! Cancelling running integrations from outside: a flag that every integration step on the
//! threads watching it polls, so that a long computation (a sweep, a fit, a replay) stops soon
//! after it is asked to, with [`OdeError::Cancelled`](super::OdeError::Cancelled). A flag may
//! also carry a check of its own, which the polls call now and then (at most every
//! [`CANCEL_CHECK_INTERVAL`]) and which raises the flag when it says so: how a caller that cannot
//! raise the flag from another thread (an interpreter that sees Ctrl-C only when asked) is
//! heard.

use std::cell::{Cell, RefCell};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The least time between two calls of a flag's check on one thread.
pub const CANCEL_CHECK_INTERVAL: Duration = Duration::from_millis(50);

/// Polls between two looks at the clock for the check.
const POLLS_PER_CLOCK: u32 = 256;

/// The flag a thread watches, with its polls since the last look at the clock and the time of
/// the last check.
struct Watched {
    cancel: Cancel,
    polls: Cell<u32>,
    checked: Cell<Instant>,
}

thread_local! {
    static WATCHED: RefCell<Option<Watched>> = const { RefCell::new(None) };
}

/// A check that says whether to cancel.
type Check = Arc<dyn Fn() -> bool + Send + Sync>;

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
#[derive(Clone, Default)]
pub struct Cancel {
    flag: Arc<AtomicBool>,
    check: Option<Check>,
}

impl std::fmt::Debug for Cancel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Cancel")
            .field("cancelled", &self.is_cancelled())
            .field("check", &self.check.is_some())
            .finish()
    }
}

impl Cancel {
    /// A flag not yet raised.
    pub fn new() -> Self {
        Self::default()
    }

    /// A flag that also raises itself when `check` returns `true`; the polls of the threads
    /// watching it call `check` at most every [`CANCEL_CHECK_INTERVAL`] each.
    ///
    /// ```
    /// use hdi_tribology::ode::Cancel;
    /// let c = Cancel::with_check(|| true);
    /// assert!(!c.is_cancelled());
    /// ```
    pub fn with_check(check: impl Fn() -> bool + Send + Sync + 'static) -> Self {
        Cancel {
            flag: Arc::default(),
            check: Some(Arc::new(check)),
        }
    }

    /// Raises the flag: integrations watching it stop at their next step.
    pub fn cancel(&self) {
        self.flag.store(true, Ordering::Relaxed);
    }

    /// Whether the flag is raised.
    pub fn is_cancelled(&self) -> bool {
        self.flag.load(Ordering::Relaxed)
    }

    /// Runs `work` with this flag watched by every integration step on the current thread
    /// (the flag watched before is watched again afterwards).
    pub fn watch<T>(&self, work: impl FnOnce() -> T) -> T {
        struct Restore(Option<Watched>);
        impl Drop for Restore {
            fn drop(&mut self) {
                let before = self.0.take();
                WATCHED.with(|w| *w.borrow_mut() = before);
            }
        }
        let now = Watched {
            cancel: self.clone(),
            polls: Cell::new(0),
            checked: Cell::new(Instant::now()),
        };
        let before = WATCHED.with(|w| w.borrow_mut().replace(now));
        let _restore = Restore(before);
        work()
    }

    /// Runs `work` watching `cancel` when there is one: how work handed to another thread
    /// keeps watching the flag of the thread that handed it over ([`Cancel::current`]).
    pub fn carry<T>(cancel: &Option<Cancel>, work: impl FnOnce() -> T) -> T {
        match cancel {
            Some(c) => c.watch(work),
            None => work(),
        }
    }

    /// The flag watched on the current thread, to watch on threads it hands work to.
    pub fn current() -> Option<Cancel> {
        WATCHED.with(|w| w.borrow().as_ref().map(|w| w.cancel.clone()))
    }

    /// Whether the flag watched on the current thread (if any) is raised, after calling its
    /// check when one is due.
    pub fn requested() -> bool {
        let due = WATCHED.with(|w| {
            let w = w.borrow();
            let w = w.as_ref()?;
            if w.cancel.is_cancelled() {
                return Some(None);
            }
            let check = w.cancel.check.as_ref()?;
            let polls = w.polls.get().wrapping_add(1);
            w.polls.set(polls);
            if polls % POLLS_PER_CLOCK != 0 || w.checked.get().elapsed() < CANCEL_CHECK_INTERVAL {
                return None;
            }
            w.checked.set(Instant::now());
            Some(Some((check.clone(), w.cancel.flag.clone())))
        });
        match due {
            None => false,
            Some(None) => true,
            // called outside the borrow: a check may run code that watches a flag itself
            Some(Some((check, flag))) => {
                if check() {
                    flag.store(true, Ordering::Relaxed);
                }
                flag.load(Ordering::Relaxed)
            }
        }
    }
}
