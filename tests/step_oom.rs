//! A step that cannot have the memory for what only it can size — the neighbour lists of
//! particles crowded together, far beyond the room reserved before the step, or the
//! corrections their projections keep — returns `Error::OutOfMemory` and leaves the world
//! exactly as it was: its exported state, its boundary with the moving body's particles, its
//! emitters and the last step's displacements, bit for bit. With the memory back it steps on
//! bit for bit as a world that never failed.
//!
//! This test program's allocator refuses, while a limit is set, every allocation larger than
//! the limit. Crowded particles need lists far longer than anything else these small worlds
//! allocate, so the refusal falls where the step grows them.

use projfluid::body::{BodyKind, BodySpec, Pose, Rotation, Shape, Velocity};
use projfluid::boundary::Aabb;
use projfluid::{EmitterShape, EmitterSpec, Error, Params, Vec3, World, WorldState};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The largest allocation (bytes) the allocator grants; `usize::MAX` while no limit is set.
static GRANTED: AtomicUsize = AtomicUsize::new(usize::MAX);

/// The system allocator, refusing allocations above [`GRANTED`] as an exhausted one would.
struct Limited;

// SAFETY: every call is passed on to the system allocator unchanged, or refused with a null
// pointer, which the `GlobalAlloc` contract allows.
unsafe impl GlobalAlloc for Limited {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if layout.size() > GRANTED.load(Ordering::SeqCst) {
            return std::ptr::null_mut();
        }
        // SAFETY: the caller's guarantees for `layout` are the system allocator's.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if layout.size() > GRANTED.load(Ordering::SeqCst) {
            return std::ptr::null_mut();
        }
        // SAFETY: as `alloc`.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from the system allocator with `layout`.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size > GRANTED.load(Ordering::SeqCst) {
            return std::ptr::null_mut();
        }
        // SAFETY: `ptr` came from the system allocator with `layout`.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Limited = Limited;

/// Holds the program to one test at a time: the limit applies to all its threads.
fn serial() -> std::sync::MutexGuard<'static, ()> {
    static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());
    ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner())
}

/// Runs `f` with allocations above `bytes` refused.
fn with_limit<R>(bytes: usize, f: impl FnOnce() -> R) -> R {
    /// Lifts the limit again, also if `f` panics.
    struct Lift;
    impl Drop for Lift {
        fn drop(&mut self) {
            GRANTED.store(usize::MAX, Ordering::SeqCst);
        }
    }
    let _lift = Lift;
    GRANTED.store(bytes, Ordering::SeqCst);
    f()
}

/// Particles in the crowd: a block of their lists (256 queries) needs 256·1500·4 bytes,
/// 1.5 MB, where the reservation before the step gave it 54 kB; the lists grow by doubling.
const CROWD: usize = 1500;

/// The largest allocation granted while a step is refused (bytes): less than the crowd's
/// lists grow to (1.7 MB), more than anything else these worlds allocate at once (the
/// largest: the 1.2 MB that a first step checks it could have for sorting the walls'
/// 9602 particles).
const LIMIT: usize = 3 << 19;

/// A closed 1 m box with a block of water, a kinematic box moving through the air and, if
/// `crowded`, the crowd: [`CROWD`] particles at rest within 2 cm of each other, each the
/// neighbour of every other. Default parameters (r = 2.5 cm), on `threads` threads.
fn world(threads: usize, crowded: bool) -> World {
    let mut world = World::new(Params {
        threads,
        ..Params::default()
    })
    .unwrap();
    let room = Aabb {
        min: Vec3::zeros(),
        max: Vec3::repeat(1.0),
    };
    world.add_container(room, 1).unwrap();
    world
        .add_fluid_block(Vec3::repeat(0.1), [6, 6, 6], Vec3::zeros())
        .unwrap();
    let mesh = Shape::Box {
        half_extents: Vec3::repeat(0.05),
    }
    .mesh(0.025)
    .unwrap();
    let body = BodySpec {
        kind: BodyKind::Kinematic,
        mesh,
        mass: None,
        pose: Pose {
            position: Vec3::new(0.75, 0.6, 0.5),
            rotation: Rotation::identity(),
        },
        velocity: Velocity {
            linear: Vec3::new(0.0, 0.0, -0.5),
            angular: Vec3::new(0.0, 1.0, 0.0),
        },
        motion: None,
    };
    world.add_body(body).unwrap();
    if crowded {
        crowd(&mut world);
    }
    world
}

