//! Force evaluations that once failed, kept as regression tests.

use hdi_tribology::force::Gaps;
use hdi_tribology::model::SliderModel;
use hdi_tribology::scene::Scene;

/// 26 nm into the disk (37σ) the Gaussian window of the intermolecular average only just reached
/// the cutoff; the integral was about 1e-306 Pa and its subnormal absolute tolerance could not be
/// met, so the direct evaluation failed and the hot path returned NaN (the end of the
/// self-excited bounce with a 100 ns interface lag). Every force must stay finite from deep
/// interference to far above the table range.
#[test]
fn forces_stay_finite_far_outside_the_table_range() {
    let model = SliderModel::from_scene(&Scene::paper()).unwrap();
    let mut d = -6e-8;
    while d < 1e-6 {
        let g = Gaps::same(d);
        let f = model.interface_force(g, 1.0);
        assert!(
            f.value.is_finite() && f.d_bulge.is_finite(),
            "d = {d:e}: {f:?}"
        );
        assert!(model.forces().real_contact_area(g).is_finite());
        model.interface_force_exact(g, 1.0).unwrap();
        d += if d.abs() < 3e-8 { 1e-11 } else { 1e-9 };
    }
}
