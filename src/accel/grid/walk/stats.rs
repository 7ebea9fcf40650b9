//! What a walk counts of its work, for the benchmark's statistics: cells, leaps, steps,
//! tests. The unit type counts nothing and compiles away.

/// Counts the work a traversal does, for the benchmark's statistics. The unit type counts
/// nothing and compiles away.
pub trait TraversalStats {
    /// One cell (or one skipped stretch of empty macrocells) stepped through.
    fn visit_cell(&mut self) {}
    /// The walk entered an occupied macrocell (and asked for its record).
    fn enter_macrocell(&mut self) {}
    /// The walk leapt over a box of empty macrocells ([`crate::accel::grid::storage::reach`]).
    fn leap_macrocells(&mut self) {}
    /// The walk leapt over an empty cube of cells ([`crate::accel::grid::storage::cell_reach`]).
    fn leap_cells(&mut self) {}
    /// The walk stepped from an empty cell to the next one (plain 3D-DDA step).
    fn step_cell(&mut self) {}
    /// One occupied cell reached (its triangles are then tested).
    fn visit_occupied(&mut self) {}
    /// The walk ahead of a tested cell stopped at the next occupied macrocell
    /// ([`super::occupied::OccupiedCells::next`]).
    fn pause_ahead(&mut self) {}
    /// Ray–triangle tests (the triangles of one block, tested together).
    fn test_triangles(&mut self, _count: usize) {}
    /// One instance considered by the top level (its bounding box tested, and its grid
    /// walked if that is hit).
    fn test_instance(&mut self) {}
}

impl TraversalStats for () {}

/// Cells visited and triangles tested, summed over rays.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraversalCounts {
    /// Cells and skipped stretches of empty macrocells stepped through.
    pub cells: u64,
    /// Entries into occupied macrocells (each asks for the macrocell's record).
    pub macrocell_entries: u64,
    /// Leaps over boxes of empty macrocells.
    pub macrocell_leaps: u64,
    /// Leaps over empty cubes of cells.
    pub cell_leaps: u64,
    /// Plain steps out of empty cells.
    pub plain_steps: u64,
    /// Occupied cells reached.
    pub occupied: u64,
    /// Walks ahead of a tested cell stopped at the next occupied macrocell.
    pub pauses: u64,
    /// Ray–triangle tests.
    pub tests: u64,
    /// Instances considered by the top level.
    pub instances: u64,
}

impl TraversalStats for TraversalCounts {
    fn visit_cell(&mut self) {
        self.cells += 1;
    }
    fn enter_macrocell(&mut self) {
        self.macrocell_entries += 1;
    }
    fn leap_macrocells(&mut self) {
        self.macrocell_leaps += 1;
    }
    fn leap_cells(&mut self) {
        self.cell_leaps += 1;
    }
    fn step_cell(&mut self) {
        self.plain_steps += 1;
    }
    fn visit_occupied(&mut self) {
        self.occupied += 1;
    }
    fn pause_ahead(&mut self) {
        self.pauses += 1;
    }
    fn test_triangles(&mut self, count: usize) {
        self.tests += count as u64;
    }
    fn test_instance(&mut self) {
        self.instances += 1;
    }
}
