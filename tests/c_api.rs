//! Exercises the C API from C: compiles `tests/c/*.c` and `c_examples/*.c` with the system
//! `cc` (C11, all warnings as errors) against the crate's static and shared libraries, runs
//! them, checks their exit codes and output, compares a C simulation bit for bit with the
//! Rust API, runs the C tests under valgrind, runs the Python ctypes example, and checks the
//! `make install-files` layout (stripped libraries) with pkg-config and the CMake example.
//! Outside CI a missing valgrind, python3, make, pkg-config, readelf or cmake skips its
//! check with a note; under CI it fails the test (`support/tools.rs`).
//!
//! Under `cargo test --release` the libraries sit next to this test's executable in
//! `target/release/deps/` (`target/<profile>/deps/` for another profile).

use projfluid::boundary::Aabb;
use projfluid::scene::Scene;
use projfluid::{ChebyshevParams, Params, SolverKind, Vec3, World};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

#[path = "support/c_bodies.rs"]
mod c_bodies;
#[path = "support/tools.rs"]
mod tools;

/// How an executable links the library.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Link {
    /// `libprojfluid.a` plus the system libraries Rust's standard library needs.
    Static,
    /// `libprojfluid.so` found through an rpath.
    Shared,
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The directory holding `libprojfluid.a` and `libprojfluid.so` for this build.
fn lib_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("the test knows its own path");
    let dir = exe
        .parent()
        .expect("the test executable has a directory")
        .to_path_buf();
    for lib in ["libprojfluid.a", "libprojfluid.so"] {
        assert!(
            dir.join(lib).exists(),
            "{} is missing; the crate's staticlib/cdylib should be built by cargo test",
            dir.join(lib).display()
        );
    }
    dir
}

/// Where compiled C programs and their output files go.
fn out_dir() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("c_api");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn describe(output: &Output) -> String {
    format!(
        "exit status {}\n--- stdout ---\n{}\n--- stderr ---\n{}",
        output.status,
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    )
}

/// Compiles `source` (relative to the crate root) once per link kind, returning the program.
fn build(source: &str, link: Link) -> PathBuf {
    static BUILT: Mutex<Option<HashMap<(String, Link), PathBuf>>> = Mutex::new(None);
    let mut built = BUILT.lock().unwrap_or_else(|e| e.into_inner());
    let built = built.get_or_insert_with(HashMap::new);
    if let Some(exe) = built.get(&(source.to_string(), link)) {
        return exe.clone();
    }
    let stem = Path::new(source).file_stem().unwrap().to_string_lossy();
    let exe = out_dir().join(format!("{stem}-{link:?}").to_lowercase());
    let libs = lib_dir();
    let mut cc = Command::new("cc");
    cc.args([
        "-std=c11",
        "-Wall",
        "-Wextra",
        "-Wpedantic",
        "-Werror",
        "-O1",
        "-g",
    ])
    .arg("-I")
    .arg(root().join("include"))
    .arg("-I")
    .arg(root().join("tests/c"))
    .arg(root().join(source))
    .arg("-o")
    .arg(&exe);
    match link {
        Link::Static => {
            cc.arg(libs.join("libprojfluid.a"))
                .args(["-lm", "-lpthread", "-ldl"]);
        }
        Link::Shared => {
            cc.arg("-L")
                .arg(&libs)
                .arg("-lprojfluid")
                // RPATH rather than RUNPATH: cargo test puts target/<profile> (which may hold
                // an older libprojfluid.so from `cargo build`) on LD_LIBRARY_PATH, and only an
                // RPATH takes precedence over it.
                .arg("-Wl,--disable-new-dtags")
                .arg(format!("-Wl,-rpath,{}", libs.display()))
                .args(["-lm", "-lpthread"]);
        }
    }
    let output = cc.output().expect("the C compiler `cc` must be installed");
    assert!(
        output.status.success(),
        "compiling {source} ({link:?}) failed: {}",
        describe(&output)
    );
    built.insert((source.to_string(), link), exe.clone());
    exe
}

