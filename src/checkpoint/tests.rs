//! Checkpoints written and resumed: bit-for-bit continuation (with ρ_c estimated online, with
//! the warm start's supports, with the physical viscosity, before the first step, with rigid
//! bodies, and with emitters, sinks and removed particles), and refused damaged, truncated,
//! foreign and earlier-format files.

use super::*;
use crate::body::BodyState;

fn temp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("projfluid-ckpt-{}-{name}", std::process::id()))
}

fn small_scene() -> Scene {
    let mut scene = Scene::builtin("dam_break_small").unwrap();
    scene.fluid_blocks[0].count = [6, 8, 5];
    scene
}

#[test]
fn a_resumed_world_continues_bit_for_bit() {
    let scene = small_scene();
    let mut reference = scene.build_world().unwrap();
    let mut interrupted = scene.build_world().unwrap();
    for _ in 0..15 {
        reference.step().unwrap();
        interrupted.step().unwrap();
    }
    let path = temp("resume.pfck");
    write_checkpoint(&path, &scene, &interrupted, Some(RunEnd::Steps(30))).unwrap();
    drop(interrupted);
    let restored = read_checkpoint(&path, Some(3)).unwrap();
    std::fs::remove_file(&path).unwrap();
    assert_eq!(restored.run_end, Some(RunEnd::Steps(30)));
    assert_eq!(restored.world.thread_count(), 3);
    let mut resumed = restored.world;
    assert_eq!(resumed.positions_hash(), reference.positions_hash());
    assert_eq!(resumed.boundary_positions(), reference.boundary_positions());
    assert_eq!(resumed.boundary.psi, reference.boundary.psi);
    for _ in 0..15 {
        reference.step().unwrap();
        resumed.step().unwrap();
    }
    assert_eq!(resumed.steps(), 30);
    assert_eq!(resumed.time().to_bits(), reference.time().to_bits());
    assert_eq!(resumed.next_dt().to_bits(), reference.next_dt().to_bits());
    assert_eq!(resumed.positions_hash(), reference.positions_hash());
    assert!(resumed.velocities() == reference.velocities());
}

/// Checkpoints `reference` (built from `scene`) to a file named by `tag` and resumes it
/// twice, once as saved and once changed by `forget`; after `steps` more steps of all three,
/// the first matches the reference bit for bit and the forgetful one does not.
fn resumed_matches_and_forgetful_does_not(
    tag: &str,
    scene: &Scene,
    mut reference: World,
    steps: usize,
    forget: impl FnOnce(&mut World),
) {
    let path = temp(&format!("{tag}.pfck"));
    write_checkpoint(&path, scene, &reference, None).unwrap();
    let mut resumed = read_checkpoint(&path, None).unwrap().world;
    let mut forgetful = read_checkpoint(&path, None).unwrap().world;
    std::fs::remove_file(&path).unwrap();
    forget(&mut forgetful);
    for _ in 0..steps {
        reference.step().unwrap();
        resumed.step().unwrap();
        forgetful.step().unwrap();
    }
    assert_eq!(resumed.positions_hash(), reference.positions_hash());
    assert_ne!(forgetful.positions_hash(), reference.positions_hash());
}

/// With the warm start, every particle's support is part of the state: a resumed run
/// matches, one that forgot the supports does not.
#[test]
fn a_resumed_world_keeps_its_supports() {
    let mut scene = small_scene();
    scene.params.warm_start = 0.45;
    let mut reference = scene.build_world().unwrap();
    for _ in 0..20 {
        reference.step().unwrap();
    }
    let supported = reference.fluid.supports.iter().filter(|a| a.norm() > 0.0);
    assert!(supported.count() > 100, "the column must be supported");
    resumed_matches_and_forgetful_does_not("supports", &scene, reference, 20, |w| {
        w.fluid.supports.fill(Vec3::zeros())
    });
}

