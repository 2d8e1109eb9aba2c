//! Removing fluid particles (docs/method.md §12.3): sinks and the domain, applied at the end
//! of every step, and removal by id for engines.

use super::World;
use crate::Error;
use crate::boundary::Aabb;

/// A sink's handle within its world: the order in which it was added, from 0.
pub type SinkId = usize;

/// Checks that `aabb` has finite corners and `min ≤ max` along every axis.
pub(super) fn check_box(field: &str, aabb: &Aabb) -> Result<(), Error> {
    super::check_finite(field, &[aabb.min, aabb.max])?;
    if let Some(a) = (0..3).find(|&a| aabb.min[a] > aabb.max[a]) {
        return Err(Error::invalid(
            field,
            format!("{:?}..{:?}", aabb.min.as_slice(), aabb.max.as_slice()),
            &format!("must have min ≤ max along every axis (axis {a})"),
        ));
    }
    Ok(())
}

impl World {
    /// Adds a sink: every fluid particle whose position (m) lies in the box (faces included)
    /// at the end of a step is removed. Returns the sink's index. Rejects non-finite corners
    /// or min > max along an axis, changing nothing.
    pub fn add_sink(&mut self, sink: Aabb) -> Result<SinkId, Error> {
        check_box("sink", &sink)?;
        self.sinks.push(sink);
        Ok(self.sinks.len() - 1)
    }

    /// The sinks added so far (index = [`SinkId`]).
    pub fn sinks(&self) -> &[Aabb] {
        &self.sinks
    }

    /// Sets the domain: every fluid particle outside it (faces included in it), or with a
    /// non-finite position, at the end of a step is removed; `None` (the default) keeps them
    /// all. Rejects a box like [`World::add_sink`] does, changing nothing.
    pub fn set_domain(&mut self, domain: Option<Aabb>) -> Result<(), Error> {
        if let Some(d) = &domain {
            check_box("domain", d)?;
        }
        self.domain = domain;
        Ok(())
    }

    /// The domain, if one is set.
    pub fn domain(&self) -> Option<&Aabb> {
        self.domain.as_ref()
    }

    /// Fluid particles removed so far: by sinks, by the domain, by
    /// [`World::remove_particles`] and by closed solids added where fluid stood.
    pub fn removed_count(&self) -> u64 {
        self.fluid.removed
    }

    /// Removes the fluid particles with the given ids now (between steps) and returns how
    /// many were removed. The others keep their ids and order. Errors, removing nothing,
    /// when an id is not that of a particle in the world (never given, or removed) or is
    /// listed twice.
    pub fn remove_particles(&mut self, ids: &[u64]) -> Result<usize, Error> {
        let mut doomed = ids.to_vec();
        doomed.sort_unstable();
        if let Some(&id) = ids.iter().find(|&&id| !self.fluid.holds(id)) {
            return Err(Error::invalid(
                "ids",
                id,
                "must name fluid particles of this world (never given, or removed already)",
            ));
        }
        if let Some(pair) = doomed.windows(2).find(|p| p[0] == p[1]) {
            return Err(Error::invalid("ids", pair[0], "must not list an id twice"));
        }
        Ok(self
            .fluid
            .remove_where(|_, id| doomed.binary_search(&id).is_ok()))
    }

    /// Removes the particles in a sink or outside the domain, at the end of a step, in one
    /// pass over the storage order (the survivors keep it).
    pub(super) fn drain(&mut self) {
        if self.sinks.is_empty() && self.domain.is_none() {
            return;
        }
        let (sinks, domain) = (&self.sinks, &self.domain);
        self.fluid.remove_where(|p, _| {
            sinks.iter().any(|s| s.contains(p, 0.0)) || domain.is_some_and(|d| !d.contains(p, 0.0))
        });
    }
}
