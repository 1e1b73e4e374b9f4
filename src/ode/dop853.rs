//! Dormand–Prince explicit Runge–Kutta 8(5,3) after Hairer, Nørsett & Wanner, "Solving ODEs I"
//! (DOP853): 12 stages with FSAL, the combined 5th/3rd-order error estimate, and a 7th-order
//! continuous extension from 3 extra stages (computed only when interpolation is needed).

use super::dense::StepPoly;
use super::stepper::{
    all_finite, stage_spectral_radius, zeros_like, Ctx, FailKind, Step, Stepper, Trial,
};
use super::system::OdeSystem;
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OVector};

const C: [f64; 16] = [
    0.0,
    0.05260015195876773,
    0.0789002279381516,
    0.1183503419072274,
    0.2816496580927726,
    0.3333333333333333,
    0.25,
    0.3076923076923077,
    0.6512820512820513,
    0.6,
    0.8571428571428571,
    1.0,
    1.0,
    0.1,
    0.2,
    0.7777777777777778,
];
/// Stage coupling, rows 1..=15 (row 12 = the 8th-order weights, rows 13..=15 = the extra
/// stages of the continuous extension), lower-triangular, 16 columns.
const A: [[f64; 16]; 16] = [
    [
        0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
    ],
    [
        0.05260015195876773,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        0.0197250569845379,
        0.0591751709536137,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        0.02958758547680685,
        0.0,
        0.08876275643042054,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        0.2413651341592667,
        0.0,
        -0.8845494793282861,
        0.924834003261792,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        0.037037037037037035,
        0.0,
        0.0,
        0.17082860872947386,
        0.12546768756682242,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        0.037109375,
        0.0,
        0.0,
        0.17025221101954405,
        0.06021653898045596,
        -0.017578125,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        0.03709200011850479,
        0.0,
        0.0,
        0.17038392571223998,
        0.10726203044637328,
        -0.015319437748624402,
        0.008273789163814023,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        0.6241109587160757,
        0.0,
        0.0,
        -3.3608926294469414,
        -0.868219346841726,
        27.59209969944671,
        20.154067550477894,
        -43.48988418106996,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        0.47766253643826434,
        0.0,
        0.0,
        -2.4881146199716677,
        -0.590290826836843,
        21.230051448181193,
        15.279233632882423,
        -33.28821096898486,
        -0.020331201708508627,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        -0.9371424300859873,
        0.0,
        0.0,
        5.186372428844064,
        1.0914373489967295,
        -8.149787010746927,
        -18.52006565999696,
        22.739487099350505,
        2.4936055526796523,
        -3.0467644718982196,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        2.273310147516538,
        0.0,
        0.0,
        -10.53449546673725,
        -2.0008720582248625,
        -17.9589318631188,
        27.94888452941996,
        -2.8589982771350235,
        -8.87285693353063,
        12.360567175794303,
        0.6433927460157636,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        0.054293734116568765,
        0.0,
        0.0,
        0.0,
        0.0,
        4.450312892752409,
        1.8915178993145003,
        -5.801203960010585,
        0.3111643669578199,
        -0.1521609496625161,
        0.20136540080403034,
        0.04471061572777259,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        0.056167502283047954,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.25350021021662483,
        -0.2462390374708025,
        -0.12419142326381637,
        0.15329179827876568,
        0.00820105229563469,
        0.007567897660545699,
        -0.008298,
        0.0,
        0.0,
        0.0,
    ],
    [
        0.03183464816350214,
        0.0,
        0.0,
        0.0,
        0.0,
        0.028300909672366776,
        0.053541988307438566,
        -0.05492374857139099,
        0.0,
        0.0,
        -0.00010834732869724932,
        0.0003825710908356584,
        -0.00034046500868740456,
        0.1413124436746325,
        0.0,
        0.0,
    ],
    [
        -0.42889630158379194,
        0.0,
        0.0,
        0.0,
        0.0,
        -4.697621415361164,
        7.683421196062599,
        4.06898981839711,
        0.3567271874552811,
        0.0,
        0.0,
        0.0,
        -0.0013990241651590145,
        2.9475147891527724,
        -9.15095847217987,
        0.0,
    ],
];
const E3: [f64; 12] = [
    -0.18980075407240762,
    0.0,
    0.0,
    0.0,
    0.0,
    4.450312892752409,
    1.8915178993145003,
    -5.801203960010585,
    -0.4226823213237919,
    -0.1521609496625161,
    0.20136540080403034,
    0.02265179219836082,
];
const E5: [f64; 12] = [
    0.01312004499419488,
    0.0,
    0.0,
    0.0,
    0.0,
    -1.2251564463762044,
    -0.4957589496572502,
    1.6643771824549864,
    -0.35032884874997366,
    0.3341791187130175,
    0.08192320648511571,
    -0.022355307863886294,
];
const DENSE: [[f64; 16]; 4] = [
    [
        -8.428938276109013,
        0.0,
        0.0,
        0.0,
        0.0,
        0.5667149535193777,
        -3.0689499459498917,
        2.38466765651207,
        2.117034582445028,
        -0.871391583777973,
        2.2404374302607883,
        0.6315787787694688,
        -0.08899033645133331,
        18.148505520854727,
        -9.194632392478356,
        -4.436036387594894,
    ],
    [
        10.427508642579134,
        0.0,
        0.0,
        0.0,
        0.0,
        242.28349177525817,
        165.20045171727028,
        -374.5467547226902,
        -22.113666853125306,
        7.733432668472264,
        -30.674084731089398,
        -9.332130526430229,
        15.697238121770845,
        -31.139403219565178,
        -9.35292435884448,
        35.81684148639408,
    ],
    [
        19.985053242002433,
        0.0,
        0.0,
        0.0,
        0.0,
        -387.0373087493518,
        -189.17813819516758,
        527.8081592054236,
        -11.57390253995963,
        6.8812326946963,
        -1.0006050966910838,
        0.7777137798053443,
        -2.778205752353508,
        -60.19669523126412,
        84.32040550667716,
        11.99229113618279,
    ],
    [
        -25.69393346270375,
        0.0,
        0.0,
        0.0,
        0.0,
        -154.18974869023643,
        -231.5293791760455,
        357.6391179106141,
        93.40532418362432,
        -37.45832313645163,
        104.0996495089623,
        29.8402934266605,
        -43.53345659001114,
        96.32455395918828,
        -39.17726167561544,
        -149.72683625798564,
    ],
];

