//! Probes in a settled tank, their determinism, and the checks of probe definitions.

use super::*;
use crate::boundary::ContainerWalls;
use crate::scene::Scene;
use crate::{Params, Vec3};
use std::sync::OnceLock;

/// Gravity (m/s²) and rest density (kg/m³) of the tank.
const G: f64 = 9.81;
const RHO0: f64 = 1000.0;

/// Both kinds of container walls, each of which the settled tank is built with.
const WALLS: [ContainerWalls; 2] = [ContainerWalls::Particles, ContainerWalls::Field];

/// What the settled tank showed.
struct Settled {
    /// Lattice spacing d (m).
    spacing: f64,
    /// N·V/area + d/2 (m): the height of the water's top face above the floor plane if the
    /// water were at rest density (its bottom face is d/2 above the plane).
    volume_surface: f64,
    /// The mean height of the particles within d/2 of the highest one, plus d/2 (m): the top
    /// face of the water as the particles show it, independently of the probes.
    particle_surface: f64,
    /// The probes read.
    probes: ProbeSet,
    /// Their reading at the end, after the tight-τ reading window.
    reading: ProbeReading,
    /// Pressure probes at random points of the fluid region the named probes sample (at
    /// least H from the floor and the side walls, at least 2H below the surface), and their
    /// reading in the same window.
    random: (Vec<PressureProbe>, Vec<f64>),
    /// The gauges' reading with spray particles added above the water.
    with_spray: Vec<f64>,
    /// N·V/area (m): the depth the water would have at rest density, spread evenly.
    volume_depth: f64,
    /// Water-content gauges on the same lines: their gauges, and their readings before and
    /// after the spray was added.
    content: (Vec<Gauge>, Vec<f64>, Vec<f64>),
    /// The spray particles' positions (m).
    spray: Vec<Vec3>,
    /// The volume m/ρ0 of a particle (m³) and the kernel.
    particle_volume: f64,
    kernel: crate::kernel::CubicKernel,
}

/// An 8 × 10 × 8 lattice at rest density (`params` with mass factor 1, the calm settings, two
/// threads) in a closed tank twice as high as the water, with its walls (`walls`) d + r/4 from
/// the lattice; and the tank.
fn tank_at_rest_density(params: Params, walls: ContainerWalls) -> (World, Aabb) {
    let params = Params {
        mass_factor: 1.0,
        threads: 2,
        ..params.calm()
    };
    let (d, r) = (params.spacing(), params.particle_radius);
    let gap = d + 0.25 * r;
    let extent = |c: usize| (c - 1) as f64 * d + 2.0 * gap;
    let tank = Aabb {
        min: Vec3::zeros(),
        max: Vec3::new(extent(8), 2.0 * extent(10), extent(8)),
    };
    let mut world = World::new(params).unwrap();
    world.add_container_with(tank, walls).unwrap();
    world
        .add_fluid_block(Vec3::repeat(gap), [8, 10, 8], Vec3::zeros())
        .unwrap();
    (world, tank)
}

