//! The GPU backend (feature `gpu`) against the CPU: a dam break and a tank at rest on the
//! first Vulkan adapter (in CI, Mesa's software device lavapipe); the backend chosen through
//! `Params::backend`, the C API's `PfParams.backend` and the scene key `backend`. A missing
//! adapter fails these tests with the reason; it does not skip them.
#![cfg(feature = "gpu")]

#[path = "support/honey.rs"]
mod honey;
#[path = "support/thrown.rs"]
mod thrown;
#[path = "support/vortex.rs"]
mod vortex;

use honey::{fronts, honey_beside_water};
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
use thrown::{clearance, thrown_at_the_floor};
use vortex::{swirl, vortex};

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

/// `world` on `backend`: switched to the GPU ([`on_gpu`]) or left on the CPU.
fn on_backend(world: World, backend: Backend) -> World {
    match backend {
        Backend::Gpu => on_gpu(world),
        Backend::Cpu => world,
    }
}

/// The positions (m) and velocities (m/s) of `world` after `steps` steps on the GPU.
fn stepped_on_gpu(world: World, steps: usize) -> (Vec<Vec3>, Vec<Vec3>) {
    let mut world = on_gpu(world);
    for _ in 0..steps {
        world.step().expect("a step on the GPU");
    }
    (world.positions(), world.velocities())
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
    /// The fluid count after each step, and the particles sinks and the domain removed.
    counts: Vec<usize>,
    removed: u64,
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
    let (mut density_errors, mut iterations, mut counts) = (Vec::new(), Vec::new(), Vec::new());
    let started = std::time::Instant::now();
    let steps = world
        .advance_with(seconds, |w| {
            let stats = w.last_step().expect("a step was taken");
            density_errors.push(stats.density_error_avg);
            iterations.push(stats.outer_iterations);
            counts.push(w.fluid_count());
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
        counts,
        removed: world.removed_count(),
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

/// The pressure a tank at rest reads over `steps` steps at the defaults, on `backend`, from
/// `state` (the relaxed tank's): Σ p_i over Σ ρ0·g·(S − y_i), S being the surface half a
/// spacing above the highest particle, over the particles at least a support radius from
/// the side walls and below the surface layers, summed over the steps.
fn hydrostatic_ratio(
    state: projfluid::WorldState,
    container: &Aabb,
    backend: Backend,
    steps: usize,
) -> f64 {
    let mut world = World::new(Params::default()).expect("parameters");
    world.import_state(state).expect("the relaxed state");
    let mut world = on_backend(world, backend);
    let (h, r) = (
        world.params().support_radius(),
        world.params().particle_radius,
    );
    let g = world.params().gravity[1].abs();
    let rho0 = world.params().rest_density;
    let (mut read, mut hydrostatic) = (0.0, 0.0);
    for _ in 0..steps {
        world.step().expect("a step");
        let pressures = world.constraint_pressures();
        let surface = pressures
            .samples
            .iter()
            .map(|(p, _)| p.y)
            .fold(f64::MIN, f64::max)
            + r;
        for (p, value) in &pressures.samples {
            let inner = p.x - container.min.x >= h
                && container.max.x - p.x >= h
                && p.z - container.min.z >= h
                && container.max.z - p.z >= h
                && p.y < surface - h;
            if inner {
                read += value;
                hydrostatic += rho0 * g * (surface - p.y);
            }
        }
    }
    read / hydrostatic
}

/// A GPU step carries its constraints' pressures through its iteration as the CPU's does
/// (docs/method.md §10.1): a tank at rest, stepped at the defaults, reads ρ0·g·depth on the
/// device as it does on the CPU, within 15 % of it. Read from a local step at the end
/// positions instead, as before the device carried them, the default τ leaves it far off.
#[test]
fn a_tank_at_rest_reads_its_hydrostatic_pressure_on_the_gpu() {
    let (relaxed, container) = relaxed_tank();
    let state = relaxed.export_state();
    let cpu = hydrostatic_ratio(state.clone(), &container, Backend::Cpu, 20);
    let gpu = hydrostatic_ratio(state, &container, Backend::Gpu, 20);
    eprintln!("tank at rest: pressure over rho0 g depth: GPU {gpu}, CPU {cpu}");
    assert!((cpu - 1.0).abs() < 0.2, "CPU {cpu}");
    assert!((gpu - cpu).abs() < 0.15 * cpu, "GPU {gpu}, CPU {cpu}");
}

/// Water thrown at a floor one layer thick and stepped at a fixed 1/60 s, a step moving it
/// some 5r, stays inside its container on the device as on the CPU (tests/containment.rs):
/// after every step every particle lies at least r/2 from the walls' planes, to single
/// precision (docs/method.md §7). Without the clearance on the device, most of the block
/// passed through the floor in its first step.
#[test]
fn water_stepped_at_a_frame_rate_stays_in_its_container_on_the_gpu() {
    let (world, r, side) = thrown_at_the_floor();
    let mut world = on_gpu(world);
    for step in 0..60 {
        world.step_with_dt(1.0 / 60.0).unwrap();
        let least = clearance(&world, side);
        assert!(
            least >= 0.5 * r - 1e-6,
            "step {step}: a particle {least} m from a wall's plane"
        );
        assert_eq!(world.escaped_count(), 0, "step {step}");
    }
}

/// Worlds with what the GPU backend does not step yet (walls built as fields, surface
/// tension, wall adhesion) are refused, naming it, and the world stays on the CPU; worlds
/// with vorticity confinement, several materials or the physical viscosity, which it steps,
/// are taken.
#[test]
fn unsupported_worlds_are_refused_naming_the_feature() {
    let mut world = World::new(Params::default()).expect("parameters");
    let tank = Aabb {
        min: Vec3::zeros(),
        max: Vec3::repeat(0.5),
    };
    world.add_container_field(tank).expect("a field wall");
    world
        .add_fluid_block(Vec3::repeat(0.1), [4, 4, 4], Vec3::zeros())
        .expect("fluid");
    let message = world.set_backend(Backend::Gpu).unwrap_err().to_string();
    assert!(
        message.contains("backend") && message.contains("fields"),
        "{message}"
    );
    assert_eq!(world.backend(), Backend::Cpu);
    for (params, what) in [
        (
            Params {
                surface_tension: 0.07,
                ..Params::default()
            },
            "surface tension (surface_tension)",
        ),
        (
            Params {
                wall_adhesion: 0.1,
                ..Params::default()
            },
            "the adhesion to walls (wall_adhesion)",
        ),
    ] {
        let mut world = World::new(params.clone()).expect("parameters");
        let message = world.set_backend(Backend::Gpu).unwrap_err().to_string();
        assert_eq!(
            message,
            format!("backend gpu: does not support {what} yet; use the CPU backend")
        );
        assert_eq!(world.backend(), Backend::Cpu);
        let on_gpu = Params {
            backend: Backend::Gpu,
            ..params
        };
        assert!(World::new(on_gpu).is_err());
    }
    // Vorticity confinement, the physical viscosity and a second material are stepped there.
    let mut world = World::new(Params {
        vorticity_confinement: 0.3,
        kinematic_viscosity: 1e-3,
        backend: Backend::Gpu,
        ..Params::default()
    })
    .expect("vorticity confinement and viscosity run on the GPU");
    world
        .add_fluid_block(Vec3::zeros(), [4, 4, 4], Vec3::zeros())
        .expect("fluid");
    world.step().expect("a step on the GPU");
    let mut world = World::new(Params::default()).expect("parameters");
    let oil = world
        .add_material(Material::with_density(800.0))
        .expect("a material");
    world.set_fluid_material(oil).expect("the material");
    world
        .add_fluid_block(Vec3::zeros(), [4, 4, 4], Vec3::zeros())
        .expect("fluid");
    let mut world = on_gpu(world);
    world.step().expect("a step on the GPU");
    world
        .set_material_kinematic_viscosity(oil, 1e-3)
        .expect("a material's viscosity on the GPU");
    world.step().expect("a viscous step on the GPU");
    assert_eq!(world.material(oil).unwrap().kinematic_viscosity, 1e-3);
}

/// The physical viscosity on the device follows the CPU's (docs/method.md §13, §14): honey
/// (1420 kg/m³, ν = 0.1 m²/s) and water collapsing towards each other in one tank
/// (tests/viscosity.rs) run as far on the GPU as on the CPU after 0.4 s, within 5 % or a
/// quarter spacing, none escaping; and there too the honey runs less than half as far as
/// the water.
#[test]
fn viscosity_on_the_gpu_follows_the_cpu() {
    let seconds = 0.4;
    let run = |backend: Backend| {
        let (world, honey) = honey_beside_water(0.1);
        let mut world = on_backend(world, backend);
        let started = std::time::Instant::now();
        let steps = world.advance(seconds).expect("the run steps");
        eprintln!(
            "honey beside water, {backend:?}: {steps} steps, {:.1} ms per step",
            started.elapsed().as_secs_f64() * 1e3 / steps as f64
        );
        assert_eq!(world.escaped_count() + world.nan_count(), 0);
        fronts(&world, honey)
    };
    let (water_cpu, honey_cpu) = run(Backend::Cpu);
    let (water, honey) = run(Backend::Gpu);
    let report = format!(
        "fronts: water {water} m on the GPU, {water_cpu} m on the CPU; \
         honey {honey} m on the GPU, {honey_cpu} m on the CPU"
    );
    eprintln!("{report}");
    let near = |a: f64, b: f64| (a - b).abs() < (0.05 * b).max(0.25 * 0.05);
    assert!(near(water, water_cpu), "{report}");
    assert!(near(honey, honey_cpu), "{report}");
    assert!(water > 2.0 * honey, "{report}");
}

/// The solve's sums and inner products are gathers and fixed reductions on the device too:
/// two runs of honey beside water give the same bits, and the viscosity changed the flow.
#[test]
fn two_gpu_runs_with_viscosity_agree_to_the_bit() {
    let run = |nu: f64| stepped_on_gpu(honey_beside_water(nu).0, 20);
    let (a, b, plain) = (run(0.1), run(0.1), run(0.0));
    assert!(a.0 == b.0, "positions differ");
    assert!(a.1 == b.1, "velocities differ");
    assert!(a.1 != plain.1, "the viscosity changed nothing");
}

/// A GPU step reports the device's own time in each stage, from timestamps (lavapipe and
/// graphics cards have them): the search, which the host does not wait for, takes a real
/// share of the step, every stage some time, and together no more than the step took.
#[test]
fn a_gpu_step_reports_the_devices_time_per_stage() {
    let mut world = on_gpu(dam_break());
    world.advance(0.05).expect("the run steps");
    for _ in 0..5 {
        let started = std::time::Instant::now();
        world.step().expect("a step on the GPU");
        let wall = started.elapsed().as_secs_f64();
        let t = world.last_step().expect("a step was taken").timings;
        let report = format!("{t:?} in a step of {wall} s");
        assert!(t.neighbors > 0.02 * wall, "{report}");
        assert!(t.global > 0.0 && t.rest > 0.0, "{report}");
        assert!(
            t.neighbors + t.local + t.global + t.rest <= wall,
            "{report}"
        );
    }
}

/// Settings changed between steps reach a world already stepping on the GPU, as on the CPU:
/// 0.1 s into the dam break, with τ so small and η so nearly 0 that no rule holds, a step takes the most outer
/// iterations twice (Chebyshev's, then the fallback's plain iterations, docs/method.md §4),
/// on both backends alike; after a change of the most iterations, the next step takes the
/// new most twice; and after a change back, the rules hold again within the most.
#[test]
fn settings_changed_between_steps_reach_the_gpu() {
    let outer_iterations = |backend: Backend| {
        let mut world = on_backend(dam_break(), backend);
        let mut counts = Vec::new();
        let mut step = |world: &mut World| {
            world.step().expect("a step");
            let stats = world.last_step().expect("a step was taken");
            counts.push((stats.outer_iterations, stats.hit_max_iterations));
        };
        world.advance(0.1).expect("the run steps");
        step(&mut world);
        world.set_displacement_tolerance(1e-12).expect("τ");
        world.set_density_tolerance(1e-12).expect("η");
        world.set_outer_iterations(1, 12).expect("iterations");
        step(&mut world);
        world.set_outer_iterations(1, 7).expect("iterations");
        step(&mut world);
        world.set_displacement_tolerance(1e-3).expect("τ");
        step(&mut world);
        counts
    };
    let cpu = outer_iterations(Backend::Cpu);
    let gpu = outer_iterations(Backend::Gpu);
    assert_eq!(cpu[1..3], [(24, true), (14, true)], "CPU: {cpu:?}");
    assert_eq!(gpu[1..3], cpu[1..3], "GPU: {gpu:?}, CPU: {cpu:?}");
    assert!(!gpu[3].1 && gpu[3].0 <= 7, "GPU: {gpu:?}");
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
            made.set_solver(SolverKind::Cg, ChebyshevParams::default())
                .err(),
            "the cg solver",
        ),
        (
            made.set_material_surface_tension(0, 0.07).err(),
            "surface tension (surface_tension)",
        ),
        (
            made.add_material(Material {
                surface_tension: 0.03,
                ..Material::with_density(800.0)
            })
            .err(),
            "surface tension (surface_tension)",
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
    assert_eq!(made.params().surface_tension, 0.0);
    // A material is added to a world on the device as on the CPU, and the world steps on
    // there with its constants made again.
    let oil = made
        .add_material(Material::with_density(800.0))
        .expect("materials run on the GPU");
    assert_eq!(made.material(oil).map(|m| m.rest_density), Some(800.0));
    made.step()
        .expect("a world of two materials steps on the GPU");
    assert_eq!(made.backend(), Backend::Gpu);

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

/// The share of its swirl (0.10–0.25 m from the axis) the vortex of tests/vorticity.rs
/// keeps over `seconds` with confinement `epsilon`, on `backend`; and its kinetic energy
/// after (J).
fn vortex_kept(epsilon: f64, backend: Backend, seconds: f64) -> (f64, f64) {
    let (world, axis) = vortex(
        Params {
            vorticity_confinement: epsilon,
            ..Params::default()
        },
        [20, 20, 4],
        0.15,
    );
    let mut world = on_backend(world, backend);
    let start = swirl(&world, axis, 0.1, 0.25);
    let started = std::time::Instant::now();
    let steps = world.advance(seconds).expect("the run steps");
    eprintln!(
        "vortex, ε = {epsilon}, {backend:?}: {steps} steps, {:.1} ms per step",
        started.elapsed().as_secs_f64() * 1e3 / steps as f64
    );
    assert_eq!(world.escaped_count() + world.nan_count(), 0);
    (
        swirl(&world, axis, 0.1, 0.25) / start,
        world.kinetic_energy(),
    )
}

/// Vorticity confinement on the device follows the CPU's (docs/method.md §15): over 0.5 s the
/// vortex keeps the share of its swirl that the CPU's keeps with the same ε within 0.03,
/// and its kinetic energy within 4 %; and, as on the CPU, it keeps measurably more of both
/// than without confinement (the CPU keeps 0.81 of the swirl without and 1.05 with ε = 1).
#[test]
fn vorticity_confinement_on_the_gpu_follows_the_cpu() {
    let seconds = 0.5;
    let epsilon = 1.0;
    let (cpu, cpu_energy) = vortex_kept(epsilon, Backend::Cpu, seconds);
    let (cpu_plain, cpu_plain_energy) = vortex_kept(0.0, Backend::Cpu, seconds);
    let (gpu, gpu_energy) = vortex_kept(epsilon, Backend::Gpu, seconds);
    let (gpu_plain, gpu_plain_energy) = vortex_kept(0.0, Backend::Gpu, seconds);
    let report = format!(
        "swirl kept: CPU {cpu_plain} → {cpu} (ε = {epsilon}), GPU {gpu_plain} → {gpu}; \
         kinetic energy: CPU {cpu_plain_energy} → {cpu_energy} J, \
         GPU {gpu_plain_energy} → {gpu_energy} J"
    );
    eprintln!("{report}");
    // The CPU's confinement keeps the vortex turning: the direction the GPU must follow.
    assert!(cpu > cpu_plain + 0.15, "{report}");
    assert!((gpu - cpu).abs() < 0.03, "{report}");
    assert!((gpu_plain - cpu_plain).abs() < 0.03, "{report}");
    assert!(gpu > gpu_plain + 0.15, "{report}");
    assert!(
        (gpu_energy - cpu_energy).abs() < 0.04 * cpu_energy,
        "{report}"
    );
    assert!(gpu_energy > 1.2 * gpu_plain_energy, "{report}");
}

/// The confinement's sums are gathers on the device too: two runs of a confined vortex give
/// the same bits, and the confinement changed the flow.
#[test]
fn two_gpu_runs_with_vorticity_confinement_agree_to_the_bit() {
    let run = |epsilon: f64| {
        let params = Params {
            vorticity_confinement: epsilon,
            ..Params::default()
        };
        stepped_on_gpu(vortex(params, [12, 12, 4], 0.1).0, 20)
    };
    let (a, b, plain) = (run(0.5), run(0.5), run(0.0));
    assert!(a.0 == b.0, "positions differ");
    assert!(a.1 == b.1, "velocities differ");
    assert!(a.1 != plain.1, "the confinement changed nothing");
}

/// A 12 × 16 × 12 tank of water with a 4 × 4 × 4 blob of `blob` (kg/m³) in its upper half
/// (material 1; the scene of tests/materials.rs), and its tank.
fn blob_world(blob: f64) -> World {
    let count = [12, 16, 12];
    let params = Params::default();
    let (r, d) = (params.particle_radius, params.spacing());
    let mut world = World::new(params).expect("parameters");
    let gap = d + 0.25 * r;
    let extent = |c: usize| (c - 1) as f64 * d + 2.0 * gap;
    let tank = Aabb {
        min: Vec3::zeros(),
        max: Vec3::new(extent(count[0]), 1.5 * extent(count[1]), extent(count[2])),
    };
    world.add_container(tank, 1).expect("container");
    let middle = |c: usize| (4..8).contains(&c);
    let (mut water, mut heavy) = (Vec::new(), Vec::new());
    for k in 0..count[2] {
        for j in 0..count[1] {
            for i in 0..count[0] {
                let p = Vec3::new(i as f64, j as f64, k as f64) * d + Vec3::repeat(gap);
                if middle(i) && middle(k) && (10..14).contains(&j) {
                    heavy.push(p);
                } else {
                    water.push(p);
                }
            }
        }
    }
    world.add_fluid_particles(&water, None).expect("water");
    let material = world
        .add_material(Material::with_density(blob))
        .expect("a material");
    world.set_fluid_material(material).expect("the material");
    world.add_fluid_particles(&heavy, None).expect("the blob");
    world
}

/// The mean height (m) and the mean density (kg/m³, in the material's own terms) of the
/// particles of `material`.
fn material_means(world: &World, material: u16) -> (f64, f64) {
    let (x, rho, m) = (
        world.positions(),
        world.densities(),
        world.particle_materials(),
    );
    let (mut height, mut density, mut n) = (0.0, 0.0, 0);
    for ((p, r), _) in x.iter().zip(&rho).zip(&m).filter(|(_, k)| **k == material) {
        height += p.y;
        density += r;
        n += 1;
    }
    (height / n as f64, density / n as f64)
}

/// A blob half again as dense as water sinks through it on the device as on the CPU
/// (docs/method.md §14): over 1 s its mean height falls by the CPU's drop within a fifth
/// (0.32 m on the CPU, most of the way to the floor) while one of water's density stays;
/// each material's mean density reads within 1 % of its own rest density, as on the CPU;
/// and the materials follow their particles through the device's sort.
#[test]
fn a_heavy_blob_sinks_on_the_gpu_as_on_the_cpu() {
    let seconds = 1.0;
    let drop = |blob: f64, backend: Backend| {
        let mut world = on_backend(blob_world(blob), backend);
        let materials = world.particle_materials();
        let (start, _) = material_means(&world, 1);
        let started = std::time::Instant::now();
        let steps = world.advance(seconds).expect("the run steps");
        eprintln!(
            "blob of {blob} kg/m³, {backend:?}: {steps} steps, {:.1} ms per step",
            started.elapsed().as_secs_f64() * 1e3 / steps as f64
        );
        assert_eq!(world.escaped_count() + world.nan_count(), 0);
        assert!(world.particle_materials() == materials, "materials moved");
        let (end, blob_density) = material_means(&world, 1);
        let (_, water_density) = material_means(&world, 0);
        (start - end, blob_density, water_density)
    };
    let cpu = drop(1500.0, Backend::Cpu);
    let gpu = drop(1500.0, Backend::Gpu);
    let neutral = drop(1000.0, Backend::Gpu);
    let report = format!(
        "(drop m, blob's density, water's density kg/m³): heavy on the CPU {cpu:?}, on the \
         GPU {gpu:?}; neutral on the GPU {neutral:?}"
    );
    eprintln!("{report}");
    assert!(cpu.0 > 0.2, "{report}");
    assert!((gpu.0 - cpu.0).abs() < 0.2 * cpu.0, "{report}");
    assert!(neutral.0.abs() < 0.05, "{report}");
    let near = |density: f64, rest: f64| (density / rest - 1.0).abs() < 0.01;
    for (run, blob) in [(cpu, 1500.0), (gpu, 1500.0), (neutral, 1000.0)] {
        assert!(near(run.1, blob) && near(run.2, 1000.0), "{report}");
    }
}

/// Two liquids on the device: two runs give the same bits, and a material of the world's
/// own density steps to the same bits as the world's fluid does (its mass ratio 1 leaves
/// every weight as it is).
#[test]
fn two_liquids_on_the_gpu_agree_to_the_bit() {
    let steps = 15;
    let run = |world: World| {
        let mut world = on_gpu(world);
        for _ in 0..steps {
            world.step().expect("a step on the GPU");
        }
        (world.positions(), world.velocities(), world.densities())
    };
    let (a, b) = (run(blob_world(2000.0)), run(blob_world(2000.0)));
    assert!(a.0 == b.0, "positions differ");
    assert!(a.1 == b.1, "velocities differ");
    assert!(a.2 == b.2, "densities differ");
    let neutral = run(blob_world(1000.0));
    let mut plain = blob_world(1000.0);
    let mut state = plain.export_state();
    state.materials.fill(0);
    plain
        .import_state(state)
        .expect("the same particles, of the world's fluid");
    let plain = run(plain);
    assert!(
        neutral.0 == plain.0,
        "a material of the world's density changed the run"
    );
    assert!(a.0 != neutral.0, "the heavy blob changed nothing");
}

/// The built-in `fountain` (a disc emitter pouring into a pool with a drain) run for
/// `seconds` on `backend`.
fn fountain(backend: Backend, seconds: f64) -> Run {
    let scene = Scene::builtin("fountain").expect("a built-in scene");
    let world = scene.build_world().expect("the scene builds");
    let basin = Aabb {
        min: Vec3::repeat(-0.00625),
        max: Vec3::new(1.00625, 1.20625, 1.00625),
    };
    run(on_backend(world, backend), seconds, &basin)
}

/// Emitters run on the GPU: the fountain pours and drains there as on the CPU over 0.6 s
/// (the emitted layers reach the pool at 0.3 s): as many particles emitted within 1 %, the
/// drain removing some, the kinetic energy within 5 %, and no particle leaving the basin;
/// two GPU runs agree to the bit.
#[test]
fn an_emitter_pours_on_the_gpu_as_on_the_cpu() {
    let (cpu, gpu) = (fountain(Backend::Cpu, 0.6), fountain(Backend::Gpu, 0.6));
    let made = |run: &Run| run.counts.last().unwrap() + run.removed as usize;
    let (on_cpu, on_gpu) = (made(&cpu), made(&gpu));
    assert!(
        on_cpu > 1444 + 200,
        "the emitter added {} particles",
        on_cpu - 1444
    );
    assert!(gpu.removed > 0, "the drain removed nothing");
    assert!(
        on_cpu.abs_diff(on_gpu) <= on_cpu / 100,
        "particles made: {on_cpu} on the CPU, {on_gpu} on the GPU"
    );
    assert_eq!(gpu.escaped, 0);
    assert!(
        (gpu.kinetic - cpu.kinetic).abs() < 0.05 * cpu.kinetic,
        "kinetic energy {} on the GPU, {} on the CPU",
        gpu.kinetic,
        cpu.kinetic
    );
    let again = fountain(Backend::Gpu, 0.6);
    assert_eq!(again.counts, gpu.counts);
    assert_eq!(again.removed, gpu.removed);
    assert!(again.positions == gpu.positions, "positions differ");
}

/// Polls `future` to its end on this thread: wgpu's native futures resolve without an
/// executor.
fn block_on<F: std::future::Future>(future: F) -> F::Output {
    let mut future = std::pin::pin!(future);
    let mut context = std::task::Context::from_waker(std::task::Waker::noop());
    loop {
        if let std::task::Poll::Ready(value) = future.as_mut().poll(&mut context) {
            return value;
        }
        std::thread::yield_now();
    }
}

/// A device and queue as an engine makes them, from the first Vulkan adapter, with
/// `storage_buffers` storage buffers per shader stage in its limits.
fn engine_device(storage_buffers: u32) -> (wgpu::Device, wgpu::Queue) {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
    desc.backends = wgpu::Backends::VULKAN;
    let instance = wgpu::Instance::new(desc);
    let adapter = block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))
        .expect("a Vulkan adapter (lavapipe in CI)");
    let required_limits = wgpu::Limits {
        max_storage_buffers_per_shader_stage: storage_buffers,
        ..wgpu::Limits::default()
    };
    block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        required_limits,
        ..Default::default()
    }))
    .expect("a device")
}

