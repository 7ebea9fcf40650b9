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

    /// What a query is handed to count into: the counter itself for one that counts
    /// nothing (the unit type, no word at all), else a reference to it. Queries take their
    /// counter by value, so the query of a render is handed its grid and ray alone, in two
    /// registers (a third word, the unit's address, made shadow queries 1.05× as slow).
    type Lent<'a>: TraversalStats
    where
        Self: 'a;

    /// Lends the counter to one query.
    fn lend(&mut self) -> Self::Lent<'_>;
}

impl TraversalStats for () {
    type Lent<'a> = ();
    fn lend(&mut self) {}
}

/// A counter lent to a query counts as itself.
impl<T: TraversalStats> TraversalStats for &mut T {
    type Lent<'a>
        = T::Lent<'a>
    where
        Self: 'a;
    fn lend(&mut self) -> T::Lent<'_> {
        (**self).lend()
    }
    fn visit_cell(&mut self) {
        (**self).visit_cell();
    }
    fn enter_macrocell(&mut self) {
        (**self).enter_macrocell();
    }
    fn leap_macrocells(&mut self) {
        (**self).leap_macrocells();
    }
    fn leap_cells(&mut self) {
        (**self).leap_cells();
    }
    fn step_cell(&mut self) {
        (**self).step_cell();
    }
    fn visit_occupied(&mut self) {
        (**self).visit_occupied();
    }
    fn pause_ahead(&mut self) {
        (**self).pause_ahead();
    }
    fn test_triangles(&mut self, count: usize) {
        (**self).test_triangles(count);
    }
    fn test_instance(&mut self) {
        (**self).test_instance();
    }
}

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
    type Lent<'a> = &'a mut TraversalCounts;
    fn lend(&mut self) -> &mut TraversalCounts {
        self
    }
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