/// An 8 × 10 × 8 lattice (r = 2.5 cm, mass factor 1, the calm settings) in a closed tank with
/// its walls (`walls`: fields or particles) d + r/4 from the lattice, as the CLI's
/// hydrostatic validation builds it; relaxed
/// for 10 s at 4/s, 2 s free, then 0.25 s solved to τ = 10⁻⁵·r with η = 0, the reading's
/// tolerance of docs/validation.md (the pressures are read from forces, docs/method.md
/// §10.3), and read; then spray is added and the gauges read again.
fn settled_tank(walls: ContainerWalls) -> &'static Settled {
    static TANKS: [OnceLock<Settled>; 2] = [OnceLock::new(), OnceLock::new()];
    TANKS[walls as usize].get_or_init(|| {
        let r = 0.025;
        let (mut world, tank) = tank_at_rest_density(Params::with_radius(r), walls);
        let d = world.params().spacing();
        let (cx, cz) = (tank.max.x / 2.0, tank.max.z / 2.0);
        let (ox, oz) = (cx + 0.37 * d, cz - 0.6 * d);
        // In the fluid: at least H from the floor and the side walls, and 2H and more below the
        // surface (about 0.51 m). On the walls: two side walls and the floor, at least H from
        // their edges.
        let probes = ProbeSet {
            rate: 100.0,
            gauges: vec![Gauge::new("centre", cx, cz), Gauge::new("off", ox, oz)],
            pressure: vec![
                PressureProbe::new("P10", [cx, 0.1, cz]),
                PressureProbe::new("P20", [cx, 0.2, cz]),
                PressureProbe::new("P30", [cx, 0.3, cz]),
                PressureProbe::new("Q15", [ox, 0.15, oz]),
                PressureProbe::new("Q25", [ox, 0.25, oz]),
                PressureProbe::on_wall("wall_x", [0.0, 0.2, cz]),
                PressureProbe::on_wall("wall_z", [cx, 0.3, 0.0]),
                PressureProbe::on_wall("floor", [cx, 0.0, cz]),
            ],
        };
        world.relax(10.0, 4.0).unwrap();
        world.advance(2.0).unwrap();
        world.set_density_tolerance(0.0).unwrap();
        world.set_displacement_tolerance(1e-5 * r).unwrap();
        world.advance(0.25).unwrap();
        let reading = probes.read(&world).unwrap();
        let h = world.params().support_radius();
        let mut random = crate::random::SplitMix64(7);
        let mut between = |low: f64, high: f64| low + (high - low) * random.next_f64();
        let random = ProbeSet {
            rate: 100.0,
            gauges: Vec::new(),
            pressure: (0..200)
                .map(|k| {
                    let x = between(h, tank.max.x - h);
                    let y = between(h, 0.31);
                    let z = between(h, tank.max.z - h);
                    PressureProbe::new(&format!("R{k}"), [x, y, z])
                })
                .collect(),
        };
        let random_reading = random.read(&world).unwrap().pressures;
        let content = ProbeSet {
            rate: 100.0,
            gauges: (probes.gauges.iter())
                .map(|g| Gauge {
                    name: format!("{}_content", g.name),
                    measure: GaugeMeasure::Content,
                    ..g.clone()
                })
                .collect(),
            pressure: Vec::new(),
        };
        let content_before = content.read(&world).unwrap().heights;

        let positions = world.positions();
        let top = positions.iter().map(|p| p.y).fold(f64::MIN, f64::max);
        let layer: Vec<f64> = (positions.iter().map(|p| p.y))
            .filter(|&y| y > top - 0.5 * d)
            .collect();
        let particle_surface = layer.iter().sum::<f64>() / layer.len() as f64 + 0.5 * d;
        let volume = world.fluid_count() as f64 * world.particle_mass() / RHO0;
        let area = (tank.max.x - d) * (tank.max.z - d);

        // Spray: single droplets on both gauge lines 3 and 5 spacings above the water, and a
        // clump of eight 6 spacings above it, each farther than H from the water.
        let s = particle_surface;
        let mut spray = vec![
            Vec3::new(cx, s + 3.0 * d, cz),
            Vec3::new(cx, s + 5.0 * d, cz),
            Vec3::new(ox, s + 3.0 * d, oz),
        ];
        for i in 0..8 {
            let corner = Vec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64);
            spray.push(Vec3::new(ox, s + 6.0 * d, oz) + (corner - Vec3::repeat(0.5)) * d);
        }
        world.add_fluid_particles(&spray, None).unwrap();
        let with_spray = probes.read(&world).unwrap().heights;
        let content_after = content.read(&world).unwrap().heights;
        Settled {
            spacing: d,
            volume_surface: volume / area + 0.5 * d,
            particle_surface,
            probes,
            reading,
            random: (random.pressure, random_reading),
            with_spray,
            volume_depth: volume / area,
            content: (content.gauges, content_before, content_after),
            spray,
            particle_volume: world.particle_mass() / RHO0,
            kernel: crate::kernel::CubicKernel::new(world.params().support_radius()),
        }
    })
}

