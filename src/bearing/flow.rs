//! The rarefaction model the Reynolds equation uses: the Poiseuille flow rate relative to
//! continuum flow, `Q(Kn)`, at the local inverse Knudsen number's reciprocal `Kn = λ/h`.
//!
//! This is the bearing's own selection of the closed-form slip models (continuum; first-order
//! slip after Burgdorfer 1959, `Q = 1 + 6 Kn`; second-order slip after Hsia & Domoto 1983,
//! `Q = 1 + 6 Kn + 6 Kn²`), with unit accommodation.

use serde::{Deserialize, Serialize};

/// Which Poiseuille flow factor the Reynolds equation uses.
///
/// ```
/// use hdi_tribology::bearing::FlowModel;
/// assert_eq!(FlowModel::Continuum.factor(0.5), 1.0);
/// assert_eq!(FlowModel::FirstOrderSlip.factor(0.5), 4.0);
/// assert_eq!(FlowModel::SecondOrderSlip.factor_and_derivative(0.5), (5.5, 12.0));
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FlowModel {
    /// No slip: `Q = 1`.
    Continuum,
    /// First-order slip: `Q = 1 + 6 Kn`.
    #[default]
    FirstOrderSlip,
    /// Second-order slip: `Q = 1 + 6 Kn + 6 Kn²`.
    SecondOrderSlip,
}

impl FlowModel {
    /// `Q(Kn)`.
    pub fn factor(self, knudsen: f64) -> f64 {
        self.factor_and_derivative(knudsen).0
    }

    /// `Q(Kn)` and `dQ/dKn`.
    pub fn factor_and_derivative(self, knudsen: f64) -> (f64, f64) {
        let k = knudsen;
        match self {
            FlowModel::Continuum => (1.0, 0.0),
            FlowModel::FirstOrderSlip => (1.0 + 6.0 * k, 6.0),
            FlowModel::SecondOrderSlip => (1.0 + 6.0 * k + 6.0 * k * k, 6.0 + 12.0 * k),
        }
    }
}
