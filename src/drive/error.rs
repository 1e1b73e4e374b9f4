//! Why the drive or a controller running it could not go on.

use crate::error::{failure_kind, Stage};

impl Stage {
    /// The drive plant.
    pub const DRIVE: Stage = Stage::named("drive");
    /// A controller running the drive.
    pub const DRIVE_CONTROLLER: Stage = Stage::named("drive controller");
}

/// Why the drive or a controller running it could not go on.
///
/// ```
/// use hdi_tribology::drive::DriveError;
/// let e: hdi_tribology::Error = DriveError::NotFinished { max_periods: 100 }.into();
/// assert_eq!(e.to_string(), "drive controller: did not finish within 100 periods");
/// let e: hdi_tribology::Error = DriveError::PeriodSteps { max_steps: 10, t0_s: 0.0, t1_s: 5e-5 }.into();
/// assert!(matches!(e, hdi_tribology::Error::NoConvergence(_)), "{e}");
/// ```
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum DriveError {
    /// A controller did not stop within its budget of periods.
    #[error("did not finish within {max_periods} periods")]
    NotFinished {
        /// The budget.
        max_periods: usize,
    },
    /// One period needed more than `solver.max_steps` steps.
    #[error("more than {max_steps} steps (solver.max_steps) in the period [{t0_s}, {t1_s}] s")]
    PeriodSteps {
        /// The step budget of one period.
        max_steps: usize,
        /// Start of the period (s).
        t0_s: f64,
        /// End of the period (s).
        t1_s: f64,
    },
    /// In the bounded mode ([`DriveOptions::steps_per_period`](super::DriveOptions)), every
    /// trial step was non-finite down to the smallest step: there the interface forces come
    /// from their tables alone ([`OutsideTables::Refused`](crate::force::OutsideTables)), so that
    /// no right-hand side pays for direct quadrature, and the slider's path most likely left
    /// the tables.
    #[error(
        "the bounded mode reads the interface forces from their tables alone ({table_low_nm:.3} \
         to {table_high_nm:.3} nm), and at t = {t_s} s every trial step was non-finite, as where \
         the slider's path leaves them ({detail}); extend the tables (table.d_min_m, \
         table.d_max_m) or run without steps_per_period"
    )]
    LeftTheTables {
        /// Where the integrator stopped (s).
        t_s: f64,
        /// Low end of the force tables (nm).
        table_low_nm: f64,
        /// High end of the force tables (nm).
        table_high_nm: f64,
        /// The integrator's own account.
        detail: String,
    },
    /// A head of a [`MultiDrive`](super::MultiDrive) failed in an earlier step, after the
    /// heads before it had moved on: the heads no longer share one clock.
    #[error(
        "head {head} failed in an earlier step and the heads before it had moved on: they no \
         longer share one clock (start the drive again)"
    )]
    HeadsOutOfStep {
        /// The head that failed.
        head: usize,
    },
}

failure_kind!(DriveError, convergence = |e| matches!(e, DriveError::PeriodSteps { .. }), {
        NotFinished => Stage::DRIVE_CONTROLLER,
        PeriodSteps => Stage::DRIVE,
        HeadsOutOfStep => Stage::DRIVE,
        LeftTheTables => Stage::DRIVE,
});
