//! The GPU backend (feature `gpu`) against the CPU: a dam break and a tank at rest on the
//! first Vulkan adapter (in CI, Mesa's software device lavapipe); the backend chosen through
//! `Params::backend`, the C API's `PfParams.backend` and the scene key `backend`. A missing
//! adapter fails these tests with the reason; it does not skip them.
#![cfg(feature = "gpu")]

use projfluid::boundary::Aabb;
use projfluid::checkpoint::{read_checkpoint, write_checkpoint};
use projfluid::ffi::{
    PfBackend, PfParams, PfPose, PfSolver, PfStatus, pf_last_error_message, pf_params_default,
    pf_pose_identity, pf_world_add_body_box, pf_world_add_container_box,
    pf_world_add_container_field, pf_world_add_fluid_box, pf_world_body_count, pf_world_create,
    pf_world_destroy, pf_world_fluid_count, pf_world_get_params, pf_world_get_positions,
    pf_world_positions_hash, pf_world_step,
};
use projfluid::material::Material;
use projfluid::scene::Scene;
use projfluid::{Backend, ChebyshevParams, Params, SolverKind, Vec3, World};
use std::ffi::CStr;
use std::mem::MaybeUninit;
use std::ptr;

/// `world` switched to the GPU backend, or a failure that says why it cannot be.
fn on_gpu(mut world: World) -> World {
    if let Err(e) = world.set_backend(Backend::Gpu) {
        panic!(
            "the GPU backend is unavailable: {e}. These tests need a Vulkan adapter; \
             on Debian install mesa-vulkan-drivers and libvulkan1 (lavapipe)"
        );
    }
    assert_eq!(world.backend(), Backend::Gpu);
    world
}

fn dam_break() -> World {
    Scene::builtin("dam_break_small")
        .expect("a built-in scene")
        .build_world()
        .expect("the scene builds")
}

/// What the comparisons read from a world after a run.
struct Run {
    count: usize,
    kinetic: f64,
    /// The largest x of the fluid (m): the surge front of the dam break.
    front: f64,
    /// Fluid particles outside the container (m).
    escaped: usize,
    /// Average density error max(ρ/ρ0 − 1, 0) of each step.
    density_errors: Vec<f64>,
    /// Outer iterations of each step.
    iterations: Vec<usize>,
    positions: Vec<Vec3>,
    velocities: Vec<Vec3>,
}

fn run(mut world: World, seconds: f64, container: &Aabb) -> Run {
    let (mut density_errors, mut iterations) = (Vec::new(), Vec::new());
    let started = std::time::Instant::now();
    let steps = world
        .advance_with(seconds, |w| {
            let stats = w.last_step().expect("a step was taken");
            density_errors.push(stats.density_error_avg);
            iterations.push(stats.outer_iterations);
            Ok(())
        })
        .expect("the run steps");
    eprintln!(
        "{:?}: {steps} steps, {:.1} ms per step, {:.1} outer iterations per step",
        world.backend(),
        started.elapsed().as_secs_f64() * 1e3 / steps as f64,
        iterations.iter().sum::<usize>() as f64 / steps as f64
    );
    let positions = world.positions();
    let escaped = positions
        .iter()
        .filter(|p| !container.contains(p, 0.0))
        .count();
    Run {
        count: world.fluid_count(),
        kinetic: world.kinetic_energy(),
        front: positions.iter().map(|p| p.x).fold(f64::MIN, f64::max),
        escaped,
        density_errors,
        iterations,
        positions,
        velocities: world.velocities(),
    }
}

/// The dam break's container (m): the scene's box, its walls r/4 outside it.
fn dam_container() -> Aabb {
    Aabb {
        min: Vec3::repeat(-0.01),
        max: Vec3::new(2.02, 1.52, 0.67),
    }
}

