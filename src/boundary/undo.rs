//! What a step keeps of the boundary so that, should it fail, it can put the boundary back
//! as it was (docs/method.md §1.3). Where bodies move, their particles are placed anew every
//! step, and the whole boundary is copied. Otherwise a step changes the boundary only by
//! sorting it into a new grid, which reorders the particles: then the order is kept, with
//! the masses and the cell table the sort replaced, and putting the boundary back reorders
//! the particles back in place.

use super::Boundary;
use crate::neighbors::{CellTable, PointsByComponent};
use crate::permutation::unpermute_in_place;
use crate::reserve::copy_reusing;
use std::collections::TryReserveError;

/// What a [`BoundaryCopy`] holds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
enum Held {
    /// Nothing: the boundary was not changed.
    #[default]
    Nothing,
    /// The order the boundary was sorted into, with its masses, table and mark from before.
    Order,
    /// The whole boundary from before.
    Whole,
}

/// The boundary as it was before a step changed it (sorting it anew, placing the moving
/// bodies' particles), kept so that a step that fails can put it back
/// ([`Boundary::restore`]). A whole copy's storage is kept from step to step.
#[derive(Clone, Debug, Default)]
pub(crate) struct BoundaryCopy {
    held: Held,
    /// With a whole copy: the positions (m) and owners.
    positions: PointsByComponent,
    owner: Vec<u32>,
    /// With an order: the particle now in slot k was in slot `order[k]`.
    order: Vec<u32>,
    /// The masses ψ (kg), cell table and mark `dirty`.
    psi: Vec<f64>,
    table: CellTable,
    dirty: bool,
}

impl BoundaryCopy {
    /// Records that a boundary holding the masses `psi` (kg), the cell table `table` and the
    /// mark `dirty` was reordered so that slot k holds the particle that was in slot
    /// `order[k]`; after an order recorded before, the two make one. Nothing is recorded
    /// while a whole copy is held.
    pub(super) fn sorted(
        &mut self,
        mut order: Vec<u32>,
        psi: Vec<f64>,
        table: CellTable,
        dirty: bool,
    ) {
        match self.held {
            Held::Whole => {}
            Held::Order => {
                for o in &mut order {
                    *o = self.order[*o as usize];
                }
                self.order = order;
            }
            Held::Nothing => {
                self.held = Held::Order;
                self.order = order;
                self.psi = psi;
                self.table = table;
                self.dirty = dirty;
            }
        }
    }

    /// Forgets what is held, once the step that kept it succeeded. A whole copy's storage
    /// is kept for the next step's; an order, and the masses and table from before a sort,
    /// are freed.
    pub fn discard(&mut self) {
        if self.held == Held::Order {
            self.release();
        }
        self.held = Held::Nothing;
    }

    /// Frees the order, the masses and the table.
    fn release(&mut self) {
        self.order = Vec::new();
        self.psi = Vec::new();
        self.table = CellTable::default();
    }
}

impl Boundary {
    /// Copies the whole boundary into `copy`, unless it holds it already (as it was before
    /// the first change of a step): from this boundary, put back in its order from before a
    /// sort the copy recorded. Errors when memory for the copy cannot be had, changing
    /// nothing but `copy`'s storage.
    pub fn save(&self, copy: &mut BoundaryCopy) -> Result<(), TryReserveError> {
        if copy.held == Held::Whole {
            return Ok(());
        }
        copy.positions.try_copy_from(&self.positions)?;
        copy_reusing(&mut copy.owner, &self.owner)?;
        if copy.held == Held::Order {
            let (positions, owner) = (&mut copy.positions, &mut copy.owner);
            unpermute_in_place(&mut copy.order, |a, b| {
                positions.swap(a, b);
                owner.swap(a, b);
            });
            copy.order = Vec::new();
        } else {
            copy_reusing(&mut copy.psi, &self.psi)?;
            copy.table.try_copy_from(&self.table)?;
            copy.dirty = self.dirty;
        }
        copy.held = Held::Whole;
        Ok(())
    }

    /// Puts back the boundary `copy` holds, if it holds one (swapped or reordered in place,
    /// not copied: this cannot fail), and leaves `copy` holding none.
    pub fn restore(&mut self, copy: &mut BoundaryCopy) {
        let held = std::mem::take(&mut copy.held);
        match held {
            Held::Nothing => return,
            Held::Order => {
                let (positions, owner) = (&mut self.positions, &mut self.owner);
                unpermute_in_place(&mut copy.order, |a, b| {
                    positions.swap(a, b);
                    owner.swap(a, b);
                });
            }
            Held::Whole => {
                std::mem::swap(&mut self.positions, &mut copy.positions);
                std::mem::swap(&mut self.owner, &mut copy.owner);
            }
        }
        std::mem::swap(&mut self.psi, &mut copy.psi);
        std::mem::swap(&mut self.table, &mut copy.table);
        self.dirty = copy.dirty;
        if held == Held::Order {
            copy.release();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vec3;
    use crate::boundary::WALLS;
    use crate::kernel::CubicKernel;
    use crate::neighbors::UniformGrid;

    /// What a boundary holds that a step may change, for comparisons.
    fn state(b: &Boundary) -> (Vec<Vec3>, Vec<u32>, Vec<f64>, CellTable, bool) {
        let positions = b.positions.to_vec();
        (
            positions,
            b.owner.clone(),
            b.psi.clone(),
            b.table.clone(),
            b.dirty,
        )
    }

    /// A boundary of scattered static particles of two owners, unsorted.
    fn scattered() -> Boundary {
        let mut rng = crate::random::SplitMix64(3);
        let mut next = || Vec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64());
        let mut boundary = Boundary::default();
        let points: Vec<Vec3> = (0..600).map(|_| next()).collect();
        boundary.add_static(&points[..400], WALLS);
        boundary.add_static(&points[400..], 0);
        boundary
    }

    /// Sorts put back in place, one sort or two in a step, and from a boundary never sorted
    /// or sorted before, give the boundary back bit for bit; so does a whole copy taken
    /// after a sort.
    #[test]
    fn a_sorted_boundary_is_put_back_as_it_was() {
        let kernel = CubicKernel::new(0.1);
        let grid = |h: f64| UniformGrid::covering(Vec3::zeros(), Vec3::repeat(1.0), h).unwrap();
        let (fine, coarse) = (grid(0.1), grid(0.13));
        let mut boundary = scattered();
        let sort = |b: &mut Boundary, grid: &UniformGrid, copy: &mut BoundaryCopy| {
            b.sort(grid, &kernel, 1000.0, copy).unwrap();
        };
        let unsorted = state(&boundary);
        let mut copy = BoundaryCopy::default();
        sort(&mut boundary, &coarse, &mut copy);
        assert_ne!(state(&boundary), unsorted);
        let sorted = state(&boundary);
        boundary.restore(&mut copy);
        assert_eq!(state(&boundary), unsorted);

        sort(&mut boundary, &coarse, &mut copy);
        sort(&mut boundary, &fine, &mut copy);
        boundary.restore(&mut copy);
        assert_eq!(state(&boundary), unsorted);

        sort(&mut boundary, &coarse, &mut copy);
        copy.discard();
        assert_eq!(state(&boundary), sorted);
        for second in [false, true] {
            sort(&mut boundary, &fine, &mut copy);
            if second {
                sort(&mut boundary, &coarse, &mut copy);
                boundary.save(&mut copy).unwrap();
            }
            boundary.restore(&mut copy);
            assert_eq!(state(&boundary), sorted, "a second sort: {second}");
        }
    }
}
