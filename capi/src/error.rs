//! Status codes, the thread-local last error, and the wrapper that keeps panics inside.

use crate::HdiStatus;
use std::cell::RefCell;
use std::ffi::CString;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// A failed call: its status and the message for `hdi_last_error`.
#[derive(Debug)]
pub(crate) struct Failure {
    pub status: HdiStatus,
    pub message: String,
}

impl Failure {
    pub(crate) fn new(status: HdiStatus, message: impl Into<String>) -> Self {
        Failure {
            status,
            message: message.into(),
        }
    }

    pub(crate) fn invalid(field: &str, reason: impl std::fmt::Display) -> Self {
        Failure::new(
            HdiStatus::InvalidInput,
            format!("invalid {field}: {reason}"),
        )
    }

    pub(crate) fn null(arg: &str) -> Self {
        Failure::new(HdiStatus::NullPointer, format!("{arg}: a null pointer"))
    }
}

impl From<hdi_tribology::Error> for Failure {
    fn from(e: hdi_tribology::Error) -> Self {
        use hdi_tribology::Error as E;
        let status = match &e {
            E::InvalidInput { .. } => HdiStatus::InvalidInput,
            E::Scene { .. } => HdiStatus::Scene,
            E::NoConvergence(_) => HdiStatus::NoConvergence,
            E::Analysis(_) => HdiStatus::Analysis,
            E::Ode(_) => HdiStatus::Integration,
            E::Io { .. } => HdiStatus::Io,
            E::Data(_) => HdiStatus::InvalidInput,
            _ => HdiStatus::Other,
        };
        Failure::new(status, e.to_string())
    }
}

/// The library's error with its field renamed by `rename` (the library's dotted name to the one
/// the C caller wrote), when it is an invalid input.
pub(crate) fn renamed(e: hdi_tribology::Error, rename: impl Fn(&str) -> Option<String>) -> Failure {
    match e {
        hdi_tribology::Error::InvalidInput { field, reason } => {
            let field = rename(&field).unwrap_or(field);
            Failure::invalid(&field, reason)
        }
        other => other.into(),
    }
}

thread_local! {
    /// The message of this thread's last failed call; empty after a call that succeeded.
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

fn set_last_error(message: String) {
    // An interior NUL would cut the C string short: show it instead.
    let c = CString::new(message.replace('\0', "\\0")).unwrap_or_default();
    LAST_ERROR.with(|e| *e.borrow_mut() = c);
}

fn clear_last_error() {
    LAST_ERROR.with(|e| {
        if !e.borrow().as_bytes().is_empty() {
            *e.borrow_mut() = CString::default();
        }
    });
}

/// The message of this thread's last failed call (valid until this thread's next call).
pub(crate) fn last_error_ptr() -> *const std::ffi::c_char {
    LAST_ERROR.with(|e| e.borrow().as_ptr())
}

/// Runs one C call: a panic becomes `HdiStatus::Panic`, a failure its status, and the message
/// goes to the thread's last error.
pub(crate) fn call(f: impl FnOnce() -> Result<(), Failure>) -> HdiStatus {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => {
            clear_last_error();
            HdiStatus::Ok
        }
        Ok(Err(e)) => {
            set_last_error(e.message);
            e.status
        }
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "no message".into());
            set_last_error(format!(
                "internal error (a bug in hdi-tribology, please report it): {what}"
            ));
            HdiStatus::Panic
        }
    }
}
