//! `hdi forces`: every interface force at given bulge gaps.

use hdi_tribology::force::{Breakdown, Gaps};
use hdi_tribology::units::shift_decimal;
use serde::Serialize;

use crate::common::{self, list, number, CliError, List, SceneArgs};

/// Interface forces at bulge gaps D, JSON, one object per gap, each key with its unit: d_m,
/// intermolecular_n, contact_n, electrostatic_per_volt2_n_per_v2, electrostatic_n (at the
/// scene's DC voltage minus the contact potential), other_n, real_contact_area_m2, total_n
/// (positive = away from the disk), and in_table_range. Pad-gap terms see D + the protrusion. A gap outside the scene's force table
/// range is computed by direct quadrature, flagged, and warned about on stderr.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    scene: SceneArgs,
    /// Bulge gaps in metres, comma-separated.
    #[arg(long, value_name = "D1,D2,...", value_parser = list, allow_hyphen_values = true,
          required_unless_present = "gaps_nm", conflicts_with = "gaps_nm")]
    gaps: Option<List>,
    /// Bulge gaps in nanometres, comma-separated.
    #[arg(long, value_name = "D1,D2,...", value_parser = list, allow_hyphen_values = true)]
    gaps_nm: Option<List>,
    /// Protrusion of the bulge over the pads (m): pad-gap terms see D + this [default: 0].
    #[arg(long, value_name = "M", value_parser = number, allow_hyphen_values = true,
          conflicts_with = "protrusion_nm")]
    protrusion_m: Option<f64>,
    /// Protrusion in nanometres.
    #[arg(long, value_name = "NM", value_parser = number, allow_hyphen_values = true)]
    protrusion_nm: Option<f64>,
}

/// Nanometres to metres on the decimal typed ([`shift_decimal`]).
fn from_nm(x: f64) -> f64 {
    shift_decimal(x, -9)
}

#[derive(Serialize)]
struct Row {
    d_m: f64,
    #[serde(flatten)]
    forces: Breakdown,
    in_table_range: bool,
}

pub fn run(a: Args) -> Result<(), CliError> {
    // The gaps as the user gave them: the option's name and the values in its unit.
    let (option, given, gaps): (&str, Vec<f64>, Vec<f64>) = match (&a.gaps, &a.gaps_nm) {
        (Some(List(m)), _) => ("--gaps", m.clone(), m.clone()),
        (None, Some(List(n))) => (
            "--gaps-nm",
            n.clone(),
            // In metres as typed in nm: 1.1 nm is 1.1e-9 m (not 1.1000000000000001e-9).
            n.iter().map(|&x| from_nm(x)).collect(),
        ),
        (None, None) => return Err(CliError::Usage("give --gaps or --gaps-nm".into())),
    };
    let protrusion = match (a.protrusion_m, a.protrusion_nm) {
        (Some(m), _) => m,
        (None, Some(n)) => from_nm(n),
        (None, None) => 0.0,
    };
    let scene = a.scene.load()?;
    let interface = common::interface(&scene)?;
    let (lo, hi) = interface.table_range();
    let volt2 = scene.dc_volt2();
    let mut rows = Vec::with_capacity(gaps.len());
    for (&d, &shown) in gaps.iter().zip(&given) {
        let g = Gaps {
            bulge: d,
            pad: d + protrusion,
        };
        let forces = interface.breakdown(g, volt2);
        let shown = hdi_tribology::units::fmt_short(shown);
        if !forces.total.is_finite() {
            return Err(CliError::Failed(format!(
                "{option} {shown}: the forces there are not finite"
            )));
        }
        let in_table_range = (lo..=hi).contains(&d) && (lo..=hi).contains(&g.pad);
        if !in_table_range {
            common::warn(&format!(
                "{option} {shown}: outside the scene's force table range {} to {} \
                 (the model is made for gaps near the flying gap); computed by direct quadrature",
                common::nm(lo),
                common::nm(hi)
            ));
        }
        rows.push(Row {
            d_m: d,
            forces,
            in_table_range,
        });
    }
    common::print_json(&rows)
}