/// The gauges read the water's height within one spacing of what its volume says, and spray
/// above the water changes nothing.
#[test]
fn gauges_read_the_water_height_and_ignore_spray() {
    for walls in WALLS {
        let t = settled_tank(walls);
        for (gauge, height) in t.probes.gauges.iter().zip(&t.reading.heights) {
            assert!(
                (height - t.volume_surface).abs() <= t.spacing,
                "{walls:?} walls, {}: {height:.4} m, N·V/area + d/2 = {:.4} m",
                gauge.name,
                t.volume_surface
            );
            assert!(
                (height - t.particle_surface).abs() <= 0.5 * t.spacing,
                "{}: {height:.4} m, top layer + d/2 = {:.4} m",
                gauge.name,
                t.particle_surface
            );
        }
        for (a, b) in t.reading.heights.iter().zip(&t.with_spray) {
            assert!((a - b).abs() <= 1e-9, "spray moved a gauge from {a} to {b}");
        }
    }
}

/// A water-content gauge reads the depth of the settled water within a quarter spacing: the
/// depth the particles show (from the water's bottom face, d/2 above the floor's particle
/// plane, to its top face, the top layer + d/2) and the surface gauges' height less that d/2;
/// and within half a spacing of the depth N·V/area (the settled water stands 2–3 % higher
/// than that). Spray above the water adds to it exactly what its particles' volumes put on
/// the line, though the surface gauges do not see it.
#[test]
fn content_gauges_count_all_the_water_on_the_line() {
    for walls in WALLS {
        let t = settled_tank(walls);
        let (gauges, before, after) = &t.content;
        for ((gauge, content), (g, surface)) in gauges
            .iter()
            .zip(before)
            .zip(t.probes.gauges.iter().zip(&t.reading.heights))
        {
            let depth = t.particle_surface - 0.5 * t.spacing;
            assert!(
                (content - depth).abs() <= 0.25 * t.spacing,
                "{walls:?} walls, {}: {content:.4} m, top layer = {depth:.4} m",
                gauge.name
            );
            assert!(
                (content - t.volume_depth).abs() <= 0.5 * t.spacing,
                "{}: {content:.4} m, N·V/area = {:.4} m",
                gauge.name,
                t.volume_depth
            );
            // The standing column's surface lies d/2 above the content's depth (its bottom face
            // is d/2 above the floor's particle plane).
            assert!(
                (surface - content - 0.5 * t.spacing).abs() <= 0.25 * t.spacing,
                "{}: surface {surface:.4} m, content {content:.4} m",
                g.name
            );
        }
        for ((gauge, a), b) in gauges.iter().zip(before).zip(after) {
            let spray: f64 = (t.spray.iter())
                .map(|p| t.kernel.line_integral((p.x - gauge.x).hypot(p.z - gauge.z)))
                .sum::<f64>()
                * t.particle_volume;
            assert!(spray > 0.5 * t.spacing, "{}: spray {spray}", gauge.name);
            assert!(
                (b - a - spray).abs() <= 1e-9,
                "{}: the spray added {} m, its volume on the line is {spray} m",
                gauge.name,
                b - a
            );
        }
    }
}

