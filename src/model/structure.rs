//! The slider's structure: lumped masses, springs and dampers, and where the bulge sits on them.
//!
//! The equation of motion is `M q̈ + C q̇ + K q = e₀ F_ab(q₀, q̇₀) + b F_if`: degree of freedom 0
//! is the heave of the slider body, where the air-bearing law acts; the interface force acts on
//! the bulge, whose displacement is `bᵀq`. Everything is stored in fixed-size matrices of
//! [`MAX_DOF`] rows; only the first [`Structure::dofs`] are used, and the state of an ODE holds
//! only those.

use nalgebra::{DMatrix, SMatrix, SVector};

use super::condensed::QuasiStaticBulge;
use crate::error::{check_finite, check_non_negative, check_positive};
use crate::scene::{Scene, StructureSpec, MAX_DOF};
use crate::{Error, Result};

/// Generalised coordinates `q` (m for translations, rad for rotations); entries beyond
/// [`Structure::dofs`] are zero.
pub type Dofs = SVector<f64, MAX_DOF>;

/// All coordinates zero (callable where generic allocator bounds hide `Dofs::zeros`).
pub(crate) fn zero_dofs() -> Dofs {
    Dofs::zeros()
}

/// A matrix over the generalised coordinates.
pub(crate) type DofMatrix = SMatrix<f64, MAX_DOF, MAX_DOF>;

/// The bordered system of [`Structure::displaced_bulge`]: coordinates plus the load.
type Bordered = SMatrix<f64, { MAX_DOF + 1 }, { MAX_DOF + 1 }>;

/// A linear structure on the air bearing: `M q̈ + C q̇ + K q = e₀ F_ab(q₀, q̇₀) + b F_if`, with
/// coordinate 0 the body heave (where the air-bearing law acts) and the bulge at `bᵀq`.
///
/// ```
/// use hdi_tribology::model::Structure;
/// let s = Structure::bulge(1e-6, 1e-13, 4e5, 0.05)?;
/// assert_eq!(s.dofs(), 2);
/// // A bulge far lighter than the body rings at √(k_b/m_b)/2π:
/// let f = s.natural_frequencies(3e5);
/// let exact = (4e5f64 / 1e-13).sqrt() / (2.0 * std::f64::consts::PI);
/// assert!((f[1] - exact).abs() < 1e-6 * exact);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Structure {
    n: usize,
    mass: DofMatrix,
    mass_inverse: DofMatrix,
    diagonal_mass: bool,
    damping: DofMatrix,
    stiffness: DofMatrix,
    bulge: Dofs,
    /// Length per unit of each coordinate (1 for translations, the lever for rotations): makes
    /// the convergence tests of the static solvers dimensionally consistent.
    length_scale: Dofs,
    /// Influence of a rigid translation of the disk on each coordinate (see
    /// [`Structure::base_influence`]).
    base: Dofs,
}

impl Structure {
    /// One rigid mass (kg): today's slider.
    ///
    /// ```
    /// let s = hdi_tribology::model::Structure::rigid(1e-6)?;
    /// assert_eq!((s.dofs(), s.bulge_influence()), (1, &[1.0][..]));
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn rigid(mass: f64) -> Result<Self> {
        check_positive("slider.mass_kg", mass)?;
        let mut s = Self::build(
            1,
            &[[mass]],
            &[[0.0]],
            &[[0.0]],
            &[1.0],
            "structure",
            Kind::Symmetric,
        )?;
        s.base[0] = 1.0;
        Ok(s)
    }

    /// Body of mass `body_mass` (kg) on the air bearing, and the bulge of mass `bulge_mass` (kg)
    /// on a spring `stiffness` (N/m) and damper of damping ratio `damping_ratio` to the body.
    /// Coordinates: body heave, bulge displacement (both absolute).
    pub fn bulge(
        body_mass: f64,
        bulge_mass: f64,
        stiffness: f64,
        damping_ratio: f64,
    ) -> Result<Self> {
        check_positive("slider.mass_kg", body_mass)?;
        check_positive("structure.mass_kg", bulge_mass)?;
        check_positive("structure.stiffness_n_per_m", stiffness)?;
        check_non_negative("structure.damping_ratio", damping_ratio)?;
        let (k, c) = (
            stiffness,
            2.0 * damping_ratio * (stiffness * bulge_mass).sqrt(),
        );
        let mut s = Self::build(
            2,
            &[[body_mass, 0.0], [0.0, bulge_mass]],
            &[[c, -c], [-c, c]],
            &[[k, -k], [-k, k]],
            &[0.0, 1.0],
            "structure",
            Kind::Symmetric,
        )?;
        // Both coordinates are absolute translations: a disk translation moves both.
        s.base[0] = 1.0;
        s.base[1] = 1.0;
        Ok(s)
    }