/// Where DOP853's stability region meets the negative real axis (`h·ρ`, about 6.0; Hairer's
/// code flags stiffness above 6.1).
const STABILITY_BOUNDARY: f64 = 6.0;

pub(crate) struct Dop853<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    k: [OVector<f64, D>; 16],
    stage: OVector<f64, D>,
    e3: OVector<f64, D>,
    e5: OVector<f64, D>,
    /// `h·ρ` of the last step (Hairer's indicator: the two evaluations at `t + h`).
    h_rho: Option<f64>,
}

impl<D: Dim> Dop853<D>
where
    DefaultAllocator: Allocator<D>,
{
    pub fn new(y: &OVector<f64, D>) -> Self {
        let z = zeros_like(y);
        Dop853 {
            k: std::array::from_fn(|_| z.clone()),
            stage: z.clone(),
            e3: z.clone(),
            e5: z,
            h_rho: None,
        }
    }

    /// Input of stage `s`: y + h Σ_j A[s][j] k_j, into `out`.
    fn stage_input(
        k: &[OVector<f64, D>],
        s: usize,
        y: &OVector<f64, D>,
        h: f64,
        out: &mut OVector<f64, D>,
    ) {
        out.copy_from(y);
        for (j, kj) in k.iter().enumerate().take(s) {
            let a = A[s][j];
            if a != 0.0 {
                out.axpy(h * a, kj, 1.0);
            }
        }
    }
}