/// With ρ_c estimated online, the estimate is part of the state: a resumed run matches,
/// one that forgot the estimate does not.
#[test]
fn a_resumed_world_keeps_its_online_rho() {
    let mut scene = small_scene();
    scene.params.chebyshev.auto_rho = true;
    // The displacement rule alone, with a tight τ, makes the steps long enough to measure.
    scene.params.density_tolerance = 0.0;
    scene.params.displacement_tolerance = 1e-4 * scene.params.particle_radius;
    let mut reference = scene.build_world().unwrap();
    for _ in 0..50 {
        reference.step().unwrap();
    }
    let saved = reference.chebyshev.online();
    assert!(saved.contraction.is_some(), "{saved:?}");
    let params = scene.params.chebyshev;
    resumed_matches_and_forgetful_does_not("online-rho", &scene, reference, 30, |w| {
        assert_eq!(w.chebyshev.online(), saved);
        w.chebyshev = crate::solver::Chebyshev::new(params);
    });
}

/// The physical viscosity and its wall condition travel with the checkpoint's scene: a
/// resumed viscous run with free-slip walls keeps both and continues bit for bit.
#[test]
fn a_resumed_world_keeps_its_physical_viscosity() {
    let mut scene = small_scene();
    scene.params.kinematic_viscosity = 0.05;
    scene.params.no_slip = false;
    let mut reference = scene.build_world().unwrap();
    for _ in 0..10 {
        reference.step().unwrap();
    }
    let path = temp("viscous.pfck");
    write_checkpoint(&path, &scene, &reference, None).unwrap();
    let mut resumed = read_checkpoint(&path, None).unwrap().world;
    std::fs::remove_file(&path).unwrap();
    assert_eq!(resumed.params().kinematic_viscosity, 0.05);
    assert!(!resumed.params().no_slip);
    for _ in 0..10 {
        reference.step().unwrap();
        resumed.step().unwrap();
    }
    assert_eq!(resumed.positions_hash(), reference.positions_hash());
    assert!(resumed.velocities() == reference.velocities());
}

/// Every particle's material and the world's materials, their viscosities and surface
/// tensions too, travel with
/// the checkpoint: a resumed world of two liquids continues bit for bit; one whose particles
/// all forgot their material does not.
#[test]
fn a_resumed_world_keeps_its_materials() {
    let scene = small_scene();
    let mut reference = scene.build_world().unwrap();
    let heavy = reference
        .add_material(crate::Material {
            rest_density: 2500.0,
            kinematic_viscosity: 0.05,
            surface_tension: 0.03,
        })
        .unwrap();
    reference.set_material_kinematic_viscosity(0, 1e-3).unwrap();
    reference.set_material_surface_tension(0, 0.05).unwrap();
    reference.set_fluid_material(heavy).unwrap();
    reference
        .add_fluid_block(Vec3::new(0.05, 0.5, 0.05), [3, 3, 3], Vec3::zeros())
        .unwrap();
    for _ in 0..5 {
        reference.step().unwrap();
    }
    let path = temp("materials.pfck");
    write_checkpoint(&path, &scene, &reference, None).unwrap();
    let resumed = read_checkpoint(&path, None).unwrap().world;
    std::fs::remove_file(&path).unwrap();
    assert_eq!(resumed.material_count(), 2);
    assert_eq!(resumed.material(heavy), reference.material(heavy));
    assert_eq!(resumed.material(0), reference.material(0));
    assert_eq!(resumed.fluid_material(), heavy);
    assert_eq!(resumed.particle_materials(), reference.particle_materials());
    resumed_matches_and_forgetful_does_not("materials", &scene, reference, 10, |w| {
        w.fluid.materials.fill(0)
    });
}

#[test]
fn a_checkpoint_before_the_first_step_resumes_too() {
    let scene = small_scene();
    let mut reference = scene.build_world().unwrap();
    let path = temp("fresh.pfck");
    write_checkpoint(&path, &scene, &reference, None).unwrap();
    let mut resumed = read_checkpoint(&path, None).unwrap().world;
    std::fs::remove_file(&path).unwrap();
    for _ in 0..5 {
        reference.step().unwrap();
        resumed.step().unwrap();
    }
    assert_eq!(resumed.positions_hash(), reference.positions_hash());
}