/// Two support radii and more below the free surface, the probes read ρ0·g·depth within 10 %,
/// in the fluid and on the walls, and 200 random points of the same region within 5 % on
/// average (each within 12 %, their standard deviation at most 5 %), with walls of particles
/// and walls that are fields; the depth is measured from the free surface the gauges read
/// (checked against the particles and the volume above). Why these bounds: see below.
#[test]
fn pressure_probes_read_the_hydrostatic_pressure() {
    for walls in WALLS {
        let t = settled_tank(walls);
        let heights = &t.reading.heights;
        let surface = heights.iter().sum::<f64>() / heights.len() as f64;
        let ratio = |probe: &PressureProbe, p: f64| p / (RHO0 * G * (surface - probe.position[1]));
        let named: Vec<f64> = (t.probes.pressure.iter().zip(&t.reading.pressures))
            .map(|(probe, &p)| ratio(probe, p))
            .collect();
        let (probes, pressures) = &t.random;
        let random: Vec<f64> = (probes.iter().zip(pressures))
            .map(|(probe, &p)| ratio(probe, p))
            .collect();
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        let deviation = |v: &[f64]| {
            let m = mean(v);
            (v.iter().map(|r| (r - m) * (r - m)).sum::<f64>() / v.len() as f64).sqrt()
        };
        let (m, sd) = (mean(&random), deviation(&random));
        let range = (random.iter().copied())
            .fold((f64::MAX, f64::MIN), |(lo, hi), r| (lo.min(r), hi.max(r)));
        let report = format!(
            "{walls:?} walls: named probes {named:.3?}; 200 random points: mean {m:.3}, standard deviation {sd:.3}, \
         extremes {:.3} and {:.3}",
            range.0, range.1
        );
        // The particle pressures vary with the packing, so a point reads ρ0·g·depth only to
        // within a few per cent (docs/method.md §10.3), and the settled packing moves with
        // the rounding alone: the same tank shifted by 10⁻⁷ to 10⁻⁶ m read its mean 1.010 to
        // 1.032 and a named point up to 1.081 with particle walls. Next to smooth walls the
        // water packs otherwise and its particle pressures read about 4 % high (as next to
        // walls sampled at 2r). So the mean must lie within 5 %, a named point within 10 %
        // and each random point within 12 %.
        let (within, named_within, each_within) = (0.05, 0.1, 0.12);
        assert!((m - 1.0).abs() <= within, "{report}");
        assert!(sd <= 0.05, "{report}");
        assert!(
            named.iter().all(|r| (r - 1.0).abs() <= named_within),
            "{report}"
        );
        assert!(
            random.iter().all(|r| (r - 1.0).abs() <= each_within),
            "{report}"
        );
    }
}

/// A 6 × 4 × 6 lattice at rest in a half-metre box, before its first step.
fn small_tank(threads: usize) -> World {
    let mut world = World::new(Params {
        threads,
        ..Params::default()
    })
    .unwrap();
    // Walls r/4 outside the nominal 0.5 m box, so that no fluid particle starts compressed.
    let gap = 0.25 * world.params().particle_radius;
    let tank = Aabb {
        min: Vec3::repeat(-gap),
        max: Vec3::repeat(0.5 + gap),
    };
    world.add_container(tank, 1).unwrap();
    world
        .add_fluid_block(Vec3::repeat(0.05), [6, 4, 6], Vec3::zeros())
        .unwrap();
    world
}

/// The ends of a gauge and the undefined readings: a dry bottom reads 0, a column over the
/// top reads top − bottom, a dry floor less than a spacing; a probe in the air reads NaN, one
/// on a dry wall 0, one on no wall NaN.
#[test]
fn gauge_ends_and_undefined_pressures() {
    let world = small_tank(1);
    let gauge = |name: &str, bottom: Option<f64>, top: Option<f64>| Gauge {
        bottom,
        top,
        ..Gauge::new(name, 0.175, 0.175)
    };
    let probes = ProbeSet {
        rate: 10.0,
        gauges: vec![
            gauge("floor", None, None),
            gauge("dry", Some(0.3), None),
            gauge("short", Some(0.05), Some(0.1)),
            Gauge::new("dry_floor", 0.42, 0.42),
        ],
        pressure: vec![
            PressureProbe::new("air", [0.25, 0.45, 0.25]),
            PressureProbe::on_wall("lid", [0.25, 0.5, 0.25]),
            PressureProbe::on_wall("nowhere", [0.25, 0.35, 0.25]),
        ],
    };
    let reading = probes.read(&world).unwrap();
    // The lattice's top centres are at 0.2 m, its top face at 0.225 m.
    let h = reading.heights[0];
    assert!((0.175..=0.25).contains(&h), "{h}");
    assert_eq!(&reading.heights[1..3], &[0.0, 0.1 - 0.05]);
    // A dry floor reads where the wall's own fraction falls to ½, within a spacing of it.
    let dry = reading.heights[3];
    assert!(dry > 0.0 && dry < world.params().spacing(), "{dry}");
    assert!(reading.pressures[0].is_nan());
    assert_eq!(reading.pressures[1], 0.0);
    assert!(reading.pressures[2].is_nan());
    assert_eq!(reading.time, 0.0);
}