/// Adds the crowd (see [`world`]) around (0.5, 0.5, 0.3) m.
fn crowd(world: &mut World) {
    let mut rng = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng >> 11) as f64 / (1u64 << 53) as f64
    };
    let crowd: Vec<Vec3> = (0..CROWD)
        .map(|_| Vec3::new(0.5, 0.5, 0.3) + Vec3::new(next(), next(), next()) * 0.02)
        .collect();
    world.add_fluid_particles(&crowd, None).unwrap();
}

/// Adds an emitter pouring down from (0.3, 0.8, 0.7) m; it inserts its first layer at the
/// start of the next step.
fn pour(world: &mut World) {
    let spec = EmitterSpec {
        shape: EmitterShape::Disc { radius: 0.06 },
        position: Vec3::new(0.3, 0.8, 0.7),
        direction: Vec3::new(0.0, -1.0, 0.0),
        speed: 0.5,
        end_time: None,
    };
    world.add_emitter(spec).unwrap();
}

/// Everything a rejected step must leave as it was, bit for bit.
#[derive(Debug, PartialEq)]
struct Fingerprint {
    state: WorldState,
    hash: String,
    boundary: Vec<Vec3>,
    displacements: Vec<f64>,
    emitted: u64,
}

fn fingerprint(world: &World) -> Fingerprint {
    Fingerprint {
        state: world.export_state(),
        hash: world.positions_hash(),
        boundary: world.boundary_positions().to_vec(),
        displacements: world.last_displacements().to_vec(),
        emitted: world.emitted_count(),
    }
}

/// Takes a step with allocations above `limit` bytes refused, which must fail for want of
/// memory during the step (not in the reservations before it) and change nothing.
fn refused_step(world: &mut World, limit: usize) {
    let before = fingerprint(world);
    // Checked once the limit is lifted: a failed check's message needs memory.
    let stepped = with_limit(limit, || world.step().map(|_| ()));
    let error = stepped.expect_err("the step needed no more memory than the limit");
    assert!(matches!(error, Error::OutOfMemory(_)), "{error}");
    assert!(error.to_string().contains("of a time step"), "{error}");
    let after = fingerprint(world);
    assert!(after == before, "the failed step changed the world");
}

/// The first step of a crowded world, which builds the grid, sorts the boundary, places the
/// moving body and inserts the emitter's first layer before its lists outgrow their
/// reservation, fails changing nothing; with the memory back it steps bit for bit as a
/// world that never failed, and so does its next step.
#[test]
fn a_first_step_whose_neighbour_lists_cannot_grow_changes_nothing() {
    let _serial = serial();
    let mut world = world(2, true);
    pour(&mut world);
    refused_step(&mut world, LIMIT);
    let mut twin = world_like_before(2);
    for _ in 0..2 {
        world.step().unwrap();
        twin.step().unwrap();
        assert!(fingerprint(&world) == fingerprint(&twin));
    }
    assert!(
        world.fluid_count() > 216 + CROWD,
        "the emitter inserted no layer"
    );
}

/// The world of [`a_first_step_whose_neighbour_lists_cannot_grow_changes_nothing`] as it
/// was built.
fn world_like_before(threads: usize) -> World {
    let mut world = world(threads, true);
    pour(&mut world);
    world
}

/// A later step (grid built, boundary sorted, body placed, displacements recorded) after the
/// crowd and an emitter were added fails changing nothing; with the memory back it steps
/// on bit for bit as a world that never failed.
#[test]
fn a_later_step_whose_neighbour_lists_cannot_grow_changes_nothing() {
    let _serial = serial();
    let build = || {
        let mut world = world(2, false);
        world.step().unwrap();
        world.step().unwrap();
        crowd(&mut world);
        pour(&mut world);
        world
    };
    let mut world = build();
    assert!(!world.last_displacements().is_empty());
    refused_step(&mut world, LIMIT);
    let mut twin = build();
    world.step().unwrap();
    twin.step().unwrap();
    assert!(fingerprint(&world) == fingerprint(&twin));
}

/// Lists that grow during a step hold the same neighbours on any number of threads: the
/// crowded world steps bit for bit alike on one and on three.
#[test]
fn grown_lists_give_the_same_step_on_one_and_three_threads() {
    let _serial = serial();
    let (mut one, mut three) = (world_like_before(1), world_like_before(3));
    one.step().unwrap();
    three.step().unwrap();
    assert!(fingerprint(&one) == fingerprint(&three));
}