/// Runs `program` with `args`, requires exit code 0, and returns its stdout.
fn run(program: &Path, args: &[&str]) -> String {
    let output = Command::new(program)
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", program.display()));
    assert!(
        output.status.success(),
        "{} {args:?} failed: {}",
        program.display(),
        describe(&output)
    );
    String::from_utf8(output.stdout).unwrap()
}

#[test]
fn basic_c_program_runs_with_static_and_shared_library() {
    for link in [Link::Static, Link::Shared] {
        let out = run(&build("tests/c/basic.c", link), &["5"]);
        assert!(out.starts_with("basic: ok"), "{link:?}: {out}");
    }
}

#[test]
fn misuse_is_rejected_with_status_and_message_leaving_the_world_unchanged() {
    let out = run(&build("tests/c/misuse.c", Link::Static), &[]);
    assert!(out.starts_with("misuse: ok"), "{out}");
    let checked: usize = out
        .split_whitespace()
        .find_map(|w| w.parse().ok())
        .expect("misuse prints the number of rejected calls");
    assert!(checked >= 90, "only {checked} rejected calls were checked");
}

#[test]
fn a_triangle_mesh_obstacle_becomes_boundary_particles_that_hold_the_fluid() {
    for link in [Link::Static, Link::Shared] {
        let out = run(&build("tests/c/mesh.c", link), &[]);
        assert!(out.starts_with("mesh: ok"), "{link:?}: {out}");
    }
}

#[test]
fn obj_files_and_transformed_meshes_become_obstacles_and_bad_files_name_their_line() {
    let dir = out_dir().join("obj-files");
    std::fs::create_dir_all(&dir).unwrap();
    for link in [Link::Static, Link::Shared] {
        let out = run(&build("tests/c/obj.c", link), &[dir.to_str().unwrap()]);
        assert!(out.starts_with("obj: ok"), "{link:?}: {out}");
    }
}

#[test]
fn distinct_worlds_step_in_parallel_and_one_world_reports_busy() {
    let out = run(&build("tests/c/parallel.c", Link::Shared), &["6"]);
    assert!(out.starts_with("parallel: ok"), "{out}");
}

/// The world `tests/c/bitwise.c` builds and steps, through the Rust API with the same
/// float inputs widened to f64 exactly as the C API does.
fn rust_reference() -> World {
    let v = |x: f32, y: f32, z: f32| Vec3::new(x.into(), y.into(), z.into());
    let defaults = Params::default();
    let params = Params {
        particle_radius: 0.02,
        displacement_tolerance: 2e-5,
        solver: SolverKind::Chebyshev,
        chebyshev: ChebyshevParams {
            rho: 0.85,
            auto_rho: false,
            ..defaults.chebyshev
        },
        threads: 2,
        ..defaults
    };
    let mut world = World::new(params).unwrap();
    let container = Aabb {
        min: v(-0.005, -0.005, -0.005),
        max: v(0.5, 0.4, 0.3),
    };
    world.add_container(container, 2).unwrap();
    world
        .add_fluid_block(v(0.03, 0.03, 0.03), [6, 7, 5], v(0.25, 0.0, -0.125))
        .unwrap();
    let drops = [v(0.4, 0.3, 0.15), v(0.41, 0.25, 0.1), v(0.2, 0.35, 0.2)];
    let drop_v = [v(-0.5, 0.0, 0.0), v(0.0, -1.0, 0.1), v(0.0, 0.0, 0.0)];
    world.add_fluid_particles(&drops, Some(&drop_v)).unwrap();
    world
        .add_boundary_particles(&[v(0.25, 0.01, 0.15), v(0.25, 0.03, 0.15)])
        .unwrap();
    world.step_with_dt(0.002).unwrap();
    world.step().unwrap();
    world.step().unwrap();
    world.advance(0.01).unwrap();
    world
}

