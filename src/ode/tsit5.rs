//! Tsitouras' explicit Runge–Kutta 5(4) pair (Ch. Tsitouras, Comput. Math. Appl. 62 (2011)
//! 770–775): 7 stages with FSAL, 4th-order continuous extension.

use super::dense::StepPoly;
use super::stepper::{
    all_finite, stage_spectral_radius, zeros_like, Ctx, FailKind, Step, Stepper, Trial,
};
use super::system::OdeSystem;
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OVector};

const C: [f64; 7] = [0.0, 0.161, 0.327, 0.9, 0.980_025_540_904_509_7, 1.0, 1.0];

const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [0.161, 0.0, 0.0, 0.0, 0.0, 0.0],
    [
        -0.008_480_655_492_356_989,
        0.335_480_655_492_357,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        2.897_153_057_105_493_5,
        -6.359_448_489_975_075,
        4.362_295_432_869_581_5,
        0.0,
        0.0,
        0.0,
    ],
    [
        5.325_864_828_439_257,
        -11.748_883_564_062_828,
        7.495_539_342_889_836_5,
        -0.092_495_066_361_755_25,
        0.0,
        0.0,
    ],
    [
        5.861_455_442_946_42,
        -12.920_969_317_847_11,
        8.159_367_898_576_159,
        -0.071_584_973_281_401,
        -0.028_269_050_394_068_383,
        0.0,
    ],
    // The 5th-order weights b (the last stage is evaluated at the new point: FSAL).
    [
        0.096_460_766_818_065_23,
        0.01,
        0.479_889_650_414_499_6,
        1.379_008_574_103_742,
        -3.290_069_515_436_081,
        2.324_710_524_099_774,
    ],
];

/// b − b̂: the error estimate weights.
const E: [f64; 7] = [
    -0.001_780_011_052_225_777,
    -0.000_816_434_459_656_746_9,
    0.007_880_878_010_261_995,
    -0.144_711_007_173_262_9,
    0.582_357_165_452_555_2,
    -0.458_082_105_929_186_97,
    1.0 / 66.0,
];

/// Continuous extension: b_i(θ) = Σ_m R[i][m-1] θ^m, m = 1..4.
const R: [[f64; 4]; 7] = [
    [
        1.0,
        -2.763_706_197_274_826,
        2.913_255_461_821_912_6,
        -1.053_088_497_729_021_6,
    ],
    [0.0, 0.131_7, -0.223_4, 0.101_7],
    [
        0.0,
        3.930_296_236_894_751_6,
        -5.941_033_872_131_505,
        2.490_627_285_651_253,
    ],
    [
        0.0,
        -12.411_077_166_933_676,
        30.338_188_630_282_32,
        -16.548_102_889_244_902,
    ],
    [
        0.0,
        37.509_313_416_511_04,
        -88.178_904_894_766_4,
        47.379_521_962_819_28,
    ],
    [
        0.0,
        -27.896_526_289_197_286,
        65.091_894_674_793_66,
        -34.870_657_861_496_61,
    ],
    [0.0, 1.5, -4.0, 2.5],
];

/// Explicit stability boundary on the negative real axis (≈ 3.5); the stiffness test uses a
/// slightly smaller value so that it triggers before the controller starts to oscillate.
pub(crate) const STABILITY_BOUNDARY: f64 = 3.3;

pub(crate) struct Tsit5<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    k: [OVector<f64, D>; 7],
    stage: OVector<f64, D>,
    err: OVector<f64, D>,
    h_rho: Option<f64>,
}

impl<D: Dim> Tsit5<D>
where
    DefaultAllocator: Allocator<D>,
{
    pub fn new(y: &OVector<f64, D>) -> Self {
        let z = zeros_like(y);
        Tsit5 {
            k: std::array::from_fn(|_| z.clone()),
            stage: z.clone(),
            err: z,
            h_rho: None,
        }
    }
}

impl<D: Dim, S: OdeSystem<D> + ?Sized> Stepper<D, S> for Tsit5<D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    fn error_order(&self) -> f64 {
        5.0
    }

    fn restart(&mut self, sys: &S, t: f64, y: &OVector<f64, D>, ctx: &mut Ctx<D>) {
        ctx.rhs(sys, t, y, &mut self.k[0]);
    }

    fn f0(&self) -> &OVector<f64, D> {
        &self.k[0]
    }

    fn attempt(&mut self, sys: &S, step: Step<'_, D>, ctx: &mut Ctx<D>) -> Trial {
        let Step { t, h, y, y_new } = step;
        for s in 1..7 {
            let (done, rest) = self.k.split_at_mut(s);
            let target = if s < 6 { &mut self.stage } else { &mut *y_new };
            target.copy_from(y);
            for (j, kj) in done.iter().enumerate() {
                let a = A[s][j];
                if a != 0.0 {
                    target.axpy(h * a, kj, 1.0);
                }
            }
            let ts = if s < 6 { t + C[s] * h } else { t + h };
            // Stages 5 and 6 share t + h: the system's values of that time are kept.
            if s == 6 {
                // Stage 6 input (at c = 1) is kept for the stiffness estimate.
                sys.rhs_memo(ts, y_new, &mut rest[0], &mut ctx.memo);
            } else {
                sys.rhs_memo(ts, &self.stage, &mut rest[0], &mut ctx.memo);
            }
        }
        ctx.stats.rhs_evals += 6;
        if !all_finite(y_new) || !all_finite(&self.k[6]) {
            return Trial::Failed {
                factor: 0.25,
                kind: FailKind::NonFinite,
            };
        }
        self.err.fill(0.0);
        for (e, kj) in E.iter().zip(self.k.iter()) {
            self.err.axpy(h * e, kj, 1.0);
        }
        let err = ctx.err_norm(&self.err, y, y_new);
        if ctx.want_stiffness {
            // h·ρ ≈ h‖k7 − k6‖ / ‖y_new − Y6‖ where stage 6 and 7 are both at t + h.
            // `stage` still holds the input of stage 6 (the last one written there).
            self.h_rho =
                stage_spectral_radius(&self.k[6], &self.k[5], y_new, &self.stage).map(|r| h * r);
        }
        Trial::Done { err }
    }

    fn accept(&mut self, _sys: &S, step: &Step<'_, D>, poly: &mut StepPoly, ctx: &mut Ctx<D>) {
        let Step { t, h, y, .. } = *step;
        // FSAL: the last stage is f at the new point.
        if !ctx.need_poly {
            self.k.swap(0, 6);
            return;
        }
        poly.begin(t, h, 4);
        let n = y.len();
        for i in 0..n {
            *poly.at(0, i) = y[i];
        }
        for (s, ks) in self.k.iter().enumerate() {
            for m in 1..=4 {
                let r = R[s][m - 1];
                if r != 0.0 {
                    for i in 0..n {
                        *poly.at(m, i) += h * r * ks[i];
                    }
                }
            }
        }
        // FSAL: the last stage is f at the new point.
        self.k.swap(0, 6);
    }

    fn stiffness(&self) -> Option<f64> {
        self.h_rho
    }

    fn stability_boundary(&self) -> f64 {
        STABILITY_BOUNDARY
    }
}