#[test]
fn damaged_truncated_and_foreign_files_are_refused() {
    let scene = small_scene();
    let mut world = scene.build_world().unwrap();
    world.step().unwrap();
    let path = temp("damaged.pfck");
    write_checkpoint(&path, &scene, &world, None).unwrap();
    let good = std::fs::read(&path).unwrap();
    let message = |bytes: &[u8]| {
        std::fs::write(&path, bytes).unwrap();
        match read_checkpoint(&path, None) {
            Ok(_) => panic!("a bad checkpoint was accepted"),
            Err(e) => e.to_string(),
        }
    };
    let mut flipped = good.clone();
    flipped[good.len() / 2] ^= 1;
    let msg = message(&flipped);
    assert!(msg.starts_with(&path.display().to_string()), "{msg}");
    assert!(msg.contains("damaged or truncated"), "{msg}");
    assert!(message(&good[..good.len() - 100]).contains("damaged or truncated"));
    assert!(message(&good[..20]).contains("truncated"));
    assert!(message(b"{\"name\": 1}").contains("not a projfluid checkpoint"));
    assert!(message(&[]).contains("not a projfluid checkpoint"));
    std::fs::remove_file(&path).unwrap();
    let msg = read_checkpoint(&path, None).err().unwrap().to_string();
    assert!(msg.starts_with("cannot read checkpoint"), "{msg}");
}

/// The checkpoint's scene records the world's backend. One that records the GPU resumes on
/// it, so in a build without the `gpu` feature it is refused naming the backend and the
/// missing feature (here a CPU checkpoint edited to say `gpu`, its digest made anew).
#[test]
fn the_backend_travels_with_the_checkpoint() {
    let scene = small_scene();
    let mut world = scene.build_world().unwrap();
    world.step().unwrap();
    let path = temp("backend.pfck");
    write_checkpoint(&path, &scene, &world, None).unwrap();
    let resumed = read_checkpoint(&path, None).unwrap();
    assert_eq!(resumed.scene.params.backend, crate::Backend::Cpu);
    assert_eq!(resumed.world.backend(), crate::Backend::Cpu);
    let bytes = std::fs::read(&path).unwrap();
    // The scene is a JSON string inside the JSON header: its quotes are escaped.
    let (cpu, gpu) = (
        &br#"\"backend\": \"cpu\""#[..],
        &br#"\"backend\": \"gpu\""#[..],
    );
    let at = bytes
        .windows(cpu.len())
        .position(|w| w == cpu)
        .expect("the checkpoint's scene names its backend");
    let mut edited = bytes[..bytes.len() - DIGEST_LEN].to_vec();
    edited[at..at + gpu.len()].copy_from_slice(gpu);
    let digest = Sha256::digest(&edited);
    edited.extend_from_slice(&digest);
    std::fs::write(&path, &edited).unwrap();
    let read = read_checkpoint(&path, None).map(|c| c.world.backend());
    std::fs::remove_file(&path).unwrap();
    #[cfg(not(feature = "gpu"))]
    assert_eq!(
        read.map_err(|e| e.to_string()),
        Err("backend gpu: not available: this build of projfluid has no `gpu` feature".into())
    );
    // With the feature it resumes on the GPU where a Vulkan adapter is (tests/gpu.rs).
    #[cfg(feature = "gpu")]
    assert!(matches!(read, Ok(crate::Backend::Gpu) | Err(_)));
}

