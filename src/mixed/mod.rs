//! Representations for arithmetic in f32 where f64 is not available (Metal, most integrated
//! GPUs, browsers): the CPU twins of what the mixed precision mode stores and how it computes
//! the few quantities that plain f32 cannot resolve.
//!
//! Why each exists is measured in `tests/precision_budget.rs` and written down in `DESIGN.md`
//! ("Precision"): in a 100 µm box a plain f32 position is good to 4.7·10⁻¹⁰ cm, three percent of
//! the JKR overlap scale δ₀ = 1.7·10⁻⁸ cm, and a wall that moves 3·10⁻¹⁰ cm per step (1 cm/s,
//! 0.3 ns) does not move at all. So:
//!
//! - [`split`]: a position is a voxel index (i32) and an f32 offset inside the voxel, and a pair's
//!   overlap is evaluated from the exact integer part and the small offsets separately;
//! - [`double_f32`]: an unevaluated sum of two f32 (about 48 bits) for the wall position, the
//!   constants a split overlap subtracts, and the accumulated energies and wall forces;
//! - [`split_pointer`]: contact pointers as double-f32 vectors turned by f32 increments, since a
//!   plain f32 pointer turned by the same small angle every step drifts systematically.

pub mod double_f32;
pub mod split;
pub mod split_pointer;