/// The device buffer's positions in the world frame, read back through the engine's
/// device and sorted, with the world's own read sorted alike.
fn bound_positions(world: &World, device: &wgpu::Device, queue: &wgpu::Queue) -> Vec<[f64; 3]> {
    let bound = world.gpu_positions().expect("a step was taken on the GPU");
    let bytes = u64::from(bound.count) * 16;
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("engine read-back"),
        size: bytes,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_buffer_to_buffer(bound.buffer, 0, &staging, 0, bytes);
    queue.submit([encoder.finish()]);
    staging.map_async(wgpu::MapMode::Read, .., |r| r.expect("mapped"));
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("the device finishes");
    let data = staging
        .get_mapped_range(..)
        .expect("the mapped range")
        .to_vec();
    let mut points: Vec<[f64; 3]> = data
        .chunks_exact(16)
        .map(|c| {
            let f = |k: usize| f32::from_le_bytes([c[k], c[k + 1], c[k + 2], c[k + 3]]);
            let p = Vec3::new(f(0).into(), f(4).into(), f(8).into()) + bound.origin;
            [p.x, p.y, p.z]
        })
        .collect();
    points.sort_by(|a, b| a.partial_cmp(b).expect("finite"));
    points
}

/// An engine's own device steps a world as the one projfluid opens does, to the bit, and
/// the position buffer it can bind holds the positions `World::positions` reads; the
/// engine's uncaptured-error handler is left in place; a device with too few storage
/// buffers per stage is refused, naming the limit, and the world stays on the CPU.
#[test]
fn a_world_steps_on_the_engines_device_and_shares_its_positions() {
    let (device, queue) = engine_device(12);
    let caught = std::sync::Arc::new(std::sync::atomic::AtomicUsize::new(0));
    let counter = std::sync::Arc::clone(&caught);
    device.on_uncaptured_error(std::sync::Arc::new(move |_: wgpu::Error| {
        counter.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
    }));
    let mut engines = dam_break();
    assert!(engines.gpu_positions().is_none());
    engines
        .set_gpu_device(device.clone(), queue.clone())
        .expect("the engine's device");
    assert_eq!(engines.backend(), Backend::Gpu);
    assert!(
        engines.gpu_positions().is_none(),
        "nothing is on the device before a step"
    );
    let own = run(on_gpu(dam_break()), 0.1, &dam_container());
    engines.advance(0.1).expect("steps on the engine's device");
    assert!(engines.positions() == own.positions, "positions differ");
    let mut read: Vec<[f64; 3]> = engines
        .positions()
        .iter()
        .map(|p| [p.x, p.y, p.z])
        .collect();
    read.sort_by(|a, b| a.partial_cmp(b).expect("finite"));
    assert_eq!(bound_positions(&engines, &device, &queue), read);
    // The engine's handler still hears of the engine's own mistakes.
    assert_eq!(caught.load(std::sync::atomic::Ordering::SeqCst), 0);
    let _bad = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("unaligned and mapped"),
        size: 6,
        usage: wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: true,
    });
    assert_eq!(caught.load(std::sync::atomic::Ordering::SeqCst), 1);
    // Too few storage buffers per stage for the kernels.
    let (small, small_queue) = engine_device(8);
    let mut world = dam_break();
    let message = world
        .set_gpu_device(small, small_queue)
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("backend gpu") && message.contains("max_storage_buffers_per_shader_stage"),
        "{message}"
    );
    assert_eq!(world.backend(), Backend::Cpu);
}
