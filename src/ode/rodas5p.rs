//! Rosenbrock method Rodas5P (G. Steinebach, "Construction of Rosenbrock–Wanner method Rodas5P
//! and numerical benchmarks within the Julia Differential Equations package", BIT 63 (2023)):
//! 8 stages, order 5, L-stable, embedded order 4, 4th-order dense output.

use super::dense::StepPoly;
use super::jacobian::{eval_jacobian_and_time_derivative, Radius};
use super::lu::Lu;
use super::stepper::{
    add_scaled, all_finite, sum_into, zeros_like, Ctx, FailKind, Step, Stepper, Trial,
};
use super::system::OdeSystem;
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OMatrix, OVector};

const GAMMA: f64 = 0.211_937_563_194_290_14;

/// Stage abscissae; the last three stages are at the end of the step.
const C: [f64; 8] = [
    0.0,
    0.635_812_689_582_870_4,
    0.409_579_839_339_753_5,
    0.976_930_672_506_071_6,
    0.428_840_360_955_866_4,
    1.0,
    1.0,
    1.0,
];

/// γ_i of the time-derivative term, h·d_i·∂f/∂t.
const D_T: [f64; 8] = [
    0.211_937_563_194_290_14,
    -0.423_875_126_388_580_27,
    -0.338_462_712_623_592_4,
    1.804_645_287_288_273_4,
    2.325_825_639_765_069,
    0.0,
    0.0,
    0.0,
];

/// Stage inputs u_s = y + Σ_j A[s][j] k_j for s = 1..5; stages 6, 7, 8 then add k6, k7, k8.
const A: [[f64; 5]; 6] = [
    [0.0; 5],
    [3.0, 0.0, 0.0, 0.0, 0.0],
    [
        2.849_394_379_747_939,
        0.458_422_422_044_639_23,
        0.0,
        0.0,
        0.0,
    ],
    [
        -6.954_028_509_809_101,
        2.489_845_061_869_568,
        -10.358_996_098_473_584,
        0.0,
        0.0,
    ],
    [
        2.802_998_627_562_896_4,
        0.507_246_473_622_820_6,
        -0.398_831_254_177_052_4,
        -0.047_211_872_304_046_41,
        0.0,
    ],
    [
        -7.502_846_399_306_121,
        2.561_846_144_803_919,
        -11.627_539_656_261_098,
        -0.182_687_676_599_422_56,
        0.030_198_172_008_377_946,
    ],
];

/// Coupling of earlier stages into the right-hand side of stage s: Σ_j CC[s][j]/h · k_j.
const CC: [[f64; 7]; 8] = [
    [0.0; 7],
    [-14.155_112_264_123_755, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [
        -17.972_960_358_859_52,
        -2.859_693_295_451_294,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        147.121_502_757_117_16,
        -1.412_214_027_182_13,
        71.689_402_513_023_58,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        165.435_170_248_716_76,
        -0.459_282_345_649_112_6,
        42.909_383_369_586_03,
        -5.961_986_721_573_306,
        0.0,
        0.0,
        0.0,
    ],
    [
        24.854_864_614_690_072,
        -3.000_922_700_283_218_6,
        47.493_111_002_076_8,
        5.581_419_782_155_812_5,
        -0.661_069_182_524_947_1,
        0.0,
        0.0,
    ],
    [
        30.912_732_140_285_99,
        -3.120_824_334_993_797_4,
        77.799_546_460_708_92,
        34.286_460_282_947_83,
        -19.097_331_116_725_623,
        -28.087_943_162_872_662,
        0.0,
    ],
    [
        37.802_771_233_905_63,
        -3.257_196_902_907_227_6,
        112.269_188_494_963_27,
        66.934_723_124_404_7,
        -40.066_189_370_910_02,
        -54.667_802_628_779_68,
        -9.488_616_523_096_27,
    ],
];

/// Dense output: y(θ) = (1−θ)y0 + θ(y1 + (1−θ)(w1 + θ(w2 + θ w3))), w_r = Σ_j H[r][j] k_j.
const H: [[f64; 8]; 3] = [
    [
        25.948_786_856_663_858,
        -2.557_972_484_584_623_5,
        10.433_815_404_888_879,
        -2.367_925_102_268_520_4,
        0.524_948_541_321_073,
        1.124_108_831_045_040_4,
        0.427_287_619_443_187_4,
        -0.172_022_210_701_554_93,
    ],
    [
        -9.915_688_506_951_71,
        -0.968_994_459_411_515_4,
        3.043_803_724_297_845_3,
        -24.495_224_566_215_796,
        20.176_138_334_709_044,
        15.980_663_614_246_51,
        -6.789_040_303_419_874,
        -6.710_236_069_923_372,
    ],
    [
        11.419_903_575_922_262,
        2.887_964_514_613_699_4,
        72.921_379_959_960_29,
        80.125_118_346_226_43,
        -52.072_871_366_152_654,
        -59.789_936_252_667_29,
        -0.155_826_842_827_519_13,
        4.883_087_185_713_722,
    ],
];

pub(crate) struct Rodas5P<D: Dim>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    f0: OVector<f64, D>,
    f0_valid: bool,
    jac: OMatrix<f64, D, D>,
    dfdt: OVector<f64, D>,
    /// ∂f/∂t is zero (autonomous systems): its stage terms are skipped.
    dfdt_zero: bool,
    /// J and ∂f/∂t belong to the current point (they survive rejected attempts).
    jac_valid: bool,
    lu: Lu<f64, D>,
    lu_h: f64,
    k: [OVector<f64, D>; 8],
    u: OVector<f64, D>,
    fu: OVector<f64, D>,
    rho: Radius,
    /// Component and floor of the last step refused for its rounding floor.
    floor_hit: Option<(usize, f64)>,
}

