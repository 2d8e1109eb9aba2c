//! Deterministic property tests ("fuzzing") of the C API and of the JSON scene reader.
//!
//! The C API test drives seeded random sequences of `pf_` calls — valid and invalid
//! arguments (NULL, NaN, ±∞, negative, huge counts, short output buffers), steps, advances,
//! reads, emitters, sinks, removals and materials — against a small world, through the
//! crate's `extern "C"` functions, and checks after every call: no panic (`PF_ERROR_PANIC`), a
//! failed call changes nothing (counts, time, steps, positions, velocities, densities, ids and
//! materials bit for bit) and explains itself, a successful one clears the message, the counts add up (added +
//! emitted − removed = fluid), time moves as the call says, and nothing is NaN.
//!
//! The scene test feeds `Scene::from_json` mutated built-in scene files and random bytes and
//! requires an answer, never a panic; a scene that parses must write itself back readably.
//!
//! Budget: `PROJFLUID_FUZZ_BUDGET` multiplies the number of calls and inputs (default 1,
//! a few seconds); CI runs a larger one. `PROJFLUID_FUZZ_TRACE=1` prints every call.

use projfluid::ffi::*;
use projfluid::scene::Scene;
use std::ffi::{CStr, CString, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::ptr::{null, null_mut};

/// SplitMix64: small, seeded, the same sequence everywhere.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    fn chance(&mut self, percent: usize) -> bool {
        self.below(100) < percent
    }

    fn pick<T: Copy>(&mut self, items: &[T]) -> T {
        items[self.below(items.len())]
    }

    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// `default` scaled by `PROJFLUID_FUZZ_BUDGET` (a positive number, default 1).
fn budget(default: usize) -> usize {
    let scale: f64 = std::env::var("PROJFLUID_FUZZ_BUDGET")
        .ok()
        .and_then(|s| s.parse().ok())
        .filter(|s: &f64| s.is_finite() && *s > 0.0)
        .unwrap_or(1.0);
    ((default as f64 * scale).ceil() as usize).max(1)
}

/// Coordinates: mostly inside the 0.6 m container, sometimes absurd.
fn coordinate(rng: &mut Rng) -> f32 {
    if rng.chance(90) {
        0.05 + 0.5 * rng.unit() as f32
    } else {
        rng.pick(&[
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::MAX,
            -f32::MAX,
            1e30,
            -0.0,
            1e-40,
        ])
    }
}

/// A double argument: ordinary values and every kind of bad one.
fn double(rng: &mut Rng, ordinary: &[f64]) -> f64 {
    if rng.chance(70) {
        rng.pick(ordinary)
    } else {
        rng.pick(&[
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            -1.0,
            0.0,
            -0.0,
            1e-300,
            1e300,
            f64::MIN_POSITIVE,
        ])
    }
}

/// Counts: small ones and ones far above every limit (never huge-but-valid, which would
/// only allocate gigabytes).
fn count(rng: &mut Rng) -> usize {
    if rng.chance(85) {
        rng.below(6)
    } else {
        rng.pick(&[
            usize::MAX,
            usize::MAX / 3 + 1,
            1 << 40,
            u32::MAX as usize / 64 + 1,
        ])
    }
}

/// Everything observable about a world that a failed call must not change.
#[derive(Debug, PartialEq)]
struct Snapshot {
    fluid: usize,
    boundary: usize,
    time: u64,
    steps: u64,
    hash: String,
    velocities: Vec<u32>,
    densities: Vec<u32>,
    ids: Vec<u64>,
    removed: u64,
    emitted: u64,
    /// Every particle's material, the number of materials and the one fluid is added of.
    materials: Vec<u16>,
    material_count: usize,
    fluid_material: u16,
}

fn ok(status: PfStatus, what: &str) {
    assert_eq!(status, PfStatus::PF_OK, "{what}: {}", message());
}

fn message() -> String {
    // SAFETY: the library returns a valid NUL-terminated string.
    unsafe { CStr::from_ptr(pf_last_error_message()) }
        .to_string_lossy()
        .into_owned()
}

