//! The drive's state buffers: their largest length and the state vector built from them.

use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OVector};

/// A state vector of dimension `dim` with components `value(i)`: an indexed loop, which costs a
/// tenth of collecting an iterator into a fixed-size vector on the drive's per-period path.
#[inline]
pub(crate) fn state_vector<D: Dim>(dim: D, value: impl Fn(usize) -> f64) -> OVector<f64, D>
where
    DefaultAllocator: Allocator<D>,
{
    OVector::<f64, D>::from_fn_generic(dim, nalgebra::U1, |i, _| value(i))
}

/// Longest state a drive integrates (the plant's largest sized integrator, and the buffers of
/// its schemes).
pub(crate) const MAX_STATE: usize = 11;