/// The first 0.3 s of `dam_break_small` on the device follows the CPU's: the same
/// particles, none escaped, every step's average density error within the tolerance η
/// the density rule holds (as on the CPU), and the kinetic energy and surge front within a
/// few per cent of the CPU's.
#[test]
fn dam_break_on_the_gpu_follows_the_cpu() {
    let seconds = 0.3;
    let container = dam_container();
    let cpu = run(dam_break(), seconds, &container);
    let gpu = run(on_gpu(dam_break()), seconds, &container);
    assert_eq!(gpu.count, cpu.count);
    assert_eq!((cpu.escaped, gpu.escaped), (0, 0));
    let tolerance = Params::default().density_tolerance;
    let worst = |r: &Run| r.density_errors.iter().fold(0.0f64, |a, &b| a.max(b));
    assert!(
        worst(&gpu) <= tolerance * 1.0001,
        "GPU density error {} > η = {tolerance} (CPU: {})",
        worst(&gpu),
        worst(&cpu)
    );
    // The collapse has started: the comparison is of a moving flow.
    assert!(cpu.kinetic > 1.0, "{}", cpu.kinetic);
    let energy = (gpu.kinetic - cpu.kinetic).abs() / cpu.kinetic;
    assert!(
        energy < 0.03,
        "kinetic energy: GPU {} J, CPU {} J",
        gpu.kinetic,
        cpu.kinetic
    );
    let start = 0.8; // the block's front before the collapse (16 particles of 2r)
    let surge = |r: &Run| r.front - start;
    let front = (surge(&gpu) - surge(&cpu)).abs() / surge(&cpu);
    assert!(
        surge(&cpu) > 0.05 && front < 0.05,
        "surge: GPU {} m, CPU {} m",
        surge(&gpu),
        surge(&cpu)
    );
    let mean = |v: &[usize]| v.iter().sum::<usize>() as f64 / v.len() as f64;
    assert!(
        mean(&gpu.iterations) < 2.0 * mean(&cpu.iterations) + 2.0,
        "outer iterations per step: GPU {}, CPU {}",
        mean(&gpu.iterations),
        mean(&cpu.iterations)
    );
}

/// Two runs on the device give the same bits.
#[test]
fn two_gpu_runs_agree_to_the_bit() {
    let container = dam_container();
    let a = run(on_gpu(dam_break()), 0.1, &container);
    let b = run(on_gpu(dam_break()), 0.1, &container);
    assert_eq!(a.iterations, b.iterations);
    assert!(a.positions == b.positions, "positions differ");
    assert!(a.velocities == b.velocities, "velocities differ");
    // And the run moved the fluid.
    assert!(a.kinetic > 0.1, "{}", a.kinetic);
}

/// A tank of water 12 particles deep, a block filling the floor of its container, relaxed
/// to its equilibrium packing on the CPU (a lattice is not at rest under gravity: its layers
/// slide into each other's hollows; docs/validation.md, "Tank at rest"); with its container.
fn relaxed_tank() -> (World, Aabb) {
    let r = 0.025;
    let d = 2.0 * r;
    let mut world = World::new(Params::default()).expect("parameters");
    // The built-in scenes' placement: walls r/4 outside the block's nominal box.
    let (nx, ny, nz) = (10, 12, 8);
    let container = Aabb {
        min: Vec3::repeat(-0.25 * r),
        max: Vec3::new(nx as f64 * d, 1.0, nz as f64 * d) + Vec3::repeat(0.25 * r),
    };
    world.add_container(container, 1).expect("container");
    world
        .add_fluid_block(Vec3::repeat(r), [nx, ny, nz], Vec3::zeros())
        .expect("fluid");
    world.relax(4.0, 4.0).expect("the relaxation steps");
    (world, container)
}