    /// Body heave (mass `body_mass`, kg) and pitch (inertia `inertia`, kg m²) with the air
    /// bearing's pitch stiffness `k_pitch` (N m/rad), heave–pitch coupling `k_coupling` (N/rad),
    /// pitch damping `c_pitch` (N m s/rad) and coupling damping `c_coupling` (N s/rad); the bulge
    /// sits at `trailing_edge` (m) from the pivot: `z = y + L θ`.
    pub fn pitch(
        body_mass: f64,
        inertia: f64,
        [k_pitch, k_coupling]: [f64; 2],
        [c_pitch, c_coupling]: [f64; 2],
        trailing_edge: f64,
    ) -> Result<Self> {
        Self::heave_pitch(
            [body_mass, inertia],
            [[0.0, c_coupling], [c_coupling, c_pitch]],
            [[0.0, k_coupling], [k_coupling, k_pitch]],
            trailing_edge,
            ("structure", Kind::Symmetric),
        )
    }

    /// Body heave and pitch (`[mass, inertia]`) with the off-heave damping `c` and stiffness
    /// `k`, the bulge at `trailing_edge` from the pivot; the matrices checked as `coefficients`
    /// and named under `prefix`.
    fn heave_pitch(
        [body_mass, inertia]: [f64; 2],
        c: [[f64; 2]; 2],
        k: [[f64; 2]; 2],
        trailing_edge: f64,
        (prefix, coefficients): (&str, Kind),
    ) -> Result<Self> {
        check_positive("slider.mass_kg", body_mass)?;
        check_positive("structure.inertia_kg_m2", inertia)?;
        check_finite("structure.trailing_edge_m", trailing_edge)?;
        let mass = [[body_mass, 0.0], [0.0, inertia]];
        let bulge = [1.0, trailing_edge];
        let mut s = Self::build(2, &mass, &c, &k, &bulge, prefix, coefficients)?;
        if trailing_edge != 0.0 {
            s.length_scale[1] = trailing_edge.abs();
        }
        // The pitch and its stiffness are relative to the disk plane; a disk translation does
        // not rotate the slider.
        s.base[0] = 1.0;
        Ok(s)
    }

    /// Body heave (mass `body_mass`, kg) and pitch (inertia `inertia`, kg m²) on an air bearing
    /// whose heave–pitch stiffness `k` and damping `c` (2 × 2, rows heave force and pitch
    /// moment, columns heave and pitch; N/m, N/rad, N m/m, N m/rad and the same times s) come
    /// from its Reynolds equation, with the bulge at `trailing_edge` (m) from the pivot:
    /// [`ReynoldsBearing::heave_pitch`](crate::force::ReynoldsBearing::heave_pitch) gives the
    /// three. The heave entries `k[0][0]`, `c[0][0]` are the bearing's heave law on coordinate
    /// 0, not part of the structure's matrices; the others are.
    ///
    /// Unlike [`Structure::pitch`], the matrices need not be symmetric and the pitch damping
    /// may be negative: they are the coefficients of a gas film that the disk drives, not
    /// springs and dampers (see `docs/air_bearing.md`).
    ///
    /// ```
    /// use hdi_tribology::model::Structure;
    /// // The example slider's bearing at 65² (tests/bearing_pitch_structure.rs).
    /// let k = [[2.4e5, 1.23e2], [3.89e1, 0.106]];
    /// let c = [[9.9, -4.5e-3], [3.4e-3, -6.6e-7]];
    /// let s = Structure::pitch_on_bearing(4.1e-6, 1.4e-12, k, c, 1e-3)?;
    /// assert_eq!(s.stiffness_matrix()[(1, 0)], 3.89e1);
    /// assert_eq!(s.damping_matrix()[(1, 1)], -6.6e-7);
    /// assert_eq!(s.stiffness_matrix()[(0, 0)], 0.0); // the heave law's
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn pitch_on_bearing(
        body_mass: f64,
        inertia: f64,
        k: [[f64; 2]; 2],
        c: [[f64; 2]; 2],
        trailing_edge: f64,
    ) -> Result<Self> {
        let off = |m: [[f64; 2]; 2]| [[0.0, m[0][1]], [m[1][0], m[1][1]]];
        Self::heave_pitch(
            [body_mass, inertia],
            off(c),
            off(k),
            trailing_edge,
            ("air_bearing", Kind::Film),
        )
    }