impl<D: Dim> Rodas5P<D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    pub fn new(y: &OVector<f64, D>) -> Self {
        let z = zeros_like(y);
        let (r, _) = y.shape_generic();
        Rodas5P {
            f0: z.clone(),
            f0_valid: false,
            jac: OMatrix::zeros_generic(r, r),
            dfdt: z.clone(),
            dfdt_zero: false,
            jac_valid: false,
            lu: Lu::new(r),
            lu_h: f64::NAN,
            k: std::array::from_fn(|_| z.clone()),
            u: z.clone(),
            fu: z,
            rho: Radius::default(),
            floor_hit: None,
        }
    }
}

impl<D: Dim> Rodas5P<D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// The rounding floor of the stage solves for the step `y → y_new` (J and the LU of W
    /// belong to it): the first component `i` whose floor exceeds `atol_i / rtol`, with the
    /// floor.
    ///
    /// Each stage solve `W k = r`, `W = I/(hγ) − J`, is exact only up to a backward error of
    /// about `ε·|J|·|k|` (the rounding of J's entries and of the elimination). `W⁻¹` damps it in
    /// the stiff directions but multiplies it by `hγ` in slow and conserved ones, and the
    /// error control cannot see it: main and embedded solution share every stage. Its size is
    /// estimated as `|W⁻¹ (ε·|J|·|y_new − y|)|`, one matrix–vector product and one solve per
    /// accepted step. Where this exceeds `atol_i / rtol` — the size below which the tolerance
    /// stops asking for relative accuracy, i.e. the smallest value the user declared
    /// significant — the step cannot deliver that component to the tolerance asked for: an
    /// error of this size in a conserved direction never decays (E5 of the Test Set: the
    /// invariant y₂ − y₃ − y₄ drifts by ~1e-21 per step at the peak, its end values are 1e-22).
    /// Radau5's result is defined by a residual in `f` alone and does not have this floor.
    fn rounding_floor(
        &mut self,
        y: &OVector<f64, D>,
        y_new: &OVector<f64, D>,
        ctx: &Ctx<D>,
    ) -> Option<(usize, f64)> {
        let n = y.len();
        self.fu.fill(0.0);
        // Column by column (J is stored by columns).
        let fu = self.fu.as_mut_slice();
        for (j, col) in self.jac.as_slice().chunks_exact(n.max(1)).enumerate() {
            let d = f64::EPSILON * (y_new[j] - y[j]).abs();
            for (v, a) in fu.iter_mut().zip(col) {
                *v += a.abs() * d;
            }
        }
        self.lu.solve_mut(&mut self.fu);
        (0..n)
            .find(|&i| self.fu[i].abs() * ctx.rtol > ctx.atol[i])
            .map(|i| (i, self.fu[i].abs()))
    }

    /// The component and floor of the last step refused by [`Self::rounding_floor`].
    pub fn floor_hit(&self) -> Option<(usize, f64)> {
        self.floor_hit
    }
}