/// A tank at rest stays at rest on the device as on the CPU: over 0.5 s from its
/// equilibrium its fluid keeps the CPU's residual motion at the default weighting (a few
/// cm/s, docs/method.md §2.5) and no more, no particle moves much
/// farther than on the CPU, and its centre of mass stays where the CPU's does.
#[test]
fn a_tank_at_rest_stays_at_rest_on_the_gpu() {
    let r = 0.025;
    let (relaxed, container) = relaxed_tank();
    let state = relaxed.export_state();
    let start = relaxed.positions();
    let centre = |p: &[Vec3]| p.iter().map(|p| p.y).sum::<f64>() / p.len() as f64;
    let cpu = run(relaxed, 0.5, &container);
    let mut world = World::new(Params::default()).expect("parameters");
    world.import_state(state).expect("the relaxed state");
    let gpu = run(on_gpu(world), 0.5, &container);
    assert_eq!(gpu.escaped, 0);
    // The CPU's own residual motion is the measure: some cm/s at the default weighting.
    let fastest = |r: &Run| r.velocities.iter().map(|v| v.norm()).fold(0.0, f64::max);
    let rms = |r: &Run| {
        let sum: f64 = r.velocities.iter().map(|v| v.norm_squared()).sum();
        (sum / r.velocities.len() as f64).sqrt()
    };
    eprintln!(
        "tank at rest: fastest {} (CPU {}) m/s, rms {} (CPU {}) m/s",
        fastest(&gpu),
        fastest(&cpu),
        rms(&gpu),
        rms(&cpu)
    );
    assert!(
        rms(&gpu) < 0.05 && rms(&gpu) < 1.5 * rms(&cpu) + 0.002,
        "rms speed: GPU {} m/s, CPU {} m/s",
        rms(&gpu),
        rms(&cpu)
    );
    assert!(
        fastest(&gpu) < 1.5 * fastest(&cpu) + 0.01,
        "fastest particle: GPU {} m/s, CPU {} m/s",
        fastest(&gpu),
        fastest(&cpu)
    );
    // Reads come in id order: each particle against where it started.
    let moved = |r: &Run| {
        (start.iter().zip(&r.positions))
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max)
    };
    assert!(
        moved(&gpu) < 2.0 * r && moved(&gpu) < 1.5 * moved(&cpu) + 0.1 * r,
        "the farthest particle moved {} m on the GPU, {} m on the CPU",
        moved(&gpu),
        moved(&cpu)
    );
    let sunk = centre(&start) - centre(&gpu.positions);
    let sunk_cpu = centre(&start) - centre(&cpu.positions);
    assert!(
        (sunk - sunk_cpu).abs() < 0.02 * r,
        "centre of mass sank {sunk} m on the GPU, {sunk_cpu} m on the CPU"
    );
}

/// Worlds with what the GPU backend does not step yet are refused, naming it, and the world
/// stays on the CPU.
#[test]
fn unsupported_worlds_are_refused_naming_the_feature() {
    let mut world = World::new(Params {
        kinematic_viscosity: 1e-4,
        ..Params::default()
    })
    .expect("parameters");
    world
        .add_fluid_block(Vec3::zeros(), [4, 4, 4], Vec3::zeros())
        .expect("fluid");
    let message = world.set_backend(Backend::Gpu).unwrap_err().to_string();
    assert!(
        message.contains("backend") && message.contains("kinematic_viscosity"),
        "{message}"
    );
    assert_eq!(world.backend(), Backend::Cpu);
    // Vorticity confinement, refused when the GPU world is made.
    let message = World::new(Params {
        vorticity_confinement: 0.3,
        backend: Backend::Gpu,
        ..Params::default()
    })
    .err()
    .expect("refused")
    .to_string();
    assert!(
        message.contains("backend gpu") && message.contains("vorticity_confinement"),
        "{message}"
    );
}

/// Set for the run of [`missing_adapter_probe`] that
/// [`a_missing_adapter_is_refused_naming_what_is_missing`] starts.
const PROBE: &str = "PROJFLUID_GPU_TEST_NO_ADAPTER";

/// Without a Vulkan driver the GPU backend is refused with an error that names the backend
/// and what is missing, and the world stays on the CPU. Runs this test binary again with the
/// Vulkan loader pointed at no driver.
#[test]
fn a_missing_adapter_is_refused_naming_what_is_missing() {
    let exe = std::env::current_exe().expect("the test binary");
    let output = std::process::Command::new(exe)
        .args(["--exact", "missing_adapter_probe", "--include-ignored"])
        .args(["--nocapture", "--test-threads", "1"])
        .env(PROBE, "1")
        .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
        .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
        .output()
        .expect("the probe runs");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success() && stdout.contains("1 passed"),
        "{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
}