/// A run with an emitter, a sink, a domain and removed particles resumes bit for bit: ids,
/// the removed count, the emitter's progress and the boxes are in the checkpoint.
#[test]
fn a_resumed_world_keeps_its_emitters_sinks_and_ids() {
    use crate::scene::{BoxSpec, SceneEmitter};
    use crate::{EmitterShape, EmitterSpec};
    // The emitter, sink and domain come from the scene, the removal by id from the caller.
    let mut scene = small_scene();
    scene.emitters.push(SceneEmitter {
        spec: EmitterSpec {
            shape: EmitterShape::Disc { radius: 0.08 },
            position: Vec3::new(0.15, 0.7, 0.3),
            direction: Vec3::new(0.3, -1.0, 0.0),
            speed: 1.2,
            end_time: Some(0.5),
        },
        material: None,
    });
    scene.sinks.push(BoxSpec {
        min: [0.0; 3],
        max: [0.15, 0.2, 0.65],
    });
    let mut domain = scene.containers[0].clone();
    domain.max[0] = 0.28;
    scene.domain = Some(BoxSpec {
        min: domain.min,
        max: domain.max,
    });
    let build = || {
        let mut world = scene.build_world().unwrap();
        let ids = world.ids();
        world.remove_particles(&ids[..3]).unwrap();
        world
    };
    let mut reference = build();
    let mut interrupted = build();
    for _ in 0..20 {
        reference.step().unwrap();
        interrupted.step().unwrap();
    }
    assert!(reference.removed_count() > 0 && reference.emitted_count() > 0);
    let path = temp("emitters.pfck");
    write_checkpoint(&path, &scene, &interrupted, None).unwrap();
    drop(interrupted);
    let restored = read_checkpoint(&path, Some(1)).unwrap();
    std::fs::remove_file(&path).unwrap();
    assert_eq!(restored.scene.emitters, scene.emitters);
    assert_eq!(
        (
            restored.world.emitters().len(),
            restored.world.sinks().len()
        ),
        (1, 1)
    );
    let mut resumed = restored.world;
    assert_eq!(resumed.export_state(), reference.export_state());
    for _ in 0..20 {
        reference.step().unwrap();
        resumed.step().unwrap();
    }
    assert_eq!(resumed.ids(), reference.ids());
    assert_eq!(resumed.positions_hash(), reference.positions_hash());
    assert_eq!(resumed.export_state(), reference.export_state());
}

/// The pressures the last step carried are part of the state: a resumed world reads the
/// pressures of the uninterrupted one, bit for bit, where a world that forgot them reads a
/// local step's (docs/method.md §10.1).
#[test]
fn a_resumed_world_reads_the_pressures_of_the_uninterrupted_one() {
    let scene = small_scene();
    let mut reference = scene.build_world().unwrap();
    for _ in 0..15 {
        reference.step().unwrap();
    }
    assert_eq!(reference.fluid.pressures.len(), reference.fluid_count());
    let path = temp("pressures.pfck");
    write_checkpoint(&path, &scene, &reference, None).unwrap();
    let resumed = read_checkpoint(&path, None).unwrap().world;
    let mut forgetful = read_checkpoint(&path, None).unwrap().world;
    std::fs::remove_file(&path).unwrap();
    forgetful.fluid.pressures.clear();
    let expected = reference.constraint_pressures();
    assert!(expected.samples.iter().any(|(_, p)| *p > 100.0));
    assert_eq!(resumed.constraint_pressures(), expected);
    assert_ne!(forgetful.constraint_pressures(), expected);
}

/// Gives the checkpoint at `path` the magic of the format before the carried pressures, with
/// its digest recomputed.
fn relabel_as_v5(path: &std::path::Path) {
    let mut bytes = std::fs::read(path).unwrap();
    bytes[..8].copy_from_slice(MAGIC_V5);
    let body = bytes.len() - DIGEST_LEN;
    let digest = Sha256::digest(&bytes[..body]);
    bytes[body..].copy_from_slice(&digest);
    std::fs::write(path, &bytes).unwrap();
}

/// A checkpoint of the format before the carried pressures (`PFCHECK5`: the same without
/// them) resumes, continuing bit for bit, and reads its pressures from a local step until
/// its next step carries them; one of that format that announces pressures is refused.
#[test]
fn a_checkpoint_without_pressures_resumes() {
    let scene = small_scene();
    let mut reference = scene.build_world().unwrap();
    let mut bare = scene.build_world().unwrap();
    for _ in 0..10 {
        reference.step().unwrap();
        bare.step().unwrap();
    }
    bare.fluid.pressures.clear();
    let path = temp("v5.pfck");
    write_checkpoint(&path, &scene, &bare, None).unwrap();
    relabel_as_v5(&path);
    let mut resumed = read_checkpoint(&path, None).unwrap().world;
    assert!(resumed.fluid.pressures.is_empty());
    for _ in 0..5 {
        reference.step().unwrap();
        resumed.step().unwrap();
    }
    assert_eq!(resumed.positions_hash(), reference.positions_hash());
    assert_eq!(resumed.fluid.pressures, reference.fluid.pressures);

    write_checkpoint(&path, &scene, &reference, None).unwrap();
    relabel_as_v5(&path);
    let message = read_checkpoint(&path, None).err().unwrap().to_string();
    std::fs::remove_file(&path).unwrap();
    assert!(message.contains("announces pressures"), "{message}");
}