#[test]
fn c_simulation_matches_the_rust_api_bit_for_bit() {
    let file = out_dir().join("bitwise_positions.f32");
    let _ = std::fs::remove_file(&file);
    let out = run(
        &build("tests/c/bitwise.c", Link::Shared),
        &[file.to_str().unwrap()],
    );
    let c_hash = out
        .lines()
        .find_map(|l| l.strip_prefix("hash "))
        .expect("bitwise prints the positions hash");

    let world = rust_reference();
    assert_eq!(world.fluid_count(), 6 * 7 * 5 + 3);
    assert_eq!(
        c_hash,
        world.positions_hash(),
        "double-precision positions differ"
    );
    let expected: Vec<u8> = world
        .positions()
        .iter()
        .flat_map(|p| p.iter().map(|&c| c as f32).collect::<Vec<_>>())
        .flat_map(f32::to_ne_bytes)
        .collect();
    let written = std::fs::read(&file).unwrap();
    assert_eq!(written.len(), expected.len(), "float count differs");
    assert!(
        written == expected,
        "the float positions read through the C API differ from World::positions()"
    );
}

/// Bodies from C: a kinematic paddle pushes water, a dynamic sphere falls freely, a target
/// pose is reached, misuse is rejected changing no body, and the paddle tank matches the
/// same scene built through the Rust API bit for bit (particles, bodies and loads).
#[test]
fn c_bodies_move_push_fall_reject_misuse_and_match_the_rust_api() {
    let steps = 30;
    let expected = c_bodies::paddle_report(steps);
    for link in [Link::Static, Link::Shared] {
        let out = run(&build("tests/c/bodies.c", link), &[&steps.to_string()]);
        let last = out.lines().last().unwrap_or_default();
        assert!(last.starts_with("bodies: ok"), "{link:?}: {out}");
        let checked: usize = last
            .split_whitespace()
            .find_map(|w| w.parse().ok())
            .expect("bodies prints the number of rejected calls");
        assert!(checked >= 65, "only {checked} rejected calls were checked");
        let report: String = out
            .lines()
            .filter(|l| ["hash ", "body ", "wall "].iter().any(|p| l.starts_with(p)))
            .map(|l| format!("{l}\n"))
            .collect();
        assert_eq!(report, expected, "{link:?}: C and Rust differ");
    }
}

/// Emitters, sinks, the domain and removal by id from C: the counts add up, and every
/// misuse is rejected changing nothing.
#[test]
fn c_emitters_and_sinks_pour_drain_and_reject_misuse() {
    for link in [Link::Static, Link::Shared] {
        let out = run(&build("tests/c/emitters.c", link), &[]);
        let last = out.lines().last().unwrap_or_default();
        assert!(last.starts_with("emitters: ok"), "{link:?}: {out}");
        let checked: usize = last
            .split_whitespace()
            .find_map(|w| w.parse().ok())
            .expect("emitters prints the number of rejected calls");
        assert!(checked >= 40, "only {checked} rejected calls were checked");
    }
}

/// Allocation failure under a lowered address-space limit (in a forked child) returns
/// `PF_ERROR_OUT_OF_MEMORY`, changes nothing, and leaves the world usable.
#[test]
fn c_allocation_failure_is_a_status_that_changes_nothing() {
    let out = run(&build("tests/c/oom.c", Link::Static), &[]);
    assert!(
        out.starts_with("oom: ok") || out.starts_with("oom: skipped"),
        "{out}"
    );
}

/// Worlds made from scenes in C: misuse is rejected leaving `*out` NULL, a built-in scene
/// pours, and the same scene stepped from C and through the Rust API agrees bit for bit.
#[test]
fn c_worlds_from_scenes_reject_misuse_and_match_the_rust_api() {
    for link in [Link::Static, Link::Shared] {
        let out = run(&build("tests/c/scene.c", link), &[]);
        let last = out.lines().last().unwrap_or_default();
        assert!(last.starts_with("scene: ok"), "{link:?}: {out}");
        let checked: usize = last
            .split_whitespace()
            .find_map(|w| w.parse().ok())
            .expect("scene prints the number of rejected calls");
        assert!(checked >= 6, "only {checked} rejected calls were checked");
    }
    let steps = 12;
    let out = run(
        &build("tests/c/scene.c", Link::Shared),
        &["fountain", &steps.to_string()],
    );
    let mut world = Scene::builtin("fountain").unwrap().build_world().unwrap();
    for _ in 0..steps {
        world.step().unwrap();
    }
    let value = |key: &str| -> &str {
        out.lines()
            .find_map(|l| l.strip_prefix(key))
            .unwrap_or_else(|| panic!("scene prints {key}: {out}"))
    };
    assert_eq!(value("fluid "), world.fluid_count().to_string());
    assert_eq!(value("bodies "), "0");
    // %.17g gives the exact double back.
    assert_eq!(value("time ").parse::<f64>().unwrap(), world.time());
    assert_eq!(value("hash "), world.positions_hash(), "C and Rust differ");
}