/// The readings do not depend on the thread count: the same flow, stepped and read with one
/// thread and with three, reads the same bits.
#[test]
fn readings_do_not_depend_on_the_thread_count() {
    let probes = ProbeSet {
        rate: 100.0,
        gauges: vec![Gauge::new("H1", 0.1, 0.2), Gauge::new("H2", 0.3, 0.3)],
        pressure: vec![
            PressureProbe::new("P1", [0.1, 0.05, 0.2]),
            PressureProbe::on_wall("W1", [0.0, 0.05, 0.25]),
        ],
    };
    let read = |threads| {
        let mut world = small_tank(threads);
        for _ in 0..12 {
            world.step().unwrap();
        }
        probes.read(&world).unwrap()
    };
    let (one, three) = (read(1), read(3));
    let bits = |r: &ProbeReading| r.values().map(f64::to_bits).collect::<Vec<_>>();
    assert_eq!(bits(&one), bits(&three));
    assert!(one.values().all(f64::is_finite), "{one:?}");
    assert!(one.pressures[1] > 0.0, "{one:?}");
}

/// Gauges read on a frame of positions: the world's own positions read what the world reads,
/// to the bit; the water without its top layer reads a spacing lower; a frame with no water on a line
/// reads a dry floor; pressure probes read NaN; a position that is not finite is refused,
/// naming it.
#[test]
fn gauges_read_frames_of_positions() {
    let mut world = small_tank(1);
    for _ in 0..6 {
        world.step().unwrap();
    }
    let probes = ProbeSet {
        rate: 100.0,
        gauges: vec![
            Gauge::new("H1", 0.175, 0.175),
            Gauge {
                measure: GaugeMeasure::Content,
                ..Gauge::new("C1", 0.175, 0.175)
            },
        ],
        pressure: vec![PressureProbe::new("P1", [0.175, 0.05, 0.175])],
    };
    let own = probes.read(&world).unwrap();
    let positions = world.positions();
    let frame = probes.read_frame(&world, &positions, 0.5).unwrap();
    assert_eq!(frame.time, 0.5);
    let bits = |h: &[f64]| h.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&frame.heights), bits(&own.heights));
    assert!(frame.pressures[0].is_nan() && own.pressures[0].is_finite());
    // Without its top layer the water's surface reads a spacing lower, within a quarter of
    // one, and the content a layer less.
    let d = world.params().spacing();
    let top = positions.iter().map(|p| p.y).fold(f64::MIN, f64::max);
    let lower: Vec<Vec3> = positions
        .iter()
        .filter(|p| p.y < top - 0.5 * d)
        .copied()
        .collect();
    let layer = probes.read_frame(&world, &lower, 0.5).unwrap();
    let drop = own.heights[0] - layer.heights[0];
    assert!((drop - d).abs() < 0.25 * d, "{layer:?} {own:?}");
    let drop = own.heights[1] - layer.heights[1];
    assert!((drop - d).abs() < 0.25 * d, "{layer:?} {own:?}");
    // Moved off the line, the water leaves a dry floor there.
    let aside: Vec<Vec3> = positions
        .iter()
        .filter(|p| (p.x - 0.175).abs() > 0.1 || (p.z - 0.175).abs() > 0.1)
        .copied()
        .collect();
    let dry = probes.read_frame(&world, &aside, 0.5).unwrap();
    assert!(
        dry.heights[0] < d && dry.heights[1] < 0.05 * own.heights[1],
        "{dry:?}"
    );
    let mut bad = positions.clone();
    bad[3].y = f64::NAN;
    let e = probes
        .read_frame(&world, &bad, 0.5)
        .unwrap_err()
        .to_string();
    assert!(e.contains("fluid[3]") && e.contains("finite"), "{e}");
}