/// A checkpoint of an earlier format is refused with a message saying what it lacks.
#[test]
fn checkpoints_of_earlier_formats_are_refused() {
    let path = temp("v2.pfck");
    for (magic, words) in [
        (MAGIC_V4, "without fluid materials"),
        (MAGIC_V3, "warm start's supports"),
        (MAGIC_V2, "stable particle ids"),
        (MAGIC_V1, "without bodies"),
    ] {
        let mut bytes = magic.to_vec();
        bytes.extend_from_slice(&[0; 64]);
        std::fs::write(&path, bytes).unwrap();
        let message = read_checkpoint(&path, None).err().unwrap().to_string();
        assert!(message.contains(words), "{message}");
    }
    std::fs::remove_file(&path).unwrap();
}

/// `small_scene` with a scripted kinematic paddle beyond the water, a dynamic box above it
/// (spinning) and a static ball on the floor.
fn scene_with_bodies() -> Scene {
    let text = r#"[
        {"kind": "kinematic", "box": {"half_extents": [0.02, 0.3, 0.3]}, "position": [0.4, 0.32, 0.325],
         "motion": {"amplitude": [0.05, 0, 0], "angular_amplitude": [0, 0, 0.2], "period": 0.5}},
        {"kind": "dynamic", "box": {"half_extents": [0.06, 0.05, 0.06]}, "density": 600,
         "position": [0.15, 0.6, 0.15], "angular_velocity": [0, 0, 2]},
        {"kind": "static", "sphere": {"radius": 0.08}, "position": [1.2, 0.1, 0.3]}
    ]"#;
    let mut json = small_scene().to_json();
    let end = json.rfind('}').unwrap();
    json.replace_range(end.., &format!(", \"bodies\": {text}}}"));
    Scene::from_json(&json).unwrap()
}

/// The particles' digest, every body's state and the walls' load, as bits.
fn fingerprint(world: &World) -> (String, Vec<BodyState>, Vec3, u64) {
    let bodies = world.bodies().iter().map(|b| b.state()).collect();
    (
        world.positions_hash(),
        bodies,
        world.wall_force(),
        world.time().to_bits(),
    )
}

#[test]
fn a_resumed_world_with_bodies_continues_bit_for_bit() {
    let scene = scene_with_bodies();
    let mut reference = scene.build_world().unwrap();
    let mut interrupted = scene.build_world().unwrap();
    assert_eq!(reference.bodies().len(), 3);
    for _ in 0..20 {
        reference.step().unwrap();
        interrupted.step().unwrap();
    }
    let path = temp("bodies.pfck");
    write_checkpoint(&path, &scene, &interrupted, None).unwrap();
    drop(interrupted);
    let restored = read_checkpoint(&path, Some(1)).unwrap();
    std::fs::remove_file(&path).unwrap();
    assert_eq!(restored.scene.bodies, scene.bodies);
    let mut resumed = restored.world;
    // The walls' load of the last step is not part of the state; everything else is.
    let without_walls = |w: &World| {
        let (hash, bodies, _, time) = fingerprint(w);
        (hash, bodies, time)
    };
    assert_eq!(without_walls(&resumed), without_walls(&reference));
    let start: Vec<BodyState> = reference.bodies().iter().map(|b| b.state()).collect();
    for _ in 0..20 {
        reference.step().unwrap();
        resumed.step().unwrap();
    }
    assert_eq!(fingerprint(&resumed), fingerprint(&reference));
    // The paddle and the box moved on after the checkpoint.
    for id in [0, 1] {
        assert_ne!(reference.bodies()[id].pose(), start[id].pose, "body {id}");
    }
}
