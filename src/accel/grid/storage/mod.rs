//! How a grid keeps what the build found and the walk reads: the two-level index of
//! occupied cells ([`cells`]), the triangles in blocks of eight ([`block`]), how far empty
//! space reaches from empty macrocells ([`reach`]) and empty cells ([`cell_reach`]), and the
//! boxes of crowded cells and their blocks ([`cell_box`]).

pub(in crate::accel::grid) mod block;
pub(in crate::accel::grid) mod cell_box;
pub(in crate::accel::grid) mod cell_reach;
pub(in crate::accel::grid) mod cells;
pub(in crate::accel::grid) mod macrocell;
pub(in crate::accel::grid) mod reach;