/// Bad definitions are rejected with the key and the value.
#[test]
fn bad_probe_definitions_name_the_key() {
    let good = ProbeSet {
        rate: 50.0,
        gauges: vec![Gauge::new("H1", 0.2, 0.2)],
        pressure: vec![PressureProbe::new("P1", [0.2, 0.1, 0.2])],
    };
    good.validate().unwrap();
    let message = |probes: ProbeSet| probes.validate().unwrap_err().to_string();
    let with_gauge = |g: Gauge| ProbeSet {
        gauges: vec![Gauge::new("H0", 0.1, 0.1), g],
        ..good.clone()
    };
    let cases = [
        (
            ProbeSet {
                rate: 0.0,
                ..good.clone()
            },
            "probes.rate must be a positive finite number of readings per second, got 0",
        ),
        (
            ProbeSet {
                rate: f64::NAN,
                ..good.clone()
            },
            "probes.rate must be a positive finite number of readings per second, got NaN",
        ),
        (
            ProbeSet {
                gauges: Vec::new(),
                pressure: Vec::new(),
                ..good.clone()
            },
            "probes must hold at least one gauge or pressure probe, got no probes",
        ),
        (
            with_gauge(Gauge::new("", 0.1, 0.1)),
            "probes.gauges[1].name must be 1 to 64 ASCII letters, digits, `_`, `-` or `.` \
             (it names a CSV column), got \"\"",
        ),
        (
            with_gauge(Gauge::new("H 2,", 0.1, 0.1)),
            "probes.gauges[1].name must be 1 to 64 ASCII letters, digits, `_`, `-` or `.` \
             (it names a CSV column), got \"H 2,\"",
        ),
        (
            with_gauge(Gauge::new("P1", 0.1, 0.1)),
            "probes.pressure[0].name must be unique among the probes (each names a CSV \
             column), got `P1`",
        ),
        (
            with_gauge(Gauge::new("H2", f64::NAN, 0.1)),
            "probes.gauges[1].x must be a finite coordinate (m), got NaN",
        ),
        (
            with_gauge(Gauge {
                top: Some(f64::INFINITY),
                ..Gauge::new("H2", 0.1, 0.1)
            }),
            "probes.gauges[1].top must be a finite coordinate (m), got inf",
        ),
        (
            with_gauge(Gauge {
                bottom: Some(0.5),
                top: Some(0.2),
                ..Gauge::new("H2", 0.1, 0.1)
            }),
            "probes.gauges[1].bottom must lie below top (0.2), got 0.5",
        ),
        (
            ProbeSet {
                pressure: vec![PressureProbe::new("P1", [0.0, f64::NAN, 0.0])],
                ..good.clone()
            },
            "probes.pressure[0].position must be a finite point (m), got [0.0, NaN, 0.0]",
        ),
    ];
    for (probes, expected) in cases {
        assert_eq!(message(probes), expected);
    }
    // Against a world: gauges need gravity along −y and a floor under a gauge without a bottom.
    let floor = [Aabb {
        min: Vec3::zeros(),
        max: Vec3::repeat(0.5),
    }];
    good.validate_for([0.0, -9.81, 0.0], &floor).unwrap();
    let err = good.validate_for([0.0, 0.0, -9.81], &floor).unwrap_err();
    assert_eq!(
        err.to_string(),
        "probes.gauges measure heights along y, so gravity must point along -y, \
         got gravity [0.0, 0.0, -9.81]"
    );
    let outside = ProbeSet {
        gauges: vec![Gauge::new("H1", 0.7, 0.2)],
        ..good.clone()
    };
    let err = outside.validate_for([0.0, -9.81, 0.0], &floor).unwrap_err();
    assert_eq!(
        err.to_string(),
        "probes.gauges[0].bottom must be given where no container's floor lies under the \
         gauge at x = 0.7, z = 0.2, got none"
    );
    let world = small_tank(1);
    assert_eq!(
        outside.read(&world).unwrap_err(),
        outside.validate_for([0.0, -9.81, 0.0], &floor).unwrap_err()
    );
    // Pressure probes alone need neither.
    let pressure_only = ProbeSet {
        gauges: Vec::new(),
        ..good
    };
    pressure_only.validate_for([0.0, 0.0, 0.0], &[]).unwrap();
}