/// The probe of [`a_missing_adapter_is_refused_naming_what_is_missing`]; passes trivially
/// when run by itself.
#[test]
#[ignore = "run by a_missing_adapter_is_refused_naming_what_is_missing"]
fn missing_adapter_probe() {
    if std::env::var_os(PROBE).is_none() {
        return;
    }
    let mut world = World::new(Params::default()).expect("parameters");
    world
        .add_fluid_block(Vec3::zeros(), [2, 2, 2], Vec3::zeros())
        .expect("fluid");
    let message = world.set_backend(Backend::Gpu).unwrap_err().to_string();
    assert!(
        message.contains("backend gpu") && message.contains("no Vulkan adapter"),
        "{message}"
    );
    assert_eq!(world.backend(), Backend::Cpu);
    world.step().expect("the CPU still steps");
}

/// Steps of the small tank below, on the device: enough to move its fluid, few enough to keep
/// the tests short on a software device.
const TANK_STEPS: usize = 4;

/// A 0.5 m box with walls of particles, and an 8 × 8 × 8 block of water in its corner
/// (values that `float` holds exactly, so that the C API's worlds are the same).
fn fill_small_tank(world: &mut World) {
    let container = Aabb {
        min: Vec3::zeros(),
        max: Vec3::repeat(0.5),
    };
    world.add_container(container, 1).expect("container");
    world
        .add_fluid_block(Vec3::repeat(0.0625), [8, 8, 8], Vec3::zeros())
        .expect("fluid");
}

/// A world made with `Params { backend: Backend::Gpu, .. }`, or a failure that says why not.
fn made_on_gpu() -> World {
    let params = Params {
        backend: Backend::Gpu,
        ..Params::default()
    };
    World::new(params).unwrap_or_else(|e| {
        panic!(
            "the GPU backend is unavailable: {e}. These tests need a Vulkan adapter; \
             on Debian install mesa-vulkan-drivers and libvulkan1 (lavapipe)"
        )
    })
}

/// A world made on the GPU through its parameters steps as one made on the CPU and switched
/// there, to the bit; both report the backend in their parameters, and switching back to the
/// CPU sets them back. A world on the GPU refuses, changing nothing, what the GPU backend
/// does not step: walls built as fields, a further material, a solver it does not run.
#[test]
fn a_world_made_on_the_gpu_steps_as_one_switched_there() {
    let mut made = made_on_gpu();
    assert_eq!(
        (made.backend(), made.params().backend),
        (Backend::Gpu, Backend::Gpu)
    );
    fill_small_tank(&mut made);
    let mut switched = World::new(Params::default()).expect("parameters");
    fill_small_tank(&mut switched);
    let mut switched = on_gpu(switched);
    assert_eq!(switched.params(), made.params());
    let start = made.positions();
    for _ in 0..TANK_STEPS {
        made.step().expect("a step on the GPU");
        switched.step().expect("a step on the GPU");
    }
    assert!(made.positions() == switched.positions(), "positions differ");
    assert!(
        made.velocities() == switched.velocities(),
        "velocities differ"
    );
    assert_eq!(made.time().to_bits(), switched.time().to_bits());
    assert!(made.positions() != start, "the fluid did not move");

    let field = Aabb {
        min: Vec3::repeat(1.0),
        max: Vec3::repeat(2.0),
    };
    let before = made.positions_hash();
    let refusals = [
        (
            made.add_container_field(field).err(),
            "container walls built as fields",
        ),
        (
            made.add_material(Material {
                rest_density: 800.0,
            })
            .err(),
            "several fluid materials",
        ),
        (
            made.set_solver(SolverKind::Cg, ChebyshevParams::default())
                .err(),
            "the cg solver",
        ),
    ];
    for (error, what) in refusals {
        assert_eq!(
            error.map(|e| e.to_string()),
            Some(format!(
                "backend gpu: does not support {what} yet; use the CPU backend"
            ))
        );
    }
    assert_eq!(made.positions_hash(), before);
    assert_eq!(made.containers().len(), 1);
    assert_eq!(made.material_count(), 1);
    assert_eq!(made.params().solver, SolverKind::Chebyshev);

    made.set_backend(Backend::Cpu)
        .expect("the CPU is always there");
    assert_eq!(
        (made.backend(), made.params().backend),
        (Backend::Cpu, Backend::Cpu)
    );
    made.step().expect("the CPU steps it on");
}