#[test]
fn c_examples_build_and_run() {
    let out = run(&build("c_examples/minimal.c", Link::Static), &[]);
    // The README's quick start, as written, starts calm: every particle made, the water lower
    // than it started (no jolt lifts it), no step at the iteration limit.
    let line = out.lines().next().unwrap_or_default();
    assert!(line.starts_with("216 particles, mean height "), "{out}");
    let height: f64 = line["216 particles, mean height ".len()..]
        .split(' ')
        .next()
        .and_then(|h| h.parse().ok())
        .unwrap_or_else(|| panic!("{out}"));
    assert!(height < 0.175 && height > 0.05, "{out}");
    assert!(!line.contains("limit"), "{out}");
    let outer: usize = line
        .split("last step: ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{out}"));
    assert!(outer < 50, "{out}");
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let example = std::fs::read_to_string(root().join("c_examples/minimal.c")).unwrap();
    assert!(
        readme.contains(&format!("```c\n{example}```")),
        "the README's C quick start is not c_examples/minimal.c"
    );

    // The example simulates 0.5 s by default; a shorter run keeps the test fast.
    let out = run(&build("c_examples/dam_break.c", Link::Shared), &["0.1"]);
    assert!(
        out.starts_with("dam_break: 3840 fluid and"),
        "unexpected start: {out}"
    );
    let last = out.lines().last().unwrap_or_default();
    assert!(
        last.starts_with("final: ") && last.contains("escaped 0"),
        "{out}"
    );
    let avg: f64 = last
        .split("over the run ")
        .nth(1)
        .and_then(|s| s.split_whitespace().next())
        .and_then(|s| s.parse().ok())
        .expect("the final line reports the mean density error");
    assert!((0.0..5.0).contains(&avg), "mean density error {avg} %");

    // The fountain pours for 1 s by default; half of it shows emitting and draining.
    let out = run(&build("c_examples/fountain.c", Link::Static), &["0.5"]);
    assert!(out.starts_with("fountain: 1444 fluid"), "{out}");
    let last = out.lines().last().unwrap_or_default();
    assert!(
        last.starts_with("final: ") && last.ends_with("escaped 0, nan 0"),
        "{out}"
    );
    // "final: steps N, emitted N, removed N, fluid N, escaped 0, nan 0"
    let count = |key: &str| -> u64 {
        last.trim_start_matches("final: ")
            .split(", ")
            .find_map(|pair| pair.strip_prefix(key)?.trim().parse().ok())
            .unwrap_or_else(|| panic!("the final line reports {key}: {last}"))
    };
    let (emitted, removed, fluid) = (count("emitted"), count("removed"), count("fluid"));
    assert!(emitted > 0 && removed > 0, "{out}");
    assert_eq!(fluid + removed, 1444 + emitted, "{out}");
}

/// coupling.c floats a box as a kinematic body moved by its own integrator from the loads it
/// reads, and as the library's dynamic body: both settle at the same height, at rest, with the
/// box floating (below where it was dropped, well above the floor).
#[test]
fn a_box_coupled_through_the_c_api_floats_like_the_dynamic_body() {
    let program = build("c_examples/coupling.c", Link::Static);
    let settle = |mode: &str| -> (f64, f64) {
        let out = run(&program, &[mode, "2.5"]);
        let last = out.lines().last().unwrap_or_default();
        assert!(last.ends_with("escaped 0, nan 0"), "{out}");
        // "final: centre Y m, speed S m/s, steps N, escaped 0, nan 0"
        let number = |key: &str| -> f64 {
            last.split(key)
                .nth(1)
                .and_then(|s| s.split_whitespace().next())
                .and_then(|s| s.parse().ok())
                .unwrap_or_else(|| panic!("the final line reports {key}: {last}"))
        };
        (number("centre "), number("speed "))
    };
    let (coupled, coupled_speed) = settle("coupled");
    let (dynamic, dynamic_speed) = settle("dynamic");
    assert!(
        (coupled - dynamic).abs() < 0.005,
        "coupled box at {coupled} m, dynamic box at {dynamic} m"
    );
    assert!(coupled_speed < 0.05 && dynamic_speed < 0.05);
    // Dropped with its centre at 0.405 m; the water is about 0.3 m deep.
    assert!((0.25..0.37).contains(&coupled), "{coupled}");
}