    /// Any structure of 1 to [`MAX_DOF`] coordinates: `M`, `C`, `K` (rows) and the bulge
    /// influence vector `b`. `M` must be symmetric positive definite, `C` and `K`
    /// symmetric (the air bearing's heave law is added on coordinate 0).
    ///
    /// ```
    /// use hdi_tribology::model::Structure;
    /// let m = vec![vec![1e-6, 0.0], vec![0.0, 1e-13]];
    /// let k = vec![vec![4e5, -4e5], vec![-4e5, 4e5]];
    /// let c = vec![vec![0.0; 2]; 2];
    /// assert!(Structure::general(&m, &c, &k, &[0.0, 1.0]).is_ok());
    /// let bad = vec![vec![1e-6, 0.0], vec![0.0, -1e-13]];
    /// let e = Structure::general(&bad, &c, &k, &[0.0, 1.0]).unwrap_err().to_string();
    /// assert!(e.contains("structure.mass"), "{e}");
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn general(
        mass: &[Vec<f64>],
        damping: &[Vec<f64>],
        stiffness: &[Vec<f64>],
        bulge_influence: &[f64],
    ) -> Result<Self> {
        StructureSpec::General {
            mass: mass.to_vec(),
            damping: damping.to_vec(),
            stiffness: stiffness.to_vec(),
            bulge_influence: bulge_influence.to_vec(),
        }
        .validate()?;
        let n = bulge_influence.len();
        let rows = |m: &[Vec<f64>]| {
            let mut a = [[0.0; MAX_DOF]; MAX_DOF];
            for (i, row) in m.iter().enumerate() {
                a[i][..n].copy_from_slice(row);
            }
            a
        };
        let mut b = [0.0; MAX_DOF];
        b[..n].copy_from_slice(bulge_influence);
        let mut s = Self::build(
            n,
            &rows(mass),
            &rows(damping),
            &rows(stiffness),
            &b,
            "structure",
            Kind::Symmetric,
        )?;
        s.base = s.rigid_translation();
        Ok(s)
    }

    /// The structure a `[structure]` section describes, with the body mass `body_mass` (kg).
    /// A `pitch` preset that takes its matrices from the air bearing (`from_bearing = true`)
    /// needs the scene's bearing: build it with [`Structure::from_scene`].
    pub fn from_spec(spec: &StructureSpec, body_mass: f64) -> Result<Self> {
        spec.validate()?;
        match spec {
            StructureSpec::Rigid => Self::rigid(body_mass),
            &StructureSpec::Bulge {
                mass_kg,
                stiffness_n_per_m,
                damping_ratio,
            } => Self::bulge(body_mass, mass_kg, stiffness_n_per_m, damping_ratio),
            StructureSpec::Pitch { .. } => match spec.pitch_values() {
                Some((inertia, stiffness, damping, trailing_edge)) => {
                    Self::pitch(body_mass, inertia, stiffness, damping, trailing_edge)
                }
                None => Err(Error::invalid(
                    "structure.from_bearing",
                    "the matrices come from the scene's air bearing: build the structure with \
                     Structure::from_scene",
                )),
            },
            StructureSpec::General {
                mass,
                damping,
                stiffness,
                bulge_influence,
            } => Self::general(mass, damping, stiffness, bulge_influence),
        }
    }