/// The scene key reads, validates against the scene and writes back.
#[test]
fn scene_key_probes_reads_and_round_trips() {
    let scene_text = |probes: &str| {
        format!(
            r#"{{"particle_radius": 0.025, "container": {{"min": [0, 0, 0], "max": [0.5, 0.5, 0.5]}},
                "fluid_blocks": [{{"start": [0.05, 0.05, 0.05], "count": [4, 4, 4]}}],
                "duration": 0.1, "probes": {probes}}}"#
        )
    };
    let probes = r#"{"rate": 200,
        "gauges": [{"name": "H1", "x": 0.2, "z": 0.2}, {"name": "H2", "x": 0.3, "z": 0.1, "bottom": 0.05, "top": 0.4}, {"name": "C", "x": 0.25, "z": 0.2, "measure": "content"}],
        "pressure": [{"name": "P1", "position": [0.2, 0.05, 0.2]}, {"name": "W1", "position": [0, 0.1, 0.2], "wall": true}]}"#;
    let scene = Scene::from_json(&scene_text(probes)).unwrap();
    let set = scene.probes.clone().unwrap();
    assert_eq!(set.rate, 200.0);
    assert_eq!(set.gauges[1].bottom, Some(0.05));
    assert_eq!(set.gauges[0].top, None);
    assert_eq!(set.gauges[0].measure, GaugeMeasure::Surface);
    assert_eq!(set.gauges[2].measure, GaugeMeasure::Content);
    assert!(set.pressure[1].wall && !set.pressure[0].wall);
    assert_eq!(set.columns(), ["H1_m", "H2_m", "C_m", "P1_Pa", "W1_Pa"]);
    assert_eq!(crate::scene::probes_from_json(probes).unwrap(), set);
    let json = scene.to_json();
    assert_eq!(Scene::from_json(&json).unwrap(), scene, "{json}");
    let message = |text: &str| Scene::from_json(text).unwrap_err().to_string();
    assert_eq!(
        message(&scene_text(
            r#"{"rate": 20000, "gauges": [{"name": "H", "x": 0.2, "z": 0.2}]}"#
        )),
        "probes.rate must be at most 1/dt_min (10000 readings per second), got 20000"
    );
    let unknown = message(&scene_text(
        r#"{"rate": 20, "gauges": [{"name": "H", "x": 0.2, "z": 0.2, "y": 1}]}"#,
    ));
    assert!(
        unknown.contains("probes.gauges[0]: unknown field `y`"),
        "{unknown}"
    );
    let unknown = message(&scene_text(
        r#"{"rate": 20, "gauges": [{"name": "H", "x": 0.2, "z": 0.2, "measure": "depth"}]}"#,
    ));
    assert!(
        unknown.contains("unknown variant `depth`, expected `surface` or `content`"),
        "{unknown}"
    );
    let unknown = crate::scene::probes_from_json(r#"{"rate": 20, "gauge": []}"#)
        .unwrap_err()
        .to_string();
    assert!(
        unknown.contains("probes: unknown field `gauge`"),
        "{unknown}"
    );
    assert_eq!(
        crate::scene::probes_from_json(r#"{"rate": 20}"#)
            .unwrap_err()
            .to_string(),
        "probes must hold at least one gauge or pressure probe, got no probes"
    );
}

/// The example of docs/scene-format.md reads in `dam_break_30k`, and its wall probe lies on
/// the far wall's particles.
#[test]
fn documented_probes_example_is_valid() {
    let doc = include_str!("../../docs/scene-format.md");
    let example = doc
        .split("```json\n")
        .find(|block| block.starts_with("\"probes\""))
        .and_then(|rest| rest.split("```").next())
        .expect("docs/scene-format.md has a probes example");
    let scene = Scene::builtin("dam_break_30k").unwrap().to_json();
    let text = format!(
        "{{{example}, {}",
        scene.trim_start().trim_start_matches('{')
    );
    let scene = Scene::from_json(&text).unwrap();
    let probes = scene.probes.unwrap();
    assert_eq!(probes.columns(), ["H1_m", "H2_m", "C1_m", "P1_Pa", "W1_Pa"]);
    assert_eq!(probes.gauges[2].measure, GaugeMeasure::Content);
    assert_eq!(probes.rate, 100.0);
    assert!(probes.pressure[1].wall);
    assert_eq!(probes.pressure[1].position[0], scene.containers[0].max[0]);
}

/// The pressures come from the multipliers the last step carried through its iteration
/// (docs/method.md §10.1), so a tank at rest reads ρ0·g·depth at the calm settings' own τ,
/// without the tight reading solve, and at a stiff k as at the default one: probes in the
/// fluid and on a side wall within 5 %, on the floor within 8 % (measured: 0.997–1.008, 1.012
/// and 0.951 at the default k; 0.962–0.995, 0.991 and 0.930 at k = 10⁶ N/m). A local step at
/// the current positions, the reading for worlds whose last step carried nothing, is off by
/// far more at k = 10⁶ N/m (0.44 to 6.4 of it, measured): there the step ends near the
/// hard-constraint solution, far from the penalty's fixed point that reading assumes.
#[test]
fn carried_pressures_need_no_tight_solve_and_hold_at_a_stiff_k() {
    for stiffness in [Params::default().stiffness, 1e6] {
        let params = Params {
            stiffness,
            ..Params::with_radius(0.025)
        };
        let (mut world, tank) = tank_at_rest_density(params, ContainerWalls::Particles);
        let (cx, cz) = (tank.max.x / 2.0, tank.max.z / 2.0);
        let probes = ProbeSet {
            rate: 100.0,
            gauges: vec![Gauge::new("centre", cx, cz)],
            pressure: vec![
                PressureProbe::new("P10", [cx, 0.1, cz]),
                PressureProbe::new("P20", [cx, 0.2, cz]),
                PressureProbe::new("P30", [cx, 0.3, cz]),
                PressureProbe::on_wall("wall_x", [0.0, 0.2, cz]),
                PressureProbe::on_wall("floor", [cx, 0.0, cz]),
            ],
        };
        world.relax(10.0, 4.0).unwrap();
        world.advance(2.25).unwrap();
        let ratios = |reading: &ProbeReading| -> Vec<f64> {
            let surface = reading.heights[0];
            (probes.pressure.iter().zip(&reading.pressures))
                .map(|(probe, p)| p / (RHO0 * G * (surface - probe.position[1])))
                .collect()
        };
        let carried = ratios(&probes.read(&world).unwrap());
        let bounds = [0.05, 0.05, 0.05, 0.05, 0.08];
        assert!(
            carried
                .iter()
                .zip(bounds)
                .all(|(r, b)| (r - 1.0).abs() <= b),
            "k = {stiffness} N/m: {carried:.3?} of ρ0·g·depth"
        );
        if stiffness == 1e6 {
            world.fluid.pressures.clear();
            let local = ratios(&probes.read(&world).unwrap());
            assert!(
                local.iter().any(|r| (r - 1.0).abs() > 0.2),
                "k = {stiffness} N/m, read from a local step: {local:.3?} of ρ0·g·depth"
            );
        }
    }
}