/// Reads a float array through one of the `pf_world_get_*` functions.
fn floats(
    world: *mut PfWorld,
    get: unsafe extern "C" fn(*const PfWorld, *mut f32, usize, *mut usize) -> PfStatus,
) -> Vec<f32> {
    let mut needed = 0usize;
    // SAFETY: a live world; a NULL buffer of capacity 0 and a valid `needed`.
    let status = unsafe { get(world, null_mut(), 0, &mut needed) };
    assert!(matches!(
        status,
        PfStatus::PF_OK | PfStatus::PF_ERROR_BUFFER_TOO_SMALL
    ));
    let mut out = vec![0f32; needed];
    // SAFETY: `out` holds `needed` floats.
    ok(
        unsafe { get(world, out.as_mut_ptr(), out.len(), &mut needed) },
        "read",
    );
    out
}

fn snapshot(world: *mut PfWorld) -> Snapshot {
    let (mut fluid, mut boundary, mut time) = (0usize, 0usize, 0f64);
    let (mut removed, mut emitted) = (0u64, 0u64);
    // SAFETY: all-zero bytes are a valid PfStepStats (integers, doubles and a bool).
    let mut stats: PfStepStats = unsafe { std::mem::zeroed() };
    let mut hash = [0 as c_char; 65];
    // SAFETY: a live world and valid outputs.
    unsafe {
        ok(pf_world_fluid_count(world, &mut fluid), "fluid_count");
        ok(
            pf_world_boundary_count(world, &mut boundary),
            "boundary_count",
        );
        ok(pf_world_time(world, &mut time), "time");
        ok(pf_world_last_step_stats(world, &mut stats), "stats");
        ok(pf_world_removed_count(world, &mut removed), "removed");
        ok(pf_world_emitted_count(world, &mut emitted), "emitted");
        ok(
            pf_world_positions_hash(world, hash.as_mut_ptr(), hash.len(), null_mut()),
            "hash",
        );
    }
    let mut ids = vec![0u64; fluid];
    let mut needed = 0;
    // SAFETY: `ids` holds `fluid` ids.
    ok(
        unsafe { pf_world_get_ids(world, ids.as_mut_ptr(), ids.len(), &mut needed) },
        "ids",
    );
    let mut materials = vec![u16::MAX; fluid];
    let (mut material_count, mut fluid_material) = (0usize, u16::MAX);
    // SAFETY: `materials` holds `fluid` ids; valid outputs.
    unsafe {
        ok(
            pf_world_get_materials(world, materials.as_mut_ptr(), fluid, &mut needed),
            "materials",
        );
        ok(
            pf_world_material_count(world, &mut material_count),
            "material_count",
        );
        ok(
            pf_world_fluid_material(world, &mut fluid_material),
            "fluid_material",
        );
    }
    // SAFETY: NUL-terminated by the library.
    let hash = unsafe { CStr::from_ptr(hash.as_ptr()) }
        .to_string_lossy()
        .into_owned();
    let bits = |v: Vec<f32>| v.into_iter().map(f32::to_bits).collect();
    Snapshot {
        fluid,
        boundary,
        time: time.to_bits(),
        steps: stats.step_count,
        hash,
        velocities: bits(floats(world, pf_world_get_velocities)),
        densities: bits(floats(world, pf_world_get_densities)),
        ids,
        removed,
        emitted,
        materials,
        material_count,
        fluid_material,
    }
}

/// What a call is expected to do to time and steps when it succeeds.
enum Moves {
    /// Nothing (reads, adds).
    Nothing,
    /// One step.
    OneStep,
    /// Time forward by about this many seconds, in zero or more steps.
    Span(f64),
}

/// The random world calls; returns the call's name and status, and what success means.
struct Fuzzer {
    rng: Rng,
    world: *mut PfWorld,
    /// Fluid particles added by successful add calls.
    added: u64,
    emitters: usize,
}

impl Fuzzer {
    fn xyz(&mut self, n: usize) -> Vec<f32> {
        (0..3 * n).map(|_| coordinate(&mut self.rng)).collect()
    }

    /// A small input array, or (sometimes) NULL with the count it claims.
    fn input(&mut self) -> (Vec<f32>, usize, bool) {
        let n = 1 + self.rng.below(4);
        let data = self.xyz(n);
        if self.rng.chance(10) {
            (data, count(&mut self.rng), true)
        } else if self.rng.chance(10) {
            // A count shorter than the array is fine; never a longer one (that is UB in C).
            (data, self.rng.below(n + 1), false)
        } else {
            (data, n, false)
        }
    }