    /// The structure of a scene: its `[structure]` section with the body mass `slider.mass_kg`,
    /// and for a `pitch` preset with `from_bearing = true` the [`Structure::pitch_on_bearing`]
    /// of the scene's `reynolds` air bearing: its
    /// [`heave_pitch`](crate::force::ReynoldsBearing::heave_pitch) stiffness and damping and the
    /// lever of its bulge ([`bulge_lever`](crate::force::ReynoldsBearing::bulge_lever)). The
    /// bearing is the one the scene's validation solved (solved once per process).
    ///
    /// ```
    /// use hdi_tribology::model::Structure;
    /// use hdi_tribology::scene::Scene;
    /// assert_eq!(Structure::from_scene(&Scene::paper())?, Structure::rigid(1e-6)?);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn from_scene(scene: &Scene) -> Result<Self> {
        let body_mass = scene.slider.mass_kg;
        scene.structure.validate()?;
        match (&scene.structure, scene.structure_bearing()?) {
            (&StructureSpec::Pitch { inertia_kg_m2, .. }, Some(bearing)) => {
                let (k, c, _) = bearing.heave_pitch();
                Self::pitch_on_bearing(body_mass, inertia_kg_m2, k, c, bearing.bulge_lever())
            }
            (spec, _) => Self::from_spec(spec, body_mass),
        }
    }

    /// The structure of `n` coordinates with these matrices (their first `n` rows and columns)
    /// and bulge influence, errors naming `{prefix}.mass` etc.; the damping and stiffness checked
    /// as `coefficients`.
    fn build<const R: usize>(
        n: usize,
        mass: &[[f64; R]],
        damping: &[[f64; R]],
        stiffness: &[[f64; R]],
        bulge: &[f64],
        prefix: &str,
        coefficients: Kind,
    ) -> Result<Self> {
        let fill = |rows: &[[f64; R]]| {
            let mut m = DofMatrix::zeros();
            for i in 0..n {
                for j in 0..n {
                    m[(i, j)] = rows[i][j];
                }
            }
            m
        };
        let (m, c, k) = (fill(mass), fill(damping), fill(stiffness));
        let mut b = Dofs::zeros();
        for i in 0..n {
            b[i] = bulge[i];
        }
        for (name, a, kind) in [
            ("mass", &m, Kind::Mass),
            ("damping", &c, coefficients),
            ("stiffness", &k, coefficients),
        ] {
            check_matrix(&format!("{prefix}.{name}"), a, n, kind)?;
        }
        let mut padded = m;
        for i in n..MAX_DOF {
            padded[(i, i)] = 1.0;
        }
        let mut mass_inverse = padded
            .try_inverse()
            .ok_or_else(|| Error::invalid(format!("{prefix}.mass"), "is singular"))?;
        for i in n..MAX_DOF {
            mass_inverse[(i, i)] = 0.0;
        }
        let diagonal_mass = (0..n).all(|i| (0..n).all(|j| i == j || m[(i, j)] == 0.0));
        let mut length_scale = Dofs::zeros();
        for i in 0..n {
            length_scale[i] = if i == 0 { 1.0 } else { b[i].abs().max(1.0) };
        }
        Ok(Structure {
            n,
            mass: m,
            mass_inverse,
            diagonal_mass,
            damping: c,
            stiffness: k,
            bulge: b,
            length_scale,
            base: Dofs::zeros(),
        })
    }

    /// The bulge mode as a [`QuasiStaticBulge`] where the structure is a body and a bulge of its
    /// own on a spring and damper (the `bulge` preset, or a `general` structure of that form):
    /// two coordinates, the bulge at coordinate 1, a diagonal mass, and the stiffness and
    /// damping of one spring and damper between them. `None` for any other structure.
    pub fn quasi_static_bulge(&self) -> Option<QuasiStaticBulge> {
        let pair = |a: &DofMatrix| {
            let x = a[(1, 1)];
            (a[(0, 0)] == x && a[(0, 1)] == -x && a[(1, 0)] == -x).then_some(x)
        };
        if self.n != 2 || self.bulge[0] != 0.0 || self.bulge[1] != 1.0 || !self.diagonal_mass {
            return None;
        }
        let k = pair(&self.stiffness).filter(|&k| k > 0.0)?;
        let c = pair(&self.damping)?;
        Some(QuasiStaticBulge::new(self.mass[(1, 1)], k, c))
    }

    /// Number of mechanical degrees of freedom.
    pub fn dofs(&self) -> usize {
        self.n
    }

    /// The bulge influence vector `b`.
    pub fn bulge_influence(&self) -> &[f64] {
        &self.bulge.as_slice()[..self.n]
    }

    /// The mass matrix `M` (n × n).
    pub fn mass_matrix(&self) -> DMatrix<f64> {
        self.mass.view((0, 0), (self.n, self.n)).into_owned()
    }

    /// The structural damping matrix `C` (n × n), without the air bearing's heave damping.
    pub fn damping_matrix(&self) -> DMatrix<f64> {
        self.damping.view((0, 0), (self.n, self.n)).into_owned()
    }

    /// The structural stiffness matrix `K` (n × n), without the air bearing's heave stiffness.
    pub fn stiffness_matrix(&self) -> DMatrix<f64> {
        self.stiffness.view((0, 0), (self.n, self.n)).into_owned()
    }

    /// The influence vector `r` of a rigid translation of the disk on each coordinate: a disk
    /// surface at height `w(t)` moves coordinate `i` by `r_i w` without loading the structure.
    ///
    /// The drive takes the state relative to the moving disk; every force of the model depends
    /// on those relative coordinates, and the disk's motion enters only through the inertia as
    /// the base excitation `−M r ẅ` (that is, `−r_i ẅ` on each acceleration). `r` is 1 on the
    /// rigid slider; `(1, 1)` on `bulge` (body and bulge are absolute translations); `(1, 0)` on
    /// `pitch` (a disk translation does not rotate the slider). For a `general` structure,
    /// `r₀ = 1` and coordinates `1..n` follow a unit heave with no structural force on them
    /// (`(K r)_i = 0` for `i ≥ 1`), exact when `K` holds the internal springs only; if that
    /// block of `K` is singular only the heave moves. A disk translation moves the bulge by
    /// `bᵀr` (1 for the presets).
    ///
    /// ```
    /// use hdi_tribology::model::Structure;
    /// assert_eq!(Structure::bulge(1e-6, 1e-13, 4e5, 0.05)?.base_influence(), &[1.0, 1.0][..]);
    /// let p = Structure::pitch(1e-6, 1e-12, [1e-3, 0.0], [0.0, 0.0], 5e-4)?;
    /// assert_eq!(p.base_influence(), &[1.0, 0.0][..]);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn base_influence(&self) -> &[f64] {
        &self.base.as_slice()[..self.n]
    }

    /// `r` of a general structure (see [`Structure::base_influence`]).
    fn rigid_translation(&self) -> Dofs {
        let mut r = Dofs::zeros();
        r[0] = 1.0;
        let m = self.n - 1;
        if m == 0 {
            return r;
        }
        let k = nalgebra::DMatrix::from_fn(m, m, |i, j| self.stiffness[(i + 1, j + 1)]);
        let rhs = nalgebra::DVector::from_fn(m, |i, _| -self.stiffness[(i + 1, 0)]);
        if let Some(x) = k.lu().solve(&rhs) {
            if x.iter().all(|v| v.is_finite()) {
                for i in 0..m {
                    r[i + 1] = x[i];
                }
            }
        }
        r
    }

    /// The body mass `M₀₀` (kg).
    pub fn body_mass(&self) -> f64 {
        self.mass[(0, 0)]
    }

    /// The bulge displacement `bᵀq` (m).
    #[inline]
    pub fn bulge_displacement(&self, q: &Dofs) -> f64 {
        self.bulge.dot(q)
    }

    /// The bulge influence vector `b` as coordinates.
    pub(crate) fn bulge_vector(&self) -> Dofs {
        self.bulge
    }

    /// Whether a tangent `J` is positive (one coordinate) or has a positive determinant.
    pub(crate) fn is_positive(&self, j: &DofMatrix) -> bool {
        if self.n == 1 {
            return j[(0, 0)] > 0.0;
        }
        if self.n == 2 {
            return j[(0, 0)] * j[(1, 1)] - j[(0, 1)] * j[(1, 0)] > 0.0;
        }
        let mut padded = *j;
        for i in self.n..MAX_DOF {
            padded[(i, i)] = 1.0;
        }
        padded.determinant() > 0.0
    }

    /// The length per unit of coordinate `i` (1 for translations, the lever for rotations).
    pub(crate) fn length_scale(&self, i: usize) -> f64 {
        self.length_scale[i]
    }

    /// `M⁻¹ f` (a diagonal mass divides, so the one-mass slider is exactly `f/m`).
    #[inline]
    pub(crate) fn mass_solve(&self, f: &Dofs) -> Dofs {
        if self.diagonal_mass {
            let mut a = Dofs::zeros();
            for i in 0..self.n {
                a[i] = f[i] / self.mass[(i, i)];
            }
            a
        } else {
            self.mass_inverse * f
        }
    }

    /// The generalised force `e₀ f_heave + b f_bulge − K q − C v`.
    #[inline]
    pub(crate) fn generalised_force(&self, q: &Dofs, v: &Dofs, f_heave: f64, f_bulge: f64) -> Dofs {
        let mut f = Dofs::zeros();
        for i in 0..self.n {
            let mut x = self.bulge[i] * f_bulge;
            if i == 0 {
                x += f_heave;
            }
            for j in 0..self.n {
                x -= self.stiffness[(i, j)] * q[j];
                x -= self.damping[(i, j)] * v[j];
            }
            f[i] = x;
        }
        f
    }

    /// Tangent stiffness `K + e₀e₀ᵀ k_heave − b (f_b bᵀ + f_p e₀ᵀ)`, for a heave stiffness
    /// `k_heave` and an interface force whose derivatives along the bulge and pad gaps are `f_b`
    /// and `f_p`.
    pub(crate) fn tangent(&self, k_heave: f64, f_b: f64, f_p: f64) -> DofMatrix {
        let mut j = self.stiffness;
        j[(0, 0)] += k_heave;
        for r in 0..self.n {
            for c in 0..self.n {
                let pad = if c == 0 { f_p } else { 0.0 };
                j[(r, c)] -= self.bulge[r] * (f_b * self.bulge[c] + pad);
            }
        }
        j
    }

    /// The damping `C + e₀e₀ᵀ c_heave`.
    pub(crate) fn damping_with(&self, c_heave: f64) -> DofMatrix {
        let mut c = self.damping;
        c[(0, 0)] += c_heave;
        c
    }

    /// Solves `J x = r` on the used block; `None` when `J` is singular.
    pub(crate) fn solve(&self, j: &DofMatrix, r: &Dofs) -> Option<Dofs> {
        if self.n == 1 {
            let x = r[0] / j[(0, 0)];
            return x.is_finite().then(|| Dofs::new(x, 0.0, 0.0));
        }
        if self.n == 2 {
            // Cramer's rule: the presets' case, several times cheaper than a padded LU.
            let det = j[(0, 0)] * j[(1, 1)] - j[(0, 1)] * j[(1, 0)];
            let x0 = (r[0] * j[(1, 1)] - j[(0, 1)] * r[1]) / det;
            let x1 = (j[(0, 0)] * r[1] - r[0] * j[(1, 0)]) / det;
            return (x0.is_finite() && x1.is_finite()).then(|| {
                let mut x = Dofs::zeros();
                x[0] = x0;
                x[1] = x1;
                x
            });
        }
        let mut padded = *j;
        for i in self.n..MAX_DOF {
            padded[(i, i)] = 1.0;
        }
        let x = padded.lu().solve(r)?;
        x.iter().all(|v| v.is_finite()).then_some(x)
    }

    /// Static condensation onto the bulge: the stiffness `1/(bᵀ J⁻¹ b)` that a force on the
    /// bulge meets through the whole structure with tangent `J` (N/m). Zero where `J` is
    /// singular; for one coordinate `J₀₀/b₀²`.
    pub(crate) fn condensed(&self, j: &DofMatrix) -> f64 {
        if self.n == 1 {
            let b = self.bulge[0];
            return if b == 1.0 {
                j[(0, 0)]
            } else {
                j[(0, 0)] / (b * b)
            };
        }
        match self.solve(j, &self.bulge) {
            Some(x) => 1.0 / self.bulge.dot(&x),
            None => 0.0,
        }
    }

    /// Largest change of `q` relative to the coordinates' length scales, for convergence tests.
    pub(crate) fn step_converged(&self, step: &Dofs, q: &Dofs, abs: f64, rel: f64) -> bool {
        (0..self.n).all(|i| {
            let s = self.length_scale[i];
            (step[i] * s).abs() <= abs + rel * (q[i] * s).abs()
        })
    }

    /// The coordinates that put the bulge at `z` (m) in static equilibrium with the heave law
    /// `heave(q₀) = (F_ab, k_ab)`, and the load on the bulge that holds it there: solves
    /// `K q − e₀ F_ab(q₀) = b F`, `bᵀq = z` by Newton's method. Returns `(q, F, ∂F/∂z)`; the
    /// last is the structure's stiffness condensed onto the bulge.
    pub(crate) fn displaced_bulge(
        &self,
        z: f64,
        heave: impl Fn(f64) -> (f64, f64),
        scale: f64,
    ) -> Result<(Dofs, f64, f64)> {
        if self.n == 1 {
            let b = self.bulge[0];
            let q0 = if b == 1.0 { z } else { z / b };
            let (f_ab, k_ab) = heave(q0);
            let load = (self.stiffness[(0, 0)] * q0 - f_ab) / b;
            let k = self.condensed(&self.tangent(k_ab, 0.0, 0.0));
            return Ok((Dofs::new(q0, 0.0, 0.0), load, k));
        }
        let n = self.n;
        let mut q = Dofs::zeros();
        let mut load = 0.0;
        for _ in 0..100 {
            let (f_ab, k_ab) = heave(q[0]);
            let j = self.tangent(k_ab, 0.0, 0.0);
            let mut a = Bordered::identity();
            let mut r = SVector::<f64, { MAX_DOF + 1 }>::zeros();
            for i in 0..n {
                for c in 0..n {
                    a[(i, c)] = j[(i, c)];
                }
                a[(i, n)] = -self.bulge[i];
                a[(n, i)] = self.bulge[i];
                let mut x = -self.bulge[i] * load;
                if i == 0 {
                    x -= f_ab;
                }
                for c in 0..n {
                    x += self.stiffness[(i, c)] * q[c];
                }
                r[i] = -x;
            }
            a[(n, n)] = 0.0;
            r[n] = z - self.bulge_displacement(&q);
            let Some(dx) = a.lu().solve(&r) else { break };
            let mut step = Dofs::zeros();
            for i in 0..n {
                step[i] = dx[i];
                q[i] += dx[i];
            }
            load += dx[n];
            if !load.is_finite() || q.iter().any(|x| !x.is_finite()) {
                break;
            }
            if self.step_converged(&step, &q, 1e-16 * scale, 1e-13) {
                let (_, k_ab) = heave(q[0]);
                return Ok((q, load, self.condensed(&self.tangent(k_ab, 0.0, 0.0))));
            }
        }
        Err(super::BalanceError::Structure { bulge_nm: z * 1e9 }.into())
    }

    /// Undamped natural frequencies (Hz) of the structure with a heave stiffness `k_heave`
    /// (N/m) on coordinate 0, ascending: `√eig(M⁻¹K)/2π`.
    ///
    /// ```
    /// use hdi_tribology::model::Structure;
    /// let f = Structure::rigid(1e-6)?.natural_frequencies(3e5);
    /// assert!((f[0] - (3e5f64 / 1e-6).sqrt() / (2.0 * std::f64::consts::PI)).abs() < 1e-6);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn natural_frequencies(&self, k_heave: f64) -> Vec<f64> {
        let k = self.tangent(k_heave, 0.0, 0.0);
        let n = self.n;
        if !self.is_symmetric(&k) {
            // A film's stiffness (Structure::pitch_on_bearing): the eigenvalues of M⁻¹K, whose
            // real parts give the frequencies (complex pairs would be a flutter).
            let mk = (self.mass_inverse * k).view((0, 0), (n, n)).into_owned();
            let mut w: Vec<f64> = mk
                .complex_eigenvalues()
                .iter()
                .map(|l| l.re.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
                .collect();
            w.sort_by(f64::total_cmp);
            return w;
        }
        // Symmetric form L⁻¹ K L⁻ᵀ with M = L Lᵀ.
        let m = self.mass_matrix();
        let Some(chol) = m.cholesky() else {
            return vec![f64::NAN; n];
        };
        let kd = k.view((0, 0), (n, n)).into_owned();
        let l = chol.l();
        let Some(linv) = l.clone().try_inverse() else {
            return vec![f64::NAN; n];
        };
        let s = &linv * kd * linv.transpose();
        let s = (&s + s.transpose()) * 0.5;
        let mut w: Vec<f64> = s
            .symmetric_eigenvalues()
            .iter()
            .map(|&l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
            .collect();
        w.sort_by(f64::total_cmp);
        w
    }
}

