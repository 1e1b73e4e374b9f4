//! Why the air bearing could not be solved.

use crate::error::{failure_kind, num, Stage};

impl Stage {
    /// The air bearing's pressure, attitude, stiffness or damping from the slider's geometry.
    pub const AIR_BEARING: Stage = Stage::named("air bearing");
}

/// Which linear solve of the air bearing fell short of its tolerance.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Solve {
    /// The pressure (Newton's method on the Reynolds equation).
    Pressure,
    /// The pressure's sensitivities to the attitude (the stiffness).
    Sensitivity,
    /// The small-amplitude squeeze solve (the damping).
    Damping,
}

impl Solve {
    /// The solve's name as the messages write it.
    pub fn name(self) -> &'static str {
        match self {
            Solve::Pressure => "pressure",
            Solve::Sensitivity => "sensitivity",
            Solve::Damping => "damping",
        }
    }
}

/// Why the air bearing could not be solved. Numbers are in engineering units, as the field names
/// say.
///
/// ```
/// use hdi_tribology::bearing::BearingError;
/// let e: hdi_tribology::Error = BearingError::SingularStiffness.into();
/// assert_eq!(e.to_string(), "air bearing did not converge: the bearing's stiffness matrix is singular");
/// ```
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BearingError {
    /// The bearing cannot carry the preload: its load stays below it down to the smallest
    /// spacing the solve allows.
    #[error(
        "the slider does not fly: the bearing carries {} mN at a smallest spacing of {} nm, short \
         of the preload {} mN",
        num(*.load_mn),
        num(*.min_spacing_nm),
        num(*.preload_mn)
    )]
    DoesNotFly {
        /// The preload (mN).
        preload_mn: f64,
        /// The bearing's load at the lowest attitude reached (mN).
        load_mn: f64,
        /// The smallest spacing there (nm).
        min_spacing_nm: f64,
    },
    /// The slider touches the disk somewhere: a spacing is not positive.
    #[error(
        "the pressure: the slider touches the disk at control volume {cell} (spacing {} nm)",
        num(*.spacing_nm)
    )]
    Touches {
        /// The control volume's index.
        cell: usize,
        /// Its spacing (nm).
        spacing_nm: f64,
    },
    /// Newton's method on the pressure used up its steps.
    #[error(
        "the pressure: {iterations} Newton steps, last change of p/p_a {last_change:.3e}, residual \
         {residual:.3e}"
    )]
    PressureNewton {
        /// Newton steps taken.
        iterations: usize,
        /// The last step's largest change of `p/p_a`.
        last_change: f64,
        /// The scaled residual left.
        residual: f64,
    },
    /// A Newton step of the pressure gives a non-finite residual.
    #[error("the pressure: the Newton step gives a non-finite residual")]
    NonFiniteResidual,
    /// A linear (GMRES) solve for the stiffness or damping fell short of its tolerance.
    #[error(
        "the {}: GMRES reached {relative_residual:.3e} in {iterations} iterations",
        .solve.name()
    )]
    Krylov {
        /// Which solve.
        solve: Solve,
        /// The relative residual reached.
        relative_residual: f64,
        /// Iterations taken.
        iterations: usize,
    },
    /// The attitude's Newton iteration used up its steps.
    #[error(
        "the attitude: {iterations} Newton steps on {nx}×{ny} control volumes, relative imbalance \
         {imbalance:.3e}"
    )]
    AttitudeNewton {
        /// Newton steps taken.
        iterations: usize,
        /// Control volumes along the slider's length.
        nx: usize,
        /// Control volumes across it.
        ny: usize,
        /// The relative imbalance of the forces and moments left.
        imbalance: f64,
    },
    /// The bearing's stiffness matrix is singular.
    #[error("the bearing's stiffness matrix is singular")]
    SingularStiffness,
    /// The caller's [`Interrupt`](super::reynolds::Interrupt) asked the solve to stop.
    #[error("stopped on request during the {} solve", .during.name())]
    Interrupted {
        /// The solve under way.
        during: Solve,
    },
}

failure_kind!(BearingError, convergence = |e| !matches!(e, BearingError::DoesNotFly { .. } | BearingError::Interrupted { .. }), {
        DoesNotFly => Stage::AIR_BEARING,
        Touches => Stage::AIR_BEARING,
        PressureNewton => Stage::AIR_BEARING,
        NonFiniteResidual => Stage::AIR_BEARING,
        Krylov => Stage::AIR_BEARING,
        AttitudeNewton => Stage::AIR_BEARING,
        SingularStiffness => Stage::AIR_BEARING,
    Interrupted => Stage::AIR_BEARING,
});