    fn ptr(data: &[f32], is_null: bool) -> *const f32 {
        if is_null { null() } else { data.as_ptr() }
    }

    fn call(&mut self, fluid: usize, boundary: usize) -> (&'static str, PfStatus, Moves, u64) {
        let w = if self.rng.chance(2) {
            null_mut()
        } else {
            self.world
        };
        let crowded = fluid > 2500;
        let walled = boundary > 40_000;
        // SAFETY (every call below): `w` is NULL or the live world; every pointer is NULL or
        // points to at least as many elements as the count passed with it.
        unsafe {
            match self.rng.below(23) {
                0 | 1 if !crowded => {
                    let (xyz, n, is_null) = self.input();
                    let status = pf_world_add_fluid_particles(w, Self::ptr(&xyz, is_null), n);
                    ("add_fluid_particles", status, Moves::Nothing, n as u64)
                }
                2 if !crowded => {
                    let (xyz, n, is_null) = self.input();
                    let velocities = self.xyz(xyz.len() / 3);
                    let v = if self.rng.chance(20) {
                        null()
                    } else {
                        velocities.as_ptr()
                    };
                    let status = pf_world_add_fluid_particles_with_velocities(
                        w,
                        Self::ptr(&xyz, is_null),
                        v,
                        n,
                    );
                    (
                        "add_fluid_particles_with_velocities",
                        status,
                        Moves::Nothing,
                        n as u64,
                    )
                }
                3 if !crowded => {
                    let start = self.xyz(1);
                    let counts = [0; 3].map(|_| count(&mut self.rng));
                    let velocity = self.xyz(1);
                    let v = if self.rng.chance(50) {
                        null()
                    } else {
                        velocity.as_ptr()
                    };
                    let c = if self.rng.chance(5) {
                        null()
                    } else {
                        counts.as_ptr()
                    };
                    let status = pf_world_add_fluid_box(w, start.as_ptr(), c, v);
                    let n = counts.iter().fold(1u64, |a, &c| a.wrapping_mul(c as u64));
                    ("add_fluid_box", status, Moves::Nothing, n)
                }
                4 if !walled => {
                    let (xyz, n, is_null) = self.input();
                    let status = pf_world_add_boundary_particles(w, Self::ptr(&xyz, is_null), n);
                    ("add_boundary_particles", status, Moves::Nothing, 0)
                }
                5 if !walled => {
                    let corners = [-0.1, 0.0, 0.05, 0.3, 0.6, 1e30, f32::NAN, f32::INFINITY];
                    let lo = [0; 3].map(|_| self.rng.pick(&corners));
                    let hi = [0; 3].map(|_| self.rng.pick(&corners));
                    let layers = self.rng.below(5) as u32;
                    let status = pf_world_add_container_box(w, lo.as_ptr(), hi.as_ptr(), layers);
                    ("add_container_box", status, Moves::Nothing, 0)
                }
                6 if !walled => {
                    let corners = [0.0, 0.1, 0.3, 0.5, 1e30, f32::NAN, f32::INFINITY];
                    let v: Vec<f32> = (0..12).map(|_| self.rng.pick(&corners)).collect();
                    let idx: Vec<u32> = (0..6)
                        .map(|_| self.rng.pick(&[0, 1, 2, 3, 4, u32::MAX]))
                        .collect();
                    let (vn, tn) = (self.rng.below(5), self.rng.below(3));
                    let mut t = PfTransform {
                        scale: [1.0; 3],
                        rotate_deg: [0.0; 3],
                        translate: [0.0; 3],
                    };
                    t.scale[self.rng.below(3)] = double(&mut self.rng, &[0.5, 1.0, 2.0]);
                    t.rotate_deg[self.rng.below(3)] = double(&mut self.rng, &[0.0, 45.0, 360.0]);
                    let tp = if self.rng.chance(50) { null() } else { &t };
                    let status =
                        pf_world_add_mesh_transformed(w, v.as_ptr(), vn, idx.as_ptr(), tn, tp);
                    ("add_mesh_transformed", status, Moves::Nothing, 0)
                }
                7..=9 => {
                    let dt = double(&mut self.rng, &[0.0, -1.0, 1e-4, 2e-3, 5e-3, 2.0]);
                    let status = pf_world_step(w, dt);
                    ("step", status, Moves::OneStep, 0)
                }
                10 | 11 => {
                    let s = double(&mut self.rng, &[0.0, 1e-13, 1e-4, 3e-3, 6e-3]);
                    let status = pf_world_advance(w, s);
                    ("advance", status, Moves::Span(s), 0)
                }
                12 => {
                    let s = double(&mut self.rng, &[0.0, 1e-4, 5e-3]);
                    let damping = double(&mut self.rng, &[0.0, 1.0, 4.0, 1e3]);
                    let status = pf_world_relax(w, s, damping);
                    ("relax", status, Moves::Span(s), 0)
                }
                13 if self.emitters < 3 => {
                    let position = [0.3, 0.45, 0.3].map(|x| double(&mut self.rng, &[x]));
                    let mut direction = [0.0, -1.0, 0.0];
                    if self.rng.chance(30) {
                        direction[self.rng.below(3)] = double(&mut self.rng, &[0.0, 1.0]);
                    }
                    let speed = double(&mut self.rng, &[0.5, 2.0]);
                    let mut time = 0.0;
                    pf_world_time(self.world, &mut time);
                    let end = double(&mut self.rng, &[time + 0.02, 0.0]);
                    let mut id = 0usize;
                    let out = if self.rng.chance(5) {
                        null_mut()
                    } else {
                        &mut id
                    };
                    let status = if self.rng.chance(50) {
                        let radius = double(&mut self.rng, &[0.05, 0.1, 1e-6, 1e9]);
                        pf_world_add_emitter_disc(
                            w,
                            position.as_ptr(),
                            direction.as_ptr(),
                            radius,
                            speed,
                            end,
                            out,
                        )
                    } else {
                        let a = double(&mut self.rng, &[0.05, 0.1, 1e9]);
                        let b = double(&mut self.rng, &[0.05, 1e-6]);
                        pf_world_add_emitter_rect(
                            w,
                            position.as_ptr(),
                            direction.as_ptr(),
                            a,
                            b,
                            speed,
                            end,
                            out,
                        )
                    };
                    if status == PfStatus::PF_OK {
                        self.emitters += 1;
                    }
                    ("add_emitter", status, Moves::Nothing, 0)
                }
                14 => {
                    let lo = [0; 3].map(|_| double(&mut self.rng, &[-1.0, 0.0, 0.1, 0.5]));
                    let hi = [0; 3].map(|_| double(&mut self.rng, &[0.05, 0.2, 0.6, 2.0]));
                    let status = match self.rng.below(3) {
                        0 => {
                            let mut id = 0usize;
                            pf_world_add_sink(w, lo.as_ptr(), hi.as_ptr(), &mut id)
                        }
                        1 => pf_world_set_domain(w, lo.as_ptr(), hi.as_ptr()),
                        _ => pf_world_clear_domain(w),
                    };
                    ("sink_or_domain", status, Moves::Nothing, 0)
                }
                15 => {
                    let mut ids = vec![0u64; fluid];
                    let mut needed = 0;
                    pf_world_get_ids(self.world, ids.as_mut_ptr(), ids.len(), &mut needed);
                    let n = self.rng.below(4);
                    let chosen: Vec<u64> = (0..n)
                        .map(|_| {
                            if !ids.is_empty() && self.rng.chance(80) {
                                ids[self.rng.below(ids.len())]
                            } else {
                                self.rng.pick(&[u64::MAX, 1 << 40, 0])
                            }
                        })
                        .collect();
                    let mut removed = 0usize;
                    let p = if n == 0 && self.rng.chance(50) {
                        null()
                    } else {
                        chosen.as_ptr()
                    };
                    let status = pf_world_remove_particles(w, p, n, &mut removed);
                    if status == PfStatus::PF_OK {
                        assert_eq!(removed, n);
                    }
                    ("remove_particles", status, Moves::Nothing, 0)
                }
                16..=18 => {
                    // Reads with random, often short, capacities and NULL outputs.
                    let needed_floats = 3 * fluid;
                    let valid = |x: f32| !x.is_nan();
                    let (name, status) = per_particle_read(
                        &mut self.rng,
                        needed_floats,
                        -7.0f32,
                        valid,
                        |rng, out, capacity, n| match rng.below(3) {
                            0 => (
                                "get_positions",
                                pf_world_get_positions(w, out, capacity, n),
                                needed_floats,
                            ),
                            1 => (
                                "get_velocities",
                                pf_world_get_velocities(w, out, capacity, n),
                                needed_floats,
                            ),
                            _ => (
                                "get_densities",
                                pf_world_get_densities(w, out, capacity, n),
                                fluid,
                            ),
                        },
                    );
                    (name, status, Moves::Nothing, 0)
                }
                19 => {
                    let capacity = self.rng.below(70);
                    let mut buf = vec![b'#' as c_char; capacity];
                    let out = if capacity == 0 {
                        null_mut()
                    } else {
                        buf.as_mut_ptr()
                    };
                    let status = pf_world_positions_hash(w, out, capacity, null_mut());
                    if status == PfStatus::PF_OK {
                        assert!(capacity >= 65);
                    }
                    ("positions_hash", status, Moves::Nothing, 0)
                }
                20 => {
                    let path = CString::new("/nonexistent/projfluid-fuzz.obj").unwrap();
                    let p = if self.rng.chance(50) {
                        null()
                    } else {
                        path.as_ptr()
                    };
                    let status = pf_world_add_obj(w, p, null());
                    ("add_obj", status, Moves::Nothing, 0)
                }
                21 => {
                    // A world from damaged parameters: created and destroyed, or refused
                    // with *out set to NULL.
                    let mut params = std::mem::MaybeUninit::<PfParams>::uninit();
                    ok(pf_params_default(params.as_mut_ptr()), "params_default");
                    let mut p = params.assume_init();
                    p.threads = 1;
                    match self.rng.below(9) {
                        0 => p.dt_max = double(&mut self.rng, &[1e-3, 1.0, 1.5]),
                        1 => p.dt_initial = double(&mut self.rng, &[1e-3, 1.0, 2.0]),
                        2 => p.dt_min = double(&mut self.rng, &[1e-5, 1e-2]),
                        3 => p.particle_radius = double(&mut self.rng, &[0.01, 0.1]),
                        4 => p.chebyshev_rho = double(&mut self.rng, &[0.5, 0.99, 1.0]),
                        5 => p.kinematic_viscosity = double(&mut self.rng, &[0.0, 1e-6, 1e-2]),
                        6 => p.no_slip = self.rng.below(3) as u32,
                        7 => p.backend = self.rng.below(3) as u32,
                        _ => p.viscosity = double(&mut self.rng, &[0.0, 0.5, 2.0]),
                    }
                    let mut other = self.world;
                    let status = pf_world_create(&p, &mut other);
                    if status == PfStatus::PF_OK {
                        pf_world_destroy(other);
                    } else {
                        assert!(other.is_null());
                    }
                    ("world_create", status, Moves::Nothing, 0)
                }
                22 => {
                    // Materials: add one (ordinary and bad densities), choose one (known or
                    // not), set a viscosity or a surface tension (ordinary or bad), or read
                    // them back, per material and per particle (short buffers).
                    let range = self.rng.pick(&[1usize, 2, 3, 8, 300]);
                    let material = self.rng.below(range) as u16;
                    match self.rng.below(6) {
                        0 => {
                            let rho = double(&mut self.rng, &[800.0, 1000.0, 1500.0, 3000.0]);
                            let mut id = u16::MAX;
                            let out = if self.rng.chance(5) {
                                null_mut()
                            } else {
                                &mut id
                            };
                            let status = pf_world_add_material(w, rho, out);
                            if status == PfStatus::PF_OK {
                                assert!((1..u16::MAX).contains(&id), "add_material: id {id}");
                            } else {
                                assert_eq!(id, u16::MAX, "add_material wrote on failure");
                            }
                            ("add_material", status, Moves::Nothing, 0)
                        }
                        1 => {
                            let status = pf_world_set_fluid_material(w, material);
                            ("set_fluid_material", status, Moves::Nothing, 0)
                        }
                        2 => {
                            let mut rho = -7.0;
                            let out = if self.rng.chance(10) {
                                null_mut()
                            } else {
                                &mut rho
                            };
                            let status = pf_world_get_material_rest_density(w, material, out);
                            match status {
                                PfStatus::PF_OK => assert!(rho.is_finite() && rho > 0.0),
                                _ => assert_eq!(rho, -7.0, "get_material_rest_density wrote"),
                            }
                            ("get_material_rest_density", status, Moves::Nothing, 0)
                        }
                        3 => {
                            let nu = double(&mut self.rng, &[0.0, 1e-4, 1e-2]);
                            let status = pf_world_set_material_kinematic_viscosity(w, material, nu);
                            // Read back only after a success: a read would replace the
                            // message of a failure, which the harness checks.
                            if status == PfStatus::PF_OK {
                                let mut read = -7.0;
                                let back = pf_world_get_material_kinematic_viscosity(
                                    w, material, &mut read,
                                );
                                assert_eq!(back, PfStatus::PF_OK);
                                assert_eq!(read, nu, "viscosity read back");
                            }
                            (
                                "set_material_kinematic_viscosity",
                                status,
                                Moves::Nothing,
                                0,
                            )
                        }
                        4 => {
                            let sigma = double(&mut self.rng, &[0.0, 0.01, 0.0728]);
                            let status = pf_world_set_material_surface_tension(w, material, sigma);
                            // Read back only after a success: a read would replace the
                            // message of a failure, which the harness checks.
                            if status == PfStatus::PF_OK {
                                let mut read = -7.0;
                                let back =
                                    pf_world_get_material_surface_tension(w, material, &mut read);
                                assert_eq!(back, PfStatus::PF_OK);
                                assert_eq!(read, sigma, "surface tension read back");
                            }
                            ("set_material_surface_tension", status, Moves::Nothing, 0)
                        }
                        _ => {
                            let valid = |m: u16| m < 0xabcd;
                            let (name, status) = per_particle_read(
                                &mut self.rng,
                                fluid,
                                0xabcd_u16,
                                valid,
                                |_, out, capacity, n| {
                                    let status = pf_world_get_materials(w, out, capacity, n);
                                    ("get_materials", status, fluid)
                                },
                            );
                            (name, status, Moves::Nothing, 0)
                        }
                    }
                }
                _ => ("skipped", PfStatus::PF_OK, Moves::Nothing, 0),
            }
        }
    }
}