impl Structure {
    /// Whether `a` is symmetric on the used block (to the check's 10⁻¹² relative).
    fn is_symmetric(&self, a: &DofMatrix) -> bool {
        (0..self.n).all(|i| {
            (0..i).all(|j| {
                let (x, y) = (a[(i, j)], a[(j, i)]);
                (x - y).abs() <= 1e-12 * x.abs().max(y.abs())
            })
        })
    }

    /// The eigenvalues `λ` (1/s) of the free structure on an air bearing of heave stiffness
    /// `k_heave` (N/m) and damping `c_heave` (N s/m) on coordinate 0: the roots of
    /// `det(λ²M + λ(C + e₀e₀ᵀ c_heave) + K + e₀e₀ᵀ k_heave) = 0`, from the first-order form
    /// `[[0, I], [−M⁻¹K, −M⁻¹C]]`, by ascending imaginary part then real part. A mode with a
    /// positive real part grows.
    ///
    /// ```
    /// use hdi_tribology::model::Structure;
    /// // One mass on the bearing: λ = (−c ± √(c² − 4mk)) / 2m.
    /// let (m, k, c) = (1e-6, 3e5, 0.1);
    /// let l = Structure::rigid(m)?.modes(k, c);
    /// let (re, im) = (-c / (2.0 * m), (4.0 * m * k - c * c).sqrt() / (2.0 * m));
    /// assert!((l[1].re - re).abs() < 1e-9 * im && (l[1].im - im).abs() < 1e-9 * im);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn modes(&self, k_heave: f64, c_heave: f64) -> Vec<num_complex::Complex64> {
        let n = self.n;
        // Balanced for the eigensolver: each coordinate in length (the rotations times their
        // lever) and the velocities over a frequency of the stiffness, which keeps the entries
        // within a few orders of one another (a similarity: the eigenvalues are the same).
        let s = |i: usize| self.length_scale[i];
        let k = self.mass_inverse * self.tangent(k_heave, 0.0, 0.0);
        let c = self.mass_inverse * self.damping_with(c_heave);
        let ks = DMatrix::from_fn(n, n, |i, j| k[(i, j)] * s(i) / s(j));
        let cs = DMatrix::from_fn(n, n, |i, j| c[(i, j)] * s(i) / s(j));
        let w = ks.amax().sqrt().max(f64::MIN_POSITIVE);
        let a = DMatrix::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
            (true, true) => 0.0,
            (true, false) => {
                if j - n == i {
                    w
                } else {
                    0.0
                }
            }
            (false, true) => -ks[(i - n, j)] / w,
            (false, false) => -cs[(i - n, j - n)],
        });
        let mut l: Vec<_> = a.complex_eigenvalues().iter().copied().collect();
        l.sort_by(|p, q| p.im.total_cmp(&q.im).then(p.re.total_cmp(&q.re)));
        l
    }
}

