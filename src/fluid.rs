//! Fluid particle storage: a structure of arrays in the order the last step sorted it, and
//! the particles' stable ids (docs/method.md §12.1).

use crate::Vec3;
use crate::material::MaterialId;

/// Fluid particles in their current storage order (Z-order after the first step).
#[derive(Clone, Debug, Default)]
pub(crate) struct Fluid {
    /// Positions (m).
    pub positions: Vec<Vec3>,
    /// Velocities (m/s).
    pub velocities: Vec<Vec3>,
    /// Densities after the last step, or where the fluid was last added (kg/m³).
    pub densities: Vec<f64>,
    /// The support each particle's constraints gave it in the last step, per unit mass
    /// (m/s²): its displacement from the inertial prediction over Δt², or zero where no
    /// active constraint moved it; the next step starts from a share of it
    /// (docs/method.md §4.1). Empty while the warm start is off, else one per particle.
    pub supports: Vec<Vec3>,
    /// Each particle's pressure from the constraint forces of the last step (Pa), one per
    /// particle; empty where the last step did not carry them (docs/method.md §10.1) or
    /// particles were added or moved since.
    pub pressures: Vec<f64>,
    /// Each particle's material (docs/method.md §14).
    pub materials: Vec<MaterialId>,
    /// Each stored particle's id: given in the order particles were added, never reused.
    pub ids: Vec<u64>,
    /// The ids of the stored particles in ascending order, the order of every read.
    pub ascending: Vec<u64>,
    /// The id the next added particle gets.
    pub next_id: u64,
    /// Particles removed so far.
    pub removed: u64,
}

impl Fluid {
    /// Number of particles.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// Appends particles of `material` at `positions` (m) with `velocities` (m/s), the
    /// densities zero, and gives them the next ids in order. The caller checked the lengths
    /// and values.
    pub fn push(
        &mut self,
        material: MaterialId,
        positions: &[Vec3],
        velocities: impl IntoIterator<Item = Vec3>,
    ) {
        self.extend(material, positions.iter().copied(), velocities);
    }

    /// [`Fluid::push`] from an iterator of positions (m), as many velocities (m/s) following.
    pub fn extend(
        &mut self,
        material: MaterialId,
        positions: impl IntoIterator<Item = Vec3>,
        velocities: impl IntoIterator<Item = Vec3>,
    ) {
        let first = self.next_id;
        let before = self.positions.len();
        self.positions.extend(positions);
        let count = (self.positions.len() - before) as u64;
        self.velocities.extend(velocities);
        self.densities.resize(self.positions.len(), 0.0);
        self.materials.resize(self.positions.len(), material);
        if !self.supports.is_empty() {
            self.supports.resize(self.positions.len(), Vec3::zeros());
        }
        self.pressures.clear();
        self.ids.extend(first..first + count);
        self.ascending.extend(first..first + count);
        self.next_id = first + count;
    }

    /// Removes the particles added since the fluid held `len` particles and gave out ids
    /// below `next_id` (those added last, with the last ids), as if never added.
    pub fn truncate(&mut self, len: usize, next_id: u64) {
        self.positions.truncate(len);
        self.velocities.truncate(len);
        self.densities.truncate(len);
        self.materials.truncate(len);
        self.supports.truncate(len);
        self.pressures.clear();
        self.ids.truncate(len);
        self.ascending.truncate(len);
        self.next_id = next_id;
    }

    /// The place of particle `id` (which must be stored) in ascending id order: the id itself
    /// while nothing was removed, else its index in [`Fluid::ascending`].
    #[inline]
    pub fn rank(&self, id: u64) -> usize {
        if self.removed == 0 {
            id as usize
        } else {
            self.ascending
                .binary_search(&id)
                .expect("a stored particle's id is in the ascending list")
        }
    }

    /// Whether particle `id` is stored.
    pub fn holds(&self, id: u64) -> bool {
        self.ascending.binary_search(&id).is_ok()
    }

    /// Removes every particle for which `doomed(position, id)` holds, keeping the others in
    /// their storage order, and returns the number removed. One pass, allocating only for
    /// the removed particles' ids.
    pub fn remove_where(&mut self, mut doomed: impl FnMut(&Vec3, u64) -> bool) -> usize {
        let mut gone = Vec::new();
        let mut kept = 0;
        for i in 0..self.len() {
            let id = self.ids[i];
            if doomed(&self.positions[i], id) {
                gone.push(id);
                continue;
            }
            // kept ≤ i: slot i is still unread.
            self.positions[kept] = self.positions[i];
            self.velocities[kept] = self.velocities[i];
            self.densities[kept] = self.densities[i];
            self.materials[kept] = self.materials[i];
            if let Some(&a) = self.supports.get(i) {
                self.supports[kept] = a;
            }
            if let Some(&p) = self.pressures.get(i) {
                self.pressures[kept] = p;
            }
            self.ids[kept] = id;
            kept += 1;
        }
        if gone.is_empty() {
            return 0;
        }
        self.positions.truncate(kept);
        self.velocities.truncate(kept);
        self.densities.truncate(kept);
        self.materials.truncate(kept);
        self.supports.truncate(kept);
        self.pressures.truncate(kept);
        self.ids.truncate(kept);
        gone.sort_unstable();
        self.ascending.retain(|id| gone.binary_search(id).is_err());
        self.removed += gone.len() as u64;
        gone.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Removal keeps the survivors' storage order and their ids; ranks follow the ascending
    /// ids; new particles get fresh ids.
    #[test]
    fn removal_keeps_order_and_ids_are_never_reused() {
        let mut fluid = Fluid::default();
        let at = |x: f64| Vec3::new(x, 0.0, 0.0);
        let points: Vec<Vec3> = (0..6).map(|i| at(i as f64)).collect();
        fluid.push(0, &points, std::iter::repeat_n(Vec3::zeros(), 6));
        fluid.ids.reverse();
        fluid.positions.reverse();
        assert_eq!(fluid.rank(4), 4);
        let removed = fluid.remove_where(|p, id| p.x == 1.0 || id == 4);
        assert_eq!(removed, 2);
        assert_eq!(fluid.ids, [5, 3, 2, 0]);
        assert_eq!(fluid.positions, [at(5.0), at(3.0), at(2.0), at(0.0)]);
        assert_eq!(fluid.ascending, [0, 2, 3, 5]);
        assert_eq!((fluid.rank(5), fluid.rank(2)), (3, 1));
        assert!(fluid.holds(3) && !fluid.holds(4));
        fluid.push(0, &[at(9.0)], [Vec3::zeros()]);
        assert_eq!(fluid.ids, [5, 3, 2, 0, 6]);
        assert_eq!((fluid.next_id, fluid.removed, fluid.rank(6)), (7, 2, 4));
        assert_eq!(fluid.remove_where(|_, _| false), 0);
    }
}