/// The C API's last error message.
fn last_error() -> String {
    // SAFETY: never NULL, NUL-terminated, valid until this thread's next call.
    unsafe { CStr::from_ptr(pf_last_error_message()) }
        .to_string_lossy()
        .into_owned()
}

/// `pf_params_default` with `backend` set to `backend`.
fn c_params(backend: u32) -> PfParams {
    let mut params = MaybeUninit::<PfParams>::uninit();
    // SAFETY: a writable PfParams.
    assert_eq!(
        unsafe { pf_params_default(params.as_mut_ptr()) },
        PfStatus::PF_OK
    );
    // SAFETY: filled above.
    let mut params = unsafe { params.assume_init() };
    params.backend = backend;
    params
}

/// Through the C API: a world created with `PfParams.backend = PF_BACKEND_GPU` reports the
/// backend, fills, steps and reads as the Rust API's world on the GPU does, to the bit, and
/// refuses a body and walls built as fields with the GPU backend's message, changing
/// nothing. An unknown backend, and the GPU with a solver it does not run, make no world.
#[test]
fn the_c_api_steps_a_world_on_the_gpu_and_refuses_its_misuse() {
    const GPU: u32 = PfBackend::PF_BACKEND_GPU as u32;
    let ok = |status: PfStatus, call: &str| {
        assert_eq!(status, PfStatus::PF_OK, "{call}: {}", last_error());
    };
    let params = c_params(GPU);
    let mut world = ptr::null_mut();
    // SAFETY: valid pointers throughout; the world is destroyed once, at the end.
    unsafe {
        ok(pf_world_create(&params, &mut world), "pf_world_create");
        let mut back = c_params(0);
        ok(pf_world_get_params(world, &mut back), "pf_world_get_params");
        assert_eq!(back.backend, GPU);
        let (lo, hi) = ([0.0f32; 3], [0.5f32; 3]);
        ok(
            pf_world_add_container_box(world, lo.as_ptr(), hi.as_ptr(), 1),
            "pf_world_add_container_box",
        );
        let (start, count) = ([0.0625f32; 3], [8usize; 3]);
        ok(
            pf_world_add_fluid_box(world, start.as_ptr(), count.as_ptr(), ptr::null()),
            "pf_world_add_fluid_box",
        );
        for _ in 0..TANK_STEPS {
            ok(pf_world_step(world, 0.0), "pf_world_step");
        }
        let mut positions = vec![0.0f32; 3 * 512];
        let mut needed = 0;
        ok(
            pf_world_get_positions(world, positions.as_mut_ptr(), positions.len(), &mut needed),
            "pf_world_get_positions",
        );
        assert_eq!(needed, positions.len());
        let mut rust = made_on_gpu();
        fill_small_tank(&mut rust);
        for _ in 0..TANK_STEPS {
            rust.step().expect("a step on the GPU");
        }
        let expected: Vec<f32> = rust
            .positions()
            .iter()
            .flat_map(|p| [p.x as f32, p.y as f32, p.z as f32])
            .collect();
        assert!(
            positions == expected,
            "the C API's world differs from the Rust API's"
        );

        let mut hash = [0u8; 65];
        let hash_of = |world, hash: &mut [u8; 65]| {
            let mut needed = 0;
            ok(
                pf_world_positions_hash(world, hash.as_mut_ptr().cast(), 65, &mut needed),
                "pf_world_positions_hash",
            );
            *hash
        };
        let before = hash_of(world, &mut hash);
        let mut pose = MaybeUninit::<PfPose>::uninit();
        ok(pf_pose_identity(pose.as_mut_ptr()), "pf_pose_identity");
        let pose = pose.assume_init();
        let half = [0.05f64; 3];
        let mut id = usize::MAX;
        assert_eq!(
            pf_world_add_body_box(world, 1, half.as_ptr(), 0.0, &pose, &mut id),
            PfStatus::PF_ERROR_INVALID_ARGUMENT
        );
        assert_eq!(
            last_error(),
            "pf_world_add_body_box: backend gpu: does not support bodies yet; use the CPU backend"
        );
        assert_eq!(id, usize::MAX);
        let (far_lo, far_hi) = ([1.0f32; 3], [2.0f32; 3]);
        assert_eq!(
            pf_world_add_container_field(world, far_lo.as_ptr(), far_hi.as_ptr()),
            PfStatus::PF_ERROR_INVALID_ARGUMENT
        );
        assert_eq!(
            last_error(),
            "pf_world_add_container_field: backend gpu: does not support container walls built \
             as fields yet; use the CPU backend"
        );
        let (mut bodies, mut fluid) = (usize::MAX, 0);
        ok(
            pf_world_body_count(world, &mut bodies),
            "pf_world_body_count",
        );
        ok(
            pf_world_fluid_count(world, &mut fluid),
            "pf_world_fluid_count",
        );
        assert_eq!((bodies, fluid), (0, 512));
        assert_eq!(hash_of(world, &mut hash), before);
        ok(
            pf_world_step(world, 0.0),
            "pf_world_step after the refusals",
        );
        pf_world_destroy(world);

        for (bad, message) in [
            (
                c_params(2),
                "pf_world_create: params->backend must be PF_BACKEND_CPU (0) or PF_BACKEND_GPU \
                 (1), got 2",
            ),
            (
                PfParams {
                    solver: PfSolver::PF_SOLVER_CG,
                    ..c_params(GPU)
                },
                "pf_world_create: backend gpu: does not support the cg solver yet; use the CPU \
                 backend",
            ),
        ] {
            let mut none = ptr::NonNull::dangling().as_ptr();
            assert_eq!(
                pf_world_create(&bad, &mut none),
                PfStatus::PF_ERROR_INVALID_ARGUMENT
            );
            assert_eq!(last_error(), message);
            assert!(none.is_null());
        }
    }
}