impl<D: Dim, S: OdeSystem<D> + ?Sized> Stepper<D, S> for Rodas5P<D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    fn error_order(&self) -> f64 {
        5.0
    }

    fn restart(&mut self, sys: &S, t: f64, y: &OVector<f64, D>, ctx: &mut Ctx<D>) {
        ctx.rhs(sys, t, y, &mut self.f0);
        self.f0_valid = true;
        self.jac_valid = false;
        self.lu.invalidate();
    }

    fn f0(&self) -> &OVector<f64, D> {
        &self.f0
    }

    fn attempt(&mut self, sys: &S, step: Step<'_, D>, ctx: &mut Ctx<D>) -> Trial {
        let Step { t, h, y, y_new } = step;
        let fail = |kind| Trial::Failed { factor: 0.25, kind };
        if !self.f0_valid {
            ctx.rhs(sys, t, y, &mut self.f0);
            self.f0_valid = true;
        }
        if !all_finite(&self.f0) {
            return fail(FailKind::NonFinite);
        }
        if !self.jac_valid {
            if !eval_jacobian_and_time_derivative(
                sys,
                t,
                y,
                &self.f0,
                h,
                &mut self.jac,
                &mut self.dfdt,
                &mut self.fu,
                ctx,
            ) {
                return fail(FailKind::NonFinite);
            }
            if !all_finite(&self.dfdt) {
                return fail(FailKind::NonFinite);
            }
            self.dfdt_zero = self.dfdt.as_slice().iter().all(|&v| v == 0.0);
            self.jac_valid = true;
            self.lu.invalidate();
            if ctx.want_stiffness {
                self.rho.at_new_jacobian(&self.jac);
            }
        }
        if !self.lu.is_valid() || self.lu_h != h {
            // W = I/(hγ) − J.
            let n = y.len();
            let d = 1.0 / (h * GAMMA);
            let w = self.lu.m.as_mut_slice();
            for (wi, ji) in w.iter_mut().zip(self.jac.as_slice()) {
                *wi = -ji;
            }
            for i in 0..n {
                w[i * n + i] += d;
            }
            ctx.stats.lu_decomps += 1;
            if !self.lu.factor() {
                return Trial::Failed {
                    factor: 0.5,
                    kind: FailKind::Singular,
                };
            }
            self.lu_h = h;
        }
        let lu = &self.lu;
        let inv_h = 1.0 / h;
        for s in 0..8 {
            let (done, rest) = self.k.split_at_mut(s);
            let ks = &mut rest[0];
            if s == 0 {
                ks.copy_from(&self.f0);
            } else {
                if s <= 5 {
                    self.u.copy_from(y);
                    for (j, kj) in done.iter().enumerate().take(5) {
                        let a = A[s][j];
                        if a != 0.0 {
                            add_scaled(&mut self.u, a, kj);
                        }
                    }
                } else {
                    add_scaled(&mut self.u, 1.0, &done[s - 1]);
                }
                ctx.rhs(sys, t + C[s] * h, &self.u, ks);
            }
            for (j, kj) in done.iter().enumerate() {
                add_scaled(ks, CC[s][j] * inv_h, kj);
            }
            if D_T[s] != 0.0 && !self.dfdt_zero {
                add_scaled(ks, h * D_T[s], &self.dfdt);
            }
            lu.solve_mut(ks);
            ctx.stats.lin_solves += 1;
        }
        sum_into(y_new, &self.u, &self.k[7]);
        if !all_finite(y_new) {
            return fail(FailKind::NonFinite);
        }
        let err = ctx.err_norm(&self.k[7], y, y_new);
        if err <= 1.0 {
            if let Some((i, floor)) = self.rounding_floor(y, y_new, ctx) {
                self.floor_hit = Some((i, floor));
                return Trial::Failed {
                    factor: 1.0,
                    kind: FailKind::RoundingFloor,
                };
            }
        }
        Trial::Done { err }
    }

    fn accept(&mut self, _sys: &S, step: &Step<'_, D>, poly: &mut StepPoly, ctx: &mut Ctx<D>) {
        let Step { t, h, y, .. } = *step;
        let y_new = &*step.y_new;
        self.f0_valid = false;
        self.jac_valid = false;
        if !ctx.need_poly {
            return;
        }
        poly.begin(t, h, 4);
        let n = y.len();
        let ks: [&[f64]; 8] = std::array::from_fn(|j| &self.k[j].as_slice()[..n]);
        let (y0, y1) = (&y.as_slice()[..n], &y_new.as_slice()[..n]);
        let [a0, a1, a2, a3, a4] = poly.rows_mut::<5>();
        for i in 0..n {
            // w_r = Σ_j H[r][j] k_j, summed in the order of j.
            let mut w = [0.0; 3];
            for (j, kj) in ks.iter().enumerate() {
                let k = kj[i];
                w[0] += H[0][j] * k;
                w[1] += H[1][j] * k;
                w[2] += H[2][j] * k;
            }
            a0[i] = y0[i];
            a1[i] = y1[i] - y0[i] + w[0];
            a2[i] = w[1] - w[0];
            a3[i] = w[2] - w[1];
            a4[i] = -w[2];
        }
    }

    fn stiffness(&self) -> Option<f64> {
        self.rho.get()
    }

    fn stiffness_exact(&mut self) -> Option<f64> {
        self.rho.exact(&self.jac, &self.f0)
    }
}
