//! Checkpoints: the complete state of a run in one file, so that a resumed run continues
//! bit for bit as if it had never stopped.
//!
//! A checkpoint holds the world's exact state ([`WorldState`]) and the scene it was built
//! from, with the world's parameters. A resumed world gets its bodies (meshes, samples and
//! masses) from the scene, so a body's mesh file must still be readable, and their poses,
//! velocities and loads from the state.
//!
//! Layout: the magic `PFCHECK6`; the length (u64, little-endian) of a JSON header, the
//! header ([`header`]: the scene with the world's parameters, time, step count, next Δt,
//! containers (and which of them have walls that are fields), grid, counts, the run's end,
//! the online ρ_c estimate, the bodies' poses, velocities and loads, the next particle id,
//! the removed count, sinks, domain and emitters); the fluid positions, velocities,
//! supports (docs/method.md §4.1; zeros while the warm start is off) and densities as f64
//! triples/values, the particle ids as u64, their materials as u16 (the header lists the
//! materials, docs/method.md §14), the pressures the last step carried as f64 where the
//! header says it carried them (docs/method.md §10.1), the static boundary positions as f64
//! triples and their owners as u32 (all little-endian); and a SHA-256 digest of everything
//! before it, so that a damaged or truncated file is refused. A `PFCHECK5` checkpoint, the
//! same without pressures, resumes as well.

mod header;

use crate::scene::Scene;
use crate::{Error, Vec3, World, WorldState};
use header::{Header, SavedBody, SavedEmitter, aabb, saved_box};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::Path;

const MAGIC: &[u8; 8] = b"PFCHECK6";
/// The format before the carried pressures, which resumes without them.
const MAGIC_V5: &[u8; 8] = b"PFCHECK5";
/// The magics of earlier formats, named in the errors that refuse them: before bodies,
/// before particle ids, sinks and emitters, before the warm start's supports, and before
/// materials.
const MAGIC_V1: &[u8; 8] = b"PFCHECK1";
const MAGIC_V2: &[u8; 8] = b"PFCHECK2";
const MAGIC_V3: &[u8; 8] = b"PFCHECK3";
const MAGIC_V4: &[u8; 8] = b"PFCHECK4";
const DIGEST_LEN: usize = 32;

/// Where the interrupted run was going to stop.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RunEnd {
    /// At this simulated time (s).
    Time(f64),
    /// After this many steps in all.
    Steps(u64),
}

/// A restored run: the scene it came from (with the world's parameters), the world in the
/// exact state it was saved in, and where the run was going to stop.
pub struct Checkpoint {
    /// The scene, its parameters those of the saved world.
    pub scene: Scene,
    /// The world, ready to continue.
    pub world: World,
    /// The end of the interrupted run, if it was saved.
    pub run_end: Option<RunEnd>,
}

/// Writes a checkpoint of `world`, which was built from `scene`, to `path` (through a
/// temporary file renamed into place, so that an interrupted write never leaves a partial
/// checkpoint under that name). `run_end` records where the run was going to stop.
pub fn write_checkpoint(
    path: &Path,
    scene: &Scene,
    world: &World,
    run_end: Option<RunEnd>,
) -> Result<(), Error> {
    let mut scene = scene.clone();
    scene.params = world.params().clone();
    let state = world.export_state();
    let header = Header {
        scene: scene.to_json(),
        time: state.time,
        steps: state.steps,
        next_dt: state.next_dt,
        containers: state.containers.iter().map(saved_box).collect(),
        field_walls: state.field_walls.iter().map(saved_box).collect(),
        grid: state.grid,
        grid_capped: state.grid_capped,
        boundary_dirty: !state.boundary_sorted,
        fluid_count: state.positions.len(),
        boundary_count: state.boundary_positions.len(),
        run_end,
        chebyshev: state.online_rho,
        bodies: state.bodies.iter().map(SavedBody::of).collect(),
        next_id: state.next_id,
        removed_count: state.removed_count,
        sinks: state.sinks.iter().map(saved_box).collect(),
        domain: state.domain.as_ref().map(saved_box),
        emitters: state.emitters.iter().map(SavedEmitter::of).collect(),
        materials: (1..world.material_count())
            .filter_map(|m| world.material(m as u16))
            .map(|m| m.rest_density)
            .collect(),
        fluid_material: world.fluid_material(),
        viscosities: (0..world.material_count())
            .filter_map(|m| world.material(m as u16))
            .map(|m| m.kinematic_viscosity)
            .collect(),
        tensions: (0..world.material_count())
            .filter_map(|m| world.material(m as u16))
            .map(|m| m.surface_tension)
            .collect(),
        pressures: !state.pressures.is_empty(),
    };
    let json = serde_json::to_vec(&header)
        .map_err(|e| Error::Io(format!("cannot encode checkpoint header: {e}")))?;
    let f = &state;
    let mut bytes = Vec::with_capacity(
        64 + json.len() + f.positions.len() * 90 + f.boundary_positions.len() * 28,
    );
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&(json.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&json);
    for v in f.positions.iter().chain(&f.velocities) {
        push_vec3(&mut bytes, v);
    }
    // No supports (the warm start off) are written as zeros, which resume alike.
    let zero = Vec3::zeros();
    for i in 0..f.positions.len() {
        push_vec3(&mut bytes, f.supports.get(i).unwrap_or(&zero));
    }
    for d in &f.densities {
        bytes.extend_from_slice(&d.to_le_bytes());
    }
    for id in &f.ids {
        bytes.extend_from_slice(&id.to_le_bytes());
    }
    for m in &f.materials {
        bytes.extend_from_slice(&m.to_le_bytes());
    }
    for p in &f.pressures {
        bytes.extend_from_slice(&p.to_le_bytes());
    }
    for p in &f.boundary_positions {
        push_vec3(&mut bytes, p);
    }
    for o in &f.boundary_owners {
        bytes.extend_from_slice(&o.to_le_bytes());
    }
    let digest = Sha256::digest(&bytes);
    bytes.extend_from_slice(&digest);

    let fail =
        |e: std::io::Error| Error::Io(format!("cannot write checkpoint {}: {e}", path.display()));
    let mut temporary = path.as_os_str().to_owned();
    temporary.push(".partial");
    std::fs::write(&temporary, &bytes).map_err(fail)?;
    std::fs::rename(&temporary, path).map_err(fail)
}

