//! The GPU backend (feature `gpu`) against the CPU: a dam break and a tank at rest on the
//! first Vulkan adapter (in CI, Mesa's software device lavapipe). A missing adapter fails
//! these tests with the reason; it does not skip them.
#![cfg(feature = "gpu")]

use projfluid::boundary::Aabb;
use projfluid::scene::Scene;
use projfluid::{Backend, Params, Vec3, World};

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