impl<D: Dim, S: OdeSystem<D> + ?Sized> Stepper<D, S> for Dop853<D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    fn error_order(&self) -> f64 {
        8.0
    }

    fn restart(&mut self, sys: &S, t: f64, y: &OVector<f64, D>, ctx: &mut Ctx<D>) {
        ctx.rhs(sys, t, y, &mut self.k[0]);
    }

    fn f0(&self) -> &OVector<f64, D> {
        &self.k[0]
    }

    fn attempt(&mut self, sys: &S, step: Step<'_, D>, ctx: &mut Ctx<D>) -> Trial {
        let Step { t, h, y, y_new } = step;
        for (s, &cs) in C.iter().enumerate().take(12).skip(1) {
            Self::stage_input(&self.k, s, y, h, &mut self.stage);
            let (_, rest) = self.k.split_at_mut(s);
            sys.rhs_memo(t + cs * h, &self.stage, &mut rest[0], &mut ctx.memo);
        }
        Self::stage_input(&self.k, 12, y, h, y_new);
        let (_, rest) = self.k.split_at_mut(12);
        // Stages 11 and 12 share t + h: the system's values of that time are kept.
        sys.rhs_memo(t + h, y_new, &mut rest[0], &mut ctx.memo);
        ctx.stats.rhs_evals += 12;
        if !all_finite(y_new) || !all_finite(&self.k[12]) {
            return Trial::Failed {
                factor: 0.25,
                kind: FailKind::NonFinite,
            };
        }
        self.e3.fill(0.0);
        self.e5.fill(0.0);
        for j in 0..12 {
            if E3[j] != 0.0 {
                self.e3.axpy(E3[j], &self.k[j], 1.0);
            }
            if E5[j] != 0.0 {
                self.e5.axpy(E5[j], &self.k[j], 1.0);
            }
        }
        // The 5th-order estimate, damped where the 3rd-order one is much larger, so the step
        // stays reliable when the asymptotic regime is not yet reached.
        let n = y.len();
        let (mut s5, mut s3) = (0.0, 0.0);
        for i in 0..n {
            let sc = ctx.atol[i] + ctx.rtol * y[i].abs().max(y_new[i].abs());
            s5 += (self.e5[i] / sc).powi(2);
            s3 += (self.e3[i] / sc).powi(2);
        }
        // Stiffness indicator: stages 11 and 12 are both at `t + h` (C[11] = 1), at the inputs
        // `stage` and `y_new`; their difference quotient estimates the spectral radius.
        // Only `Auto` asks for it.
        if ctx.want_stiffness {
            self.h_rho = stage_spectral_radius(&self.k[12], &self.k[11], y_new, &self.stage)
                .map(|r| h.abs() * r);
        }
        let mut deno = s5 + 0.01 * s3;
        if deno.is_nan() || deno <= 0.0 {
            deno = 1.0;
        }
        Trial::Done {
            err: h.abs() * s5 / (n as f64 * deno).sqrt(),
        }
    }

    fn accept(&mut self, sys: &S, step: &Step<'_, D>, poly: &mut StepPoly, ctx: &mut Ctx<D>) {
        let Step { t, h, y, .. } = *step;
        let y_new = &*step.y_new;
        if ctx.need_poly {
            for (s, &cs) in C.iter().enumerate().skip(13) {
                Self::stage_input(&self.k, s, y, h, &mut self.stage);
                let (_, rest) = self.k.split_at_mut(s);
                sys.rhs(t + cs * h, &self.stage, &mut rest[0]);
            }
            ctx.stats.rhs_evals += 3;
            poly.begin(t, h, 7);
            for i in 0..y.len() {
                let dy = y_new[i] - y[i];
                let (f_old, f_new) = (self.k[0][i], self.k[12][i]);
                let mut f = [0.0; 7];
                f[0] = dy;
                f[1] = h * f_old - dy;
                f[2] = 2.0 * dy - h * (f_new + f_old);
                for (r, dr) in DENSE.iter().enumerate() {
                    f[3 + r] = h * dr
                        .iter()
                        .zip(self.k.iter())
                        .map(|(d, kj)| d * kj[i])
                        .sum::<f64>();
                }
                // y(x) = y0 + x(F0 + (1−x)(F1 + x(F2 + (1−x)(F3 + x(F4 + (1−x)(F5 + x F6)))))).
                let mut p = [0.0; 8];
                p[0] = f[6];
                let mul_x = |p: &mut [f64; 8]| {
                    for m in (1..8).rev() {
                        p[m] = p[m - 1];
                    }
                    p[0] = 0.0;
                };
                let mul_1mx = |p: &mut [f64; 8]| {
                    for m in (1..8).rev() {
                        p[m] -= p[m - 1];
                    }
                };
                mul_x(&mut p);
                p[0] += f[5];
                mul_1mx(&mut p);
                p[0] += f[4];
                mul_x(&mut p);
                p[0] += f[3];
                mul_1mx(&mut p);
                p[0] += f[2];
                mul_x(&mut p);
                p[0] += f[1];
                mul_1mx(&mut p);
                p[0] += f[0];
                mul_x(&mut p);
                p[0] += y[i];
                for (m, pm) in p.iter().enumerate() {
                    *poly.at(m, i) = *pm;
                }
            }
        }
        // FSAL.
        self.k.swap(0, 12);
    }

    fn stiffness(&self) -> Option<f64> {
        self.h_rho
    }

    fn stability_boundary(&self) -> f64 {
        STABILITY_BOUNDARY
    }
}
