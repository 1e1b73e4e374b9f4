//! Why the slider's static balance could not be found.

use crate::error::{failure_kind, num, Stage};

impl Stage {
    /// The slider's static balance on its air bearing and structure.
    pub const BALANCE: Stage = Stage::named("static balance");
}

/// Why the slider's static balance at a bulge gap could not be found (always
/// [`Error::NoConvergence`](crate::Error::NoConvergence)). Lengths are in nm, as the field names
/// say.
///
/// ```
/// use hdi_tribology::model::BalanceError;
/// let e: hdi_tribology::Error = BalanceError::Structure { bulge_nm: 3.0 }.into();
/// assert_eq!(
///     e.to_string(),
///     "static balance did not converge: no static displacement of the structure puts the bulge \
///      at 3.0000 nm"
/// );
/// ```
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BalanceError {
    /// No static displacement of the structure puts the bulge at this height.
    #[error(
        "no static displacement of the structure puts the bulge at {} nm",
        num(*.bulge_nm)
    )]
    Structure {
        /// The bulge's height asked for (nm).
        bulge_nm: f64,
    },
    /// The forces are not finite during the air-bearing balance.
    #[error(
        "the forces are not finite at d = {} nm, body displacement {} nm",
        num(*.d_nm),
        num(*.y_nm)
    )]
    NotFinite {
        /// The bulge gap (nm).
        d_nm: f64,
        /// The body's displacement (nm).
        y_nm: f64,
    },
    /// No displacement balances the interface force.
    #[error(
        "no displacement balances the interface force at d = {} nm, V² = {volt2_v2} V²",
        num(*.d_nm)
    )]
    NoBalance {
        /// The bulge gap (nm).
        d_nm: f64,
        /// The squared voltage (V²).
        volt2_v2: f64,
    },
}

failure_kind!(BalanceError, convergence = |_| true, {
        Structure => Stage::BALANCE,
        NotFinite => Stage::BALANCE,
        NoBalance => Stage::BALANCE,
});