fn push_vec3(bytes: &mut Vec<u8>, v: &Vec3) {
    for c in v.iter() {
        bytes.extend_from_slice(&c.to_le_bytes());
    }
}

/// Reads the checkpoint at `path` and rebuilds its world, on `threads` worker threads when
/// given (the result does not depend on it), else on the saved parameters' count. Errors
/// ([`Error::InvalidArgument`] with field `checkpoint`, or [`Error::Io`] when unreadable)
/// start with the path and say what is wrong: not a checkpoint, truncated, damaged
/// (digest mismatch) or inconsistent.
pub fn read_checkpoint(path: &Path, threads: Option<usize>) -> Result<Checkpoint, Error> {
    let bytes = std::fs::read(path)
        .map_err(|e| Error::Io(format!("cannot read checkpoint {}: {e}", path.display())))?;
    let bad = |what: &str| Error::InvalidArgument {
        field: "checkpoint".to_string(),
        message: format!("{}: {what}", path.display()),
    };
    if bytes.starts_with(MAGIC_V1) {
        return Err(bad(
            "is a checkpoint of an earlier version without bodies, which this version cannot resume",
        ));
    }
    if bytes.starts_with(MAGIC_V2) {
        return Err(bad(
            "is a checkpoint of an earlier version without stable particle ids, sinks and \
             emitters, which this version cannot resume",
        ));
    }
    if bytes.starts_with(MAGIC_V3) {
        return Err(bad(
            "is a checkpoint of an earlier version without the warm start's supports, which \
             this version cannot resume",
        ));
    }
    if bytes.starts_with(MAGIC_V4) {
        return Err(bad(
            "is a checkpoint of an earlier version without fluid materials, which this \
             version cannot resume",
        ));
    }
    let earlier = bytes.starts_with(MAGIC_V5);
    if !(bytes.starts_with(MAGIC) || earlier) {
        return Err(bad("is not a projfluid checkpoint (wrong magic bytes)"));
    }
    if bytes.len() < MAGIC.len() + 8 + DIGEST_LEN {
        return Err(bad("is truncated"));
    }
    let (body, digest) = bytes.split_at(bytes.len() - DIGEST_LEN);
    let header_len = u64::from_le_bytes(body[8..16].try_into().unwrap_or_default());
    let header_end = usize::try_from(header_len)
        .ok()
        .and_then(|n| n.checked_add(16))
        .filter(|&end| end <= body.len());
    let Some(header_end) = header_end else {
        return Err(bad(
            "is truncated (the header runs past the end of the file)",
        ));
    };
    if Sha256::digest(body).as_slice() != digest {
        return Err(bad(
            "is damaged or truncated (its SHA-256 digest does not match its contents)",
        ));
    }
    let header: Header = serde_json::from_slice(&body[16..header_end])
        .map_err(|e| bad(&format!("has an unreadable header: {e}")))?;
    if earlier && header.pressures {
        return Err(bad(
            "is inconsistent: a checkpoint of the format before pressures announces pressures",
        ));
    }
    let (n, m) = (header.fluid_count, header.boundary_count);
    let pressure_bytes = if header.pressures { 8 } else { 0 };
    let expected = n
        .checked_mul(3 * 8 * 3 + 8 + 8 + 2 + pressure_bytes)
        .and_then(|f| m.checked_mul(24 + 4).and_then(|b| f.checked_add(b)));
    if expected != Some(body.len() - header_end) {
        return Err(bad(&format!(
            "holds {} bytes of particle data, not the {n} fluid and {m} boundary particles its header announces",
            body.len() - header_end
        )));
    }
    let mut scene = Scene::from_json(&header.scene)
        .map_err(|e| bad(&format!("holds an invalid scene: {e}")))?;
    if let Some(t) = threads {
        scene.params.threads = t;
    }

    let mut data = Reader(&body[header_end..]);
    let positions = data.vec3s(n);
    let velocities = data.vec3s(n);
    let mut supports = data.vec3s(n);
    if supports.iter().all(|a| *a == Vec3::zeros()) {
        supports = Vec::new();
    }
    let densities: Vec<f64> = (0..n).map(|_| f64::from_le_bytes(data.take())).collect();
    let ids: Vec<u64> = (0..n).map(|_| u64::from_le_bytes(data.take())).collect();
    let materials: Vec<u16> = (0..n).map(|_| u16::from_le_bytes(data.take())).collect();
    let pressures: Vec<f64> = match header.pressures {
        true => (0..n).map(|_| f64::from_le_bytes(data.take())).collect(),
        false => Vec::new(),
    };
    let boundary = data.vec3s(m);
    let owners: Vec<u32> = (0..m).map(|_| u32::from_le_bytes(data.take())).collect();
    let bodies = header
        .bodies
        .iter()
        .map(SavedBody::state)
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| bad(&format!("holds an invalid body pose: {e}")))?;
    let state = WorldState {
        time: header.time,
        steps: header.steps,
        next_dt: header.next_dt,
        positions,
        velocities,
        supports,
        densities,
        materials,
        pressures,
        ids,
        next_id: header.next_id,
        removed_count: header.removed_count,
        boundary_positions: boundary,
        boundary_owners: owners,
        bodies,
        boundary_sorted: !header.boundary_dirty,
        containers: header.containers.iter().map(aabb).collect(),
        field_walls: header.field_walls.iter().map(aabb).collect(),
        sinks: header.sinks.iter().map(aabb).collect(),
        domain: header.domain.as_ref().map(aabb),
        emitters: header.emitters.iter().map(SavedEmitter::state).collect(),
        grid: header.grid,
        grid_capped: header.grid_capped,
        online_rho: header.chebyshev,
    };
    // The bodies come from the scene (their meshes, samples and masses are not saved); the
    // particles of the walls, obstacles and fluid come from the state.
    let mut world = World::new(scene.params.clone())?;
    for &rest_density in &header.materials {
        world
            .add_material(crate::Material::with_density(rest_density))
            .map_err(|e| bad(&format!("holds an invalid material: {e}")))?;
    }
    for (m, &nu) in header.viscosities.iter().enumerate() {
        let id = u16::try_from(m).unwrap_or(u16::MAX);
        world
            .set_material_kinematic_viscosity(id, nu)
            .map_err(|e| bad(&format!("holds an invalid material: {e}")))?;
    }
    for (m, &sigma) in header.tensions.iter().enumerate() {
        let id = u16::try_from(m).unwrap_or(u16::MAX);
        world
            .set_material_surface_tension(id, sigma)
            .map_err(|e| bad(&format!("holds an invalid material: {e}")))?;
    }
    world
        .set_fluid_material(header.fluid_material)
        .map_err(|e| bad(&format!("is inconsistent: {e}")))?;
    scene.add_bodies(&mut world).map_err(|e| {
        bad(&format!(
            "holds a scene whose bodies cannot be rebuilt: {e}"
        ))
    })?;
    world
        .import_state(state)
        .map_err(|e| bad(&format!("is inconsistent: {e}")))?;
    Ok(Checkpoint {
        scene,
        world,
        run_end: header.run_end,
    })
}

/// Little-endian values read from the front of a slice whose length was checked.
struct Reader<'a>(&'a [u8]);

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let (head, rest) = self.0.split_at(N);
        self.0 = rest;
        head.try_into().unwrap_or([0; N])
    }

    fn vec3s(&mut self, count: usize) -> Vec<Vec3> {
        (0..count)
            .map(|_| {
                Vec3::from(std::array::from_fn::<f64, 3, _>(|_| {
                    f64::from_le_bytes(self.take())
                }))
            })
            .collect()
    }
}

#[cfg(test)]
mod tests;
