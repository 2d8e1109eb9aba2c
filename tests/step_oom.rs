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
//!
//! It also refuses, on request, one allocation at a given count on a world's own threads:
//! refusing each allocation of a step in turn, in worlds with bodies (their coupling to the
//! fluid, docs/method.md §11.3) and the LDLᵀ solver (its factorisation), every one must make
//! the step fail with `Error::OutOfMemory`, changing nothing; none may abort the process.

use projfluid::body::{BodyKind, BodyMass, BodySpec, Pose, Rotation, Shape, Velocity};
use projfluid::boundary::Aabb;
use projfluid::{EmitterShape, EmitterSpec, Error, Params, SolverKind, Vec3, World, WorldState};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// The largest allocation (bytes) the allocator grants; `usize::MAX` while no limit is set.
static GRANTED: AtomicUsize = AtomicUsize::new(usize::MAX);

/// How many more allocations larger than [`BOOKKEEPING`] on [`MARKED`] threads the
/// allocator grants before it refuses one; `usize::MAX` while none is to be refused.
static COUNTDOWN: AtomicUsize = AtomicUsize::new(usize::MAX);

/// Allocations of at most this many bytes are not counted down. Among them is the one
/// allocation of a step that cannot fail gracefully: rayon's record of a broadcast to the
/// pool's threads (a few dozen bytes per thread), when the step widens every thread's scratch
/// for larger stencils than any before. Everything the step sizes by particles, slots or
/// factors is larger in these worlds.
const BOOKKEEPING: usize = 512;

/// Set when the allocator refused the allocation [`COUNTDOWN`] counted down to.
static REFUSED: AtomicBool = AtomicBool::new(false);

thread_local! {
    /// Whether this thread's allocations count down [`COUNTDOWN`]: the threads of the worlds
    /// built by [`bodies_world`], where their steps do their work.
    static MARKED: Cell<bool> = const { Cell::new(false) };
}

/// Whether an allocation of `size` bytes is to be refused.
fn refuse(size: usize) -> bool {
    if size > GRANTED.load(Ordering::SeqCst) {
        return true;
    }
    if !MARKED.with(Cell::get) || size <= BOOKKEEPING {
        return false;
    }
    let counted = COUNTDOWN.fetch_update(Ordering::SeqCst, Ordering::SeqCst, |left| match left {
        usize::MAX => None,
        0 => Some(usize::MAX),
        left => Some(left - 1),
    });
    let refused = counted == Ok(0);
    if refused {
        REFUSED.store(true, Ordering::SeqCst);
    }
    refused
}

/// The system allocator, refusing allocations above [`GRANTED`], and the one [`COUNTDOWN`]
/// counts down to, as an exhausted one would.
struct Limited;