/// A scene whose key `backend` is `"gpu"` builds its world on the GPU, and a checkpoint of
/// that world records the key and resumes on the GPU, where it steps on.
#[test]
fn a_scene_for_the_gpu_and_its_checkpoint_run_there() {
    let mut scene = Scene::builtin("dam_break_small").expect("a built-in scene");
    scene.fluid_blocks[0].count = [6, 8, 5];
    let json = scene
        .to_json()
        .replace("\"backend\": \"cpu\"", "\"backend\": \"gpu\"");
    let scene = Scene::from_json(&json).expect("the scene reads");
    assert_eq!(scene.params.backend, Backend::Gpu);
    let mut world = scene.build_world().expect("the scene builds on the GPU");
    assert_eq!(world.backend(), Backend::Gpu);
    for _ in 0..2 {
        world.step().expect("a step on the GPU");
    }
    let path = std::env::temp_dir().join(format!("projfluid-gpu-{}.pfck", std::process::id()));
    write_checkpoint(&path, &scene, &world, None).expect("the checkpoint is written");
    let bytes = std::fs::read(&path).expect("the checkpoint reads");
    let restored = read_checkpoint(&path, None);
    std::fs::remove_file(&path).expect("the checkpoint is removed");
    let key = br#"\"backend\": \"gpu\""#;
    assert!(
        bytes.windows(key.len()).any(|w| w == key),
        "the checkpoint lacks the key"
    );
    let mut resumed = restored.expect("the checkpoint resumes").world;
    assert_eq!(resumed.backend(), Backend::Gpu);
    assert_eq!(resumed.params(), world.params());
    assert_eq!(resumed.positions_hash(), world.positions_hash());
    resumed.step().expect("the resumed world steps on the GPU");
    world.step().expect("a step on the GPU");
    let apart = (resumed.positions().iter().zip(world.positions()))
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(
        apart < 1e-4,
        "the resumed run is {apart} m from the original"
    );
}
