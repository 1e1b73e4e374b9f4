//! In-place LU factorisation with partial pivoting for square nalgebra matrices of any
//! dimension, real or complex, reusing its storage (no allocation after construction).

use nalgebra::{allocator::Allocator, ComplexField, DefaultAllocator, Dim, OMatrix, OVector};

pub(crate) struct Lu<T: ComplexField, D: Dim>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// The matrix to factor; after `factor`, L (unit lower, below the diagonal) and U.
    pub m: OMatrix<T, D, D>,
    piv: OVector<usize, D>,
    /// Reciprocals of U's diagonal: the solves multiply by them (a division costs several
    /// multiplications' time, complex ones more).
    inv_diag: OVector<T, D>,
    valid: bool,
}

impl<T: ComplexField<RealField = f64>, D: Dim> Lu<T, D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    pub fn new(dim: D) -> Self {
        Lu {
            m: OMatrix::from_element_generic(dim, dim, T::zero()),
            piv: OVector::from_element_generic(dim, nalgebra::U1, 0),
            inv_diag: OVector::from_element_generic(dim, nalgebra::U1, T::zero()),
            valid: false,
        }
    }

    pub fn is_valid(&self) -> bool {
        self.valid
    }

    pub fn invalidate(&mut self) {
        self.valid = false;
    }

    /// Factors `m` in place; `false` if it is singular (a zero or non-finite pivot).
    pub fn factor(&mut self) -> bool {
        let n = self.m.nrows();
        self.valid = false;
        for k in 0..n {
            // Pivot on |re| + |im| (the modulus needs a hypot per entry and picks the same
            // magnitude up to a factor √2, which is all partial pivoting needs).
            let mut p = k;
            let mut best = self.m[(k, k)].clone().norm1();
            for i in k + 1..n {
                let v = self.m[(i, k)].clone().norm1();
                if v > best {
                    best = v;
                    p = i;
                }
            }
            if best.is_nan() || best <= 0.0 || !best.is_finite() {
                return false;
            }
            self.piv[k] = p;
            if p != k {
                self.m.swap_rows(p, k);
            }
            let inv_pivot = T::one() / self.m[(k, k)].clone();
            self.inv_diag[k] = inv_pivot.clone();
            for i in k + 1..n {
                self.m[(i, k)] *= inv_pivot.clone();
            }
            // Column by column (the storage order).
            for j in k + 1..n {
                let ukj = self.m[(k, j)].clone();
                if ukj == T::zero() {
                    continue;
                }
                for i in k + 1..n {
                    let lik = self.m[(i, k)].clone();
                    self.m[(i, j)] -= lik * ukj.clone();
                }
            }
        }
        self.valid = true;
        true
    }

    /// Solves `M x = b` in place with the factors.
    pub fn solve_mut(&self, b: &mut OVector<T, D>) {
        let n = self.m.nrows();
        for k in 0..n {
            let p = self.piv[k];
            if p != k {
                b.swap_rows(p, k);
            }
        }
        // Forward substitution by columns: each b[i] receives its terms in the same order as
        // by rows.
        for j in 0..n {
            let bj = b[j].clone();
            for i in j + 1..n {
                b[i] -= self.m[(i, j)].clone() * bj.clone();
            }
        }
        for i in (0..n).rev() {
            let mut s = b[i].clone();
            for j in i + 1..n {
                s -= self.m[(i, j)].clone() * b[j].clone();
            }
            b[i] = s * self.inv_diag[i].clone();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix4, Vector4, U4};
    use num_complex::Complex64;

    #[test]
    fn solves_real_system_with_pivoting() {
        // Zero leading pivot forces a row exchange.
        let m = Matrix4::new(
            0.0, 2.0, 1.0, 3.0, 4.0, 1.0, 0.5, 2.0, 1.0, 1.0, 5.0, 0.0, 2.0, 3.0, 1.0, 7.0,
        );
        let x = Vector4::new(1.0, -2.0, 0.5, 3.0);
        let mut b = m * x;
        let mut lu = Lu::<f64, U4>::new(U4);
        lu.m.copy_from(&m);
        assert!(lu.factor());
        lu.solve_mut(&mut b);
        assert!((b - x).amax() < 1e-13);
    }

    #[test]
    fn solves_complex_system_and_flags_singular() {
        let m = Matrix4::from_fn(|i, j| {
            Complex64::new((i + 2 * j) as f64, if i == j { 3.0 } else { -0.5 })
        });
        let x = Vector4::from_fn(|i, _| Complex64::new(i as f64, 1.0 - i as f64));
        let mut b = m * x;
        let mut lu = Lu::<Complex64, U4>::new(U4);
        lu.m.copy_from(&m);
        assert!(lu.factor());
        lu.solve_mut(&mut b);
        assert!((b - x).iter().all(|d| d.norm() < 1e-12));
        lu.m.fill(Complex64::new(1.0, 0.0));
        assert!(!lu.factor());
    }
}