#[test]
fn c_tests_are_clean_under_valgrind() {
    if !tools::available("valgrind") {
        return;
    }
    let suppressions = root().join("tests/c/valgrind.supp");
    let obj_dir = out_dir().join("obj-files-valgrind");
    std::fs::create_dir_all(&obj_dir).unwrap();
    let obj_dir = obj_dir.to_string_lossy().into_owned();
    let obj_args = [obj_dir.as_str()];
    // Not tests/c/oom.c: it limits the address space (RLIMIT_AS) relative to the process's
    // usage, which valgrind's own mappings and replaced allocator make meaningless.
    // placement.c first: it takes longer under valgrind than all the others together.
    let runs: Vec<(&str, PathBuf, &[&str])> = [
        ("tests/c/placement.c", &[][..]),
        ("tests/c/basic.c", &["2"][..]),
        ("tests/c/misuse.c", &[][..]),
        ("tests/c/mesh.c", &["0.01"][..]),
        ("tests/c/obj.c", &obj_args[..]),
        ("tests/c/parallel.c", &["2"][..]),
        ("tests/c/bodies.c", &["2"][..]),
        ("tests/c/emitters.c", &[][..]),
        ("tests/c/scene.c", &[][..]),
    ]
    .into_iter()
    .map(|(source, args)| (source, build(source, Link::Static), args))
    .collect();
    // Valgrind runs a program on one core, so the programs run side by side, one per core.
    let next = AtomicUsize::new(0);
    let failures = Mutex::new(Vec::new());
    let workers = std::thread::available_parallelism().map_or(2, |n| n.get());
    std::thread::scope(|scope| {
        for _ in 0..workers.min(runs.len()) {
            scope.spawn(|| {
                while let Some((source, program, args)) = runs.get(next.fetch_add(1, Relaxed)) {
                    let output = Command::new("valgrind")
                        .args(["--error-exitcode=99", "--leak-check=full", "--quiet"])
                        .arg(format!("--suppressions={}", suppressions.display()))
                        .arg(program)
                        .args(*args)
                        .output()
                        .expect("valgrind runs");
                    if !output.status.success() {
                        failures.lock().unwrap().push(format!(
                            "valgrind found errors or leaks in {source}: {}",
                            describe(&output)
                        ));
                    }
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn python_ctypes_example_runs() {
    if !tools::available("python3") {
        return;
    }
    let lib = lib_dir().join("libprojfluid.so");
    let output = Command::new("python3")
        .arg(root().join("c_examples/python/dam_break.py"))
        .arg(&lib)
        .output()
        .expect("python3 runs");
    assert!(output.status.success(), "{}", describe(&output));
    let out = String::from_utf8(output.stdout).unwrap();
    let last = out.lines().last().unwrap_or_default();
    assert!(
        last.starts_with("python dam_break: ok") && last.contains("escaped 0"),
        "{out}"
    );
}

#[test]
fn make_install_layout_works_with_pkg_config_and_cmake() {
    if !tools::available("make") {
        return;
    }
    let prefix = out_dir().join("prefix");
    let _ = std::fs::remove_dir_all(&prefix);
    // `install-files` is `make install` without its build step (`make build`), fed with the
    // libraries of this build.
    let output = Command::new("make")
        .current_dir(root())
        .arg("install-files")
        .arg(format!("PREFIX={}", prefix.display()))
        .arg(format!("BUILT={}", lib_dir().display()))
        .output()
        .expect("make runs");
    assert!(output.status.success(), "{}", describe(&output));
    for file in [
        "lib/libprojfluid.a",
        "lib/libprojfluid.so",
        "include/projfluid.h",
        "lib/pkgconfig/projfluid.pc",
    ] {
        assert!(prefix.join(file).exists(), "{file} was not installed");
    }
    let pc = std::fs::read_to_string(prefix.join("lib/pkgconfig/projfluid.pc")).unwrap();
    assert!(
        pc.contains(&format!("Version: {}", env!("CARGO_PKG_VERSION"))),
        "{pc}"
    );
    assert!(pc.contains(&format!("prefix={}", prefix.display())), "{pc}");

    if !tools::available("pkg-config") {
        return;
    }
    let flags = Command::new("pkg-config")
        .args(["--cflags", "--libs", "projfluid"])
        .env("PKG_CONFIG_PATH", prefix.join("lib/pkgconfig"))
        .output()
        .expect("pkg-config runs");
    assert!(flags.status.success(), "{}", describe(&flags));
    let flags = String::from_utf8(flags.stdout).unwrap();
    let exe = out_dir().join("minimal-pkgconfig");
    let output = Command::new("cc")
        .args(["-std=c11", "-Wall", "-Wextra", "-Wpedantic", "-Werror"])
        .arg(root().join("c_examples/minimal.c"))
        .arg("-o")
        .arg(&exe)
        .args(flags.split_whitespace())
        .arg(format!("-Wl,-rpath,{}", prefix.join("lib").display()))
        .output()
        .expect("cc runs");
    assert!(output.status.success(), "{}", describe(&output));
    let out = run(&exe, &[]);
    assert!(out.starts_with("216 particles, mean height"), "{out}");

    if tools::available("readelf") {
        for lib in ["lib/libprojfluid.so", "lib/libprojfluid.a"] {
            let sections = Command::new("readelf")
                .args(["--wide", "--sections"])
                .arg(prefix.join(lib))
                .output()
                .expect("readelf runs");
            let sections = String::from_utf8_lossy(&sections.stdout);
            assert!(
                !sections.contains(".debug_"),
                "the installed {lib} still carries debugging information"
            );
        }
    }

    if !tools::available("cmake") {
        return;
    }
    // The CMake example of docs/c-api.md, configured against the installed prefix.
    let build_dir = out_dir().join("cmake-build");
    let _ = std::fs::remove_dir_all(&build_dir);
    let configure = Command::new("cmake")
        .arg("-S")
        .arg(root().join("c_examples/cmake"))
        .arg("-B")
        .arg(&build_dir)
        .arg(format!("-DCMAKE_PREFIX_PATH={}", prefix.display()))
        .env_remove("PKG_CONFIG_PATH")
        .output()
        .expect("cmake runs");
    assert!(configure.status.success(), "{}", describe(&configure));
    let compile = Command::new("cmake")
        .arg("--build")
        .arg(&build_dir)
        .output()
        .expect("cmake runs");
    assert!(compile.status.success(), "{}", describe(&compile));
    let from_cmake = run(&build_dir.join("minimal"), &[]);
    assert_eq!(
        from_cmake, out,
        "the CMake build of minimal.c prints what the pkg-config build printed"
    );
}

/// The placement sweep of tests/placement.rs from C: blocks put 0 to 3 radii from container
/// walls of particles and of fields, a closed obstacle mesh and static and kinematic box
/// bodies start calm on one and two threads alike, and fluid placed in a solid is not made.
#[test]
fn c_placement_sweep_starts_calm_against_every_solid_on_one_and_two_threads() {
    for link in [Link::Static, Link::Shared] {
        let out = run(&build("tests/c/placement.c", link), &[]);
        assert_eq!(out.lines().last(), Some("placement: ok"), "{link:?}: {out}");
        for solid in [
            "wall particles:",
            "wall fields:",
            "obstacle mesh:",
            "static body:",
            "kinematic body:",
        ] {
            assert!(
                out.lines().any(|l| l.starts_with(solid)),
                "{link:?}: no line for {solid}\n{out}"
            );
        }
    }
}