/// What a matrix of a structure must be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    /// Symmetric positive definite.
    Mass,
    /// Symmetric: the springs and dampers of a structure, which store and dissipate energy
    /// (Maxwell–Betti reciprocity).
    Symmetric,
    /// Finite only: the coefficients of a gas film, a flow that the disk drives through the
    /// gap. Such a film is not a conservative spring: its stiffness is not the Hessian of an
    /// energy and need not be symmetric (the cross-coupled coefficients of fluid-film bearings,
    /// Lund 1987; those of the gas-lubricated slider bearing, Ono 1975), and the pressure lags
    /// the motion by the time the disk takes to carry the gas along the slider, which makes
    /// the low-frequency pitch damping of an air-bearing slider negative about a central pivot
    /// (docs/air_bearing.md, "Stiffness and damping", with its closed form).
    Film,
}

/// Finite on the used block; symmetric unless the coefficients of a film ([`Kind::Film`]);
/// positive definite for the mass. The stiffness and damping are not required to be
/// semi-definite on their own: the air bearing's heave law completes them (a pitch coupling
/// makes the structural part alone indefinite).
fn check_matrix(field: &str, a: &DofMatrix, n: usize, kind: Kind) -> Result<()> {
    for i in 0..n {
        for j in 0..n {
            check_finite(&format!("{field}[{i}][{j}]"), a[(i, j)])?;
            let (x, y) = (a[(i, j)], a[(j, i)]);
            if kind != Kind::Film && (x - y).abs() > 1e-12 * x.abs().max(y.abs()) {
                return Err(Error::invalid(
                    format!("{field}[{i}][{j}]"),
                    format!("the matrix must be symmetric, got {x:e} and [{j}][{i}] = {y:e}"),
                ));
            }
        }
    }
    if kind != Kind::Mass {
        return Ok(());
    }
    let block = a.view((0, 0), (n, n)).into_owned();
    let eig = block.symmetric_eigenvalues();
    let largest = eig.iter().fold(0.0f64, |m, &x| m.max(x.abs()));
    let smallest = eig.iter().copied().fold(f64::INFINITY, f64::min);
    if !(smallest > 1e-14 * largest && largest > 0.0) {
        return Err(Error::invalid(
            field,
            format!(
                "must be positive definite, its smallest eigenvalue is {smallest:e} (largest \
                 {largest:e})"
            ),
        ));
    }
    Ok(())
}