// SAFETY: every call is passed on to the system allocator unchanged, or refused with a null
// pointer, which the `GlobalAlloc` contract allows.
unsafe impl GlobalAlloc for Limited {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if refuse(layout.size()) {
            return std::ptr::null_mut();
        }
        // SAFETY: the caller's guarantees for `layout` are the system allocator's.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if refuse(layout.size()) {
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
        if refuse(new_size) {
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

/// A 0.6 m box holding a block of water 0.4 m × 0.25 m × 0.4 m, a dynamic cube falling into
/// it, a kinematic paddle pushed into it and an inlet in a wall pouring in, stepped by the LDLᵀ solver on a pool of
/// `threads` threads whose allocations [`COUNTDOWN`] counts.
fn bodies_world(threads: usize) -> World {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .start_handler(|_| MARKED.with(|marked| marked.set(true)))
        .build()
        .unwrap();
    let params = Params {
        threads,
        solver: SolverKind::Ldlt,
        ..Params::default()
    };
    let mut world = World::with_pool(params, pool).unwrap();
    let room = Aabb {
        min: Vec3::zeros(),
        max: Vec3::repeat(0.6),
    };
    world.add_container(room, 1).unwrap();
    world
        .add_fluid_block(Vec3::repeat(0.1), [8, 5, 8], Vec3::zeros())
        .unwrap();
    let body = |kind, half_extents, mass, position, linear| BodySpec {
        kind,
        mesh: Shape::Box { half_extents }.mesh(0.025).unwrap(),
        mass,
        pose: Pose {
            position,
            rotation: Rotation::identity(),
        },
        velocity: Velocity {
            linear,
            angular: Vec3::zeros(),
        },
        motion: None,
    };
    let cube = body(
        BodyKind::Dynamic,
        Vec3::repeat(0.06),
        Some(BodyMass::Density(500.0)),
        Vec3::new(0.35, 0.39, 0.3),
        Vec3::zeros(),
    );
    world.add_body(cube).unwrap();
    let paddle = body(
        BodyKind::Kinematic,
        Vec3::new(0.02, 0.15, 0.1),
        None,
        Vec3::new(0.05, 0.2, 0.3),
        Vec3::new(0.3, 0.0, 0.0),
    );
    world.add_body(paddle).unwrap();
    // An inlet in the wall above the water, whose layers are settled against the wall.
    let inlet = EmitterSpec {
        shape: EmitterShape::Rectangle {
            half_extents: [0.05, 0.05],
        },
        position: Vec3::new(0.6, 0.45, 0.3),
        direction: Vec3::new(-1.0, 0.0, 0.0),
        speed: 0.5,
        end_time: None,
    };
    world.add_emitter(inlet).unwrap();
    world
}

/// Takes the next step once for every allocation it makes on the world's threads, refusing
/// that allocation: each such step must fail with `Error::OutOfMemory` and change nothing.
/// The last one, in which nothing was refused, takes the step. Returns the number of
/// allocations refused.
fn refuse_each_allocation(world: &mut World) -> usize {
    /// Stops counting down, also if the step panics.
    struct Disarm;
    impl Drop for Disarm {
        fn drop(&mut self) {
            COUNTDOWN.store(usize::MAX, Ordering::SeqCst);
        }
    }
    let before = fingerprint(world);
    for granted in 0..100_000 {
        REFUSED.store(false, Ordering::SeqCst);
        let stepped = {
            let _disarm = Disarm;
            COUNTDOWN.store(granted, Ordering::SeqCst);
            world.step().map(|_| ())
        };
        if !REFUSED.load(Ordering::SeqCst) {
            stepped.unwrap();
            return granted;
        }
        let error = stepped.expect_err("a step succeeded without an allocation it made");
        assert!(matches!(error, Error::OutOfMemory(_)), "{error}");
        assert!(error.to_string().contains("of a time step"), "{error}");
        let after = fingerprint(world);
        assert!(
            after == before,
            "refusing allocation {granted} changed the world"
        );
    }
    panic!("the step made more than 100000 allocations");
}

/// The first step of a world with bodies and the LDLᵀ solver — its grid, the boundary's sort,
/// the bodies' placement, the coupling's slots, the factorisation — fails with
/// `OutOfMemory` and changes nothing wherever an allocation is refused; then it steps bit for
/// bit as a world that never failed, and so does its next step.
#[test]
fn every_allocation_of_a_first_step_with_bodies_and_ldlt_can_fail() {
    let _serial = serial();
    let mut world = bodies_world(1);
    assert!(refuse_each_allocation(&mut world) > 0);
    let mut twin = bodies_world(1);
    twin.step().unwrap();
    assert!(fingerprint(&world) == fingerprint(&twin));
    world.step().unwrap();
    twin.step().unwrap();
    assert!(fingerprint(&world) == fingerprint(&twin));
}

/// A later step on three threads, after more water was placed at the paddle (the coupling
/// needs more slots), fails with `OutOfMemory` and changes nothing wherever an
/// allocation is refused; then it steps on bit for bit as a world that never failed.
#[test]
fn every_allocation_of_a_later_step_with_bodies_and_ldlt_can_fail() {
    let _serial = serial();
    let build = || {
        let mut world = bodies_world(3);
        world.step().unwrap();
        world.step().unwrap();
        world
            .add_fluid_block(Vec3::new(0.1, 0.36, 0.1), [3, 2, 8], Vec3::zeros())
            .unwrap();
        world
    };
    let mut world = build();
    let bodies_before = world.export_state().bodies;
    assert!(refuse_each_allocation(&mut world) > 0);
    assert!(
        world.export_state().bodies != bodies_before,
        "the bodies did not move"
    );
    let mut twin = build();
    twin.step().unwrap();
    assert!(fingerprint(&world) == fingerprint(&twin));
    world.step().unwrap();
    twin.step().unwrap();
    assert!(fingerprint(&world) == fingerprint(&twin));
}
