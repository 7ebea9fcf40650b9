//! The size of a macrocell, the unit of the two-level index: every part of the storage
//! counts in it.

/// A macrocell is 2^MACRO_SHIFT cells along each axis.
pub(in crate::accel::grid) const MACRO_SHIFT: i32 = 3;
/// Cells per macrocell.
pub(in crate::accel::grid) const MACRO_CELLS: usize = 1 << (3 * MACRO_SHIFT);
