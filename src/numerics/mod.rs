//! Numerical building blocks that know no physics and are shared by several modules.
//!
//! - [`rng`]: seeded pseudo-random generators whose streams are fixed by the crate alone
//!   (SplitMix64 and xoshiro256**), for the sampled surfaces, the fit's starting points and the
//!   drive's noise.
//!
//! ```
//! use hdi_tribology::numerics::rng::{SplitMix64, Xoshiro256};
//! let mut bits = SplitMix64::new(0);
//! assert_eq!(bits.next_u64(), 0xE220_A839_7B1D_CDAF); // the published first word for seed 0
//! let u = Xoshiro256::new(42).next_open01();
//! assert!(u > 0.0 && u < 1.0);
//! ```

pub mod rng;