/// One of the per-particle reads with a random capacity below `room + 4` (often short),
/// sometimes NULL outputs, and every slot of its buffer filled with `fill`: `read(rng, out,
/// capacity, needed)` makes the call and returns its name, its status and how many values it
/// owes. A success writes exactly those, each `valid`, and nothing past them; a short buffer
/// writes nothing and reports the count where asked. Returns the name and the status.
fn per_particle_read<T: Copy + PartialEq + std::fmt::Debug>(
    rng: &mut Rng,
    room: usize,
    fill: T,
    valid: impl Fn(T) -> bool,
    read: impl FnOnce(&mut Rng, *mut T, usize, *mut usize) -> (&'static str, PfStatus, usize),
) -> (&'static str, PfStatus) {
    let capacity = rng.below(room + 4);
    let mut buf = vec![fill; capacity];
    let mut needed = usize::MAX;
    let out = if capacity == 0 && rng.chance(50) {
        null_mut()
    } else {
        buf.as_mut_ptr()
    };
    let n = if rng.chance(20) {
        null_mut()
    } else {
        &mut needed
    };
    let (name, status, wanted) = read(rng, out, capacity, n);
    match status {
        PfStatus::PF_OK => {
            assert!(capacity >= wanted, "{name}");
            assert!(buf[wanted..].iter().all(|&x| x == fill), "{name}");
            assert!(buf[..wanted].iter().all(|&x| valid(x)), "{name}: {buf:?}");
        }
        PfStatus::PF_ERROR_BUFFER_TOO_SMALL => {
            assert!(capacity < wanted, "{name}");
            assert!(buf.iter().all(|&x| x == fill), "{name} wrote");
            if !n.is_null() {
                assert_eq!(needed, wanted, "{name}");
            }
        }
        _ => {}
    }
    (name, status)
}

/// One seeded run of `calls` random calls against a small world.
fn fuzz_world(seed: u64, calls: usize) {
    let mut params = std::mem::MaybeUninit::<PfParams>::uninit();
    let mut world = null_mut();
    // SAFETY: valid outputs; the world is destroyed at the end.
    unsafe {
        ok(pf_params_default(params.as_mut_ptr()), "params_default");
        let mut params = params.assume_init();
        params.threads = 1;
        // Behaviour, not convergence, is under test: cap the cost of a step.
        params.max_outer_iterations = 20;
        ok(pf_world_create(&params, &mut world), "world_create");
        let (lo, hi) = ([0.0f32; 3], [0.6f32; 3]);
        ok(
            pf_world_add_container_box(world, lo.as_ptr(), hi.as_ptr(), 1),
            "container",
        );
        let counts = [5usize, 5, 5];
        let start = [0.1f32; 3];
        ok(
            pf_world_add_fluid_box(world, start.as_ptr(), counts.as_ptr(), null()),
            "fluid_box",
        );
    }
    let mut fuzzer = Fuzzer {
        rng: Rng(seed),
        world,
        added: 125,
        emitters: 0,
    };
    let trace = std::env::var_os("PROJFLUID_FUZZ_TRACE").is_some();
    let mut before = snapshot(world);
    for call in 0..calls {
        let started = std::time::Instant::now();
        let (name, status, moves, n) = fuzzer.call(before.fluid, before.boundary);
        let text = message();
        if trace {
            eprintln!(
                "seed {seed}, call {call}: {name} -> {status:?} in {:.3} s, fluid {}, boundary {}",
                started.elapsed().as_secs_f64(),
                before.fluid,
                before.boundary
            );
        }
        let after = snapshot(world);
        let context = format!("seed {seed}, call {call}: pf_world_{name} -> {status:?} ({text})");
        assert!(
            !matches!(
                status,
                PfStatus::PF_ERROR_PANIC | PfStatus::PF_ERROR_WORLD_POISONED
            ),
            "{context}"
        );
        if status == PfStatus::PF_OK {
            if name != "skipped" {
                assert_eq!(text, "", "{context}: success left a message");
            }
            if name.starts_with("add_fluid") {
                // Particles whose centres lie inside a solid are not created.
                let mut made = 0usize;
                // SAFETY: a live world and a valid output.
                unsafe {
                    ok(
                        pf_world_last_added_count(world, &mut made),
                        "last_added_count",
                    )
                };
                assert!(made as u64 <= n, "{context}: made {made} of {n}");
                fuzzer.added += made as u64;
            }
            let (t0, t1) = (f64::from_bits(before.time), f64::from_bits(after.time));
            match moves {
                Moves::Nothing => {
                    assert_eq!((after.time, after.steps), (before.time, before.steps));
                    assert_eq!(after.emitted, before.emitted, "{context}");
                }
                Moves::OneStep => {
                    assert_eq!(after.steps, before.steps + 1, "{context}");
                    assert!(t1 > t0, "{context}: time did not move");
                }
                Moves::Span(s) => {
                    assert!(t1 >= t0, "{context}");
                    assert!(
                        (t1 - (t0 + s)).abs() <= 1e-9,
                        "{context}: {t0} + {s} → {t1}"
                    );
                    assert_eq!(s > 0.0, after.steps > before.steps, "{context}");
                }
            }
        } else {
            assert!(
                text.starts_with("pf_") && text.len() > 12,
                "{context}: no helpful message"
            );
            assert!(
                after == before,
                "{context}: a failed call changed the world"
            );
        }
        assert_eq!(
            after.fluid as u64 + after.removed,
            fuzzer.added + after.emitted,
            "{context}: counts do not add up"
        );
        assert!(after.removed >= before.removed && after.emitted >= before.emitted);
        assert_eq!(after.ids.len(), after.fluid, "{context}");
        assert!(
            after
                .materials
                .iter()
                .all(|&m| (m as usize) < after.material_count)
                && (after.fluid_material as usize) < after.material_count,
            "{context}: materials"
        );
        assert!(
            after.material_count >= before.material_count,
            "{context}: a material was lost"
        );
        assert!(after.ids.windows(2).all(|p| p[0] < p[1]), "{context}: ids");
        for (what, values) in [
            ("velocities", &after.velocities),
            ("densities", &after.densities),
        ] {
            assert!(
                values.iter().all(|&b| !f32::from_bits(b).is_nan()),
                "{context}: NaN {what}"
            );
        }
        assert!(
            floats(world, pf_world_get_positions)
                .iter()
                .all(|x| !x.is_nan()),
            "{context}: NaN positions"
        );
        before = after;
    }
    // SAFETY: destroyed once.
    unsafe { pf_world_destroy(world) };
}

#[test]
fn random_c_api_calls_fail_cleanly_or_keep_the_world_consistent() {
    let calls = budget(150);
    for seed in 0..3u64 {
        fuzz_world(0x5eed_0000 + seed, calls);
    }
}

/// Damages `text` in one of several ways: a byte flipped, a span deleted or repeated, a
/// number replaced by an extreme one, random bytes inserted.
fn mutate(rng: &mut Rng, text: &[u8]) -> Vec<u8> {
    let mut out = text.to_vec();
    for _ in 0..1 + rng.below(3) {
        if out.is_empty() {
            out.push(b'{');
        }
        let at = rng.below(out.len());
        match rng.below(6) {
            0 => out[at] ^= 1 << rng.below(8),
            1 => {
                let end = (at + 1 + rng.below(40)).min(out.len());
                out.drain(at..end);
            }
            2 => {
                let end = (at + 1 + rng.below(40)).min(out.len());
                let piece = out[at..end].to_vec();
                out.splice(at..at, piece);
            }
            3 | 4 => {
                // Replace the number (or value) starting at the next digit.
                let Some(start) = out[at..].iter().position(|b| b.is_ascii_digit()) else {
                    continue;
                };
                let start = at + start;
                let len = out[start..]
                    .iter()
                    .position(|b| !(b.is_ascii_digit() || b"+-.eE".contains(b)))
                    .unwrap_or(out.len() - start);
                let value = rng.pick(&[
                    "0",
                    "-0",
                    "-1",
                    "1e308",
                    "-1e308",
                    "1e400",
                    "1e-320",
                    "18446744073709551616",
                    "4294967295",
                    "9007199254740993",
                    "1e9",
                    "0.5",
                    "null",
                    "\"x\"",
                    "[]",
                    "{}",
                    "true",
                    "[1e9, 1e9, 1e9]",
                ]);
                out.splice(start..start + len, value.bytes());
            }
            _ => {
                let bytes: Vec<u8> = (0..1 + rng.below(8)).map(|_| rng.next() as u8).collect();
                out.splice(at..at, bytes);
            }
        }
    }
    out
}

/// Parses `bytes` as a scene; a panic fails the test with the input.
fn parse_without_panic(bytes: &[u8]) {
    let text = String::from_utf8_lossy(bytes);
    let parsed = catch_unwind(AssertUnwindSafe(|| Scene::from_json(&text)));
    let Ok(result) = parsed else {
        panic!("Scene::from_json panicked on:\n{text}");
    };
    if let Ok(scene) = result {
        let json = scene.to_json();
        let back = catch_unwind(AssertUnwindSafe(|| Scene::from_json(&json)));
        match back {
            Ok(Ok(_)) => {}
            Ok(Err(e)) => panic!("a scene read from\n{text}\nwrote\n{json}\nwhich fails: {e}"),
            Err(_) => panic!("Scene::from_json panicked on its own output:\n{json}"),
        }
    }
}

#[test]
fn the_scene_reader_answers_damaged_and_random_input_without_panicking() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut seeds: Vec<Vec<u8>> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .map(|p| std::fs::read(p).unwrap())
        .collect();
    seeds.sort();
    assert!(seeds.len() >= 5, "the built-in scene files are the seeds");
    let mut rng = Rng(0x5ce7e);
    for _ in 0..budget(20_000) {
        let seed = &seeds[rng.below(seeds.len())];
        parse_without_panic(&mutate(&mut rng, seed));
    }
    for _ in 0..budget(5_000) {
        let len = rng.below(200);
        let bytes: Vec<u8> = (0..len).map(|_| rng.next() as u8).collect();
        parse_without_panic(&bytes);
    }
}
