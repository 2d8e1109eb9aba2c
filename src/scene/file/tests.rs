//! Tests of the JSON form: keys and defaults, round trips, and the messages of bad files.

use crate::params::Params;
use crate::scene::test_support::{GOOD, assert_names, message};
use crate::scene::{OutputSpec, Scene};
use std::path::{Path, PathBuf};

#[test]
fn defaults_come_from_params_with_radius() {
    let scene = Scene::from_json(GOOD).unwrap();
    assert_eq!(scene.params, Params::with_radius(0.05));
    assert_eq!(scene.containers[0].layers, 1);
    assert_eq!(
        scene.containers[0].walls,
        crate::scene::ContainerWalls::Particles
    );
    assert_eq!(scene.fluid_blocks[0].velocity, [0.0; 3]);
    assert_eq!(scene.output, OutputSpec::default());
    assert_eq!(scene.particle_count(), 64 + 12);
}

/// A weighting's name is the value scenes write for it, and it parses back; an unknown
/// name does not.
#[test]
fn projection_weight_names_are_the_scene_values() {
    use crate::ProjectionWeight as W;
    for w in [W::NeighborCount, W::Unit, W::Uniform] {
        let text = format!(
            r#"{{"particle_radius": 0.025, "container": {{"min": [0, 0, 0], "max": [1, 1, 1]}},
                    "fluid_blocks": [{{"start": [0.1, 0.1, 0.1], "count": [2, 2, 2]}}],
                    "duration": 1, "solver": {{"projection_weight": "{}"}}}}"#,
            w.name()
        );
        let scene = Scene::from_json(&text).unwrap();
        assert_eq!(scene.params.projection_weight, w);
        assert_eq!(W::from_name(w.name()), Some(w));
    }
    assert_eq!(W::from_name("neighbour_count"), None);
}

#[test]
fn every_key_is_read() {
    let text = r#"{
            "name": "all", "description": "every key",
            "particle_radius": 0.02, "rest_density": 998, "mass_factor": 0.9, "stiffness": 1e5,
            "gravity": [0, 0, -9.8],
            "container": [{"min": [0, 0, 0], "max": [1, 1, 1], "walls": "particles", "layers": 2}],
            "fluid_blocks": [{"start": [0.1, 0.1, 0.1], "count": [2, 2, 2], "velocity": [0, 1, 0]}],
            "solver": {"kind": "jacobi", "rho": 0.8, "delay": 2, "omega2": "paper", "gamma": 0.9,
                       "tau": 1e-6, "warm_start": 0.3, "coarse_correction": false,
                       "max_iterations": 50, "min_iterations": 2, "projection_weight": "unit"},
            "time": {"cfl_factor": 0.4, "dt_min": 1e-5, "dt_max": 1e-2, "dt_initial": 2e-3},
            "viscosity": 0.02, "kinematic_viscosity": 1e-4, "no_slip": false,
            "vorticity_confinement": 0.4, "threads": 2, "backend": "gpu", "duration": 3,
            "output": {"dir": "frames", "every": 5, "fps": 25}
        }"#;
    let s = Scene::from_json(text).unwrap();
    let p = &s.params;
    assert_eq!(
        (
            p.particle_radius,
            p.rest_density,
            p.mass_factor,
            p.stiffness
        ),
        (0.02, 998.0, 0.9, 1e5)
    );
    assert_eq!(p.gravity, [0.0, 0.0, -9.8]);
    assert_eq!(p.solver, crate::SolverKind::Jacobi);
    assert_eq!(p.chebyshev.rho, 0.8);
    assert_eq!(p.chebyshev.delay, 2);
    assert_eq!(p.chebyshev.omega2_rule, crate::Omega2Rule::Paper);
    assert_eq!(p.chebyshev.gamma, 0.9);
    assert_eq!(p.displacement_tolerance, 1e-6);
    assert_eq!(p.warm_start, 0.3);
    assert!(!p.coarse_correction);
    assert_eq!((p.min_outer_iterations, p.max_outer_iterations), (2, 50));
    assert_eq!(p.projection_weight, crate::ProjectionWeight::Unit);
    assert_eq!(
        (p.cfl_factor, p.dt_min, p.dt_max, p.dt_initial),
        (0.4, 1e-5, 1e-2, 2e-3)
    );
    assert_eq!((p.viscosity, p.threads), (0.02, 2));
    assert_eq!(p.kinematic_viscosity, 1e-4);
    assert_eq!(p.vorticity_confinement, 0.4);
    assert!(!p.no_slip);
    assert_eq!(p.backend, crate::Backend::Gpu);
    assert_eq!(s.containers[0].layers, 2);
    assert_eq!(
        s.containers[0].walls,
        crate::scene::ContainerWalls::Particles
    );
    assert_eq!(s.fluid_blocks[0].velocity, [0.0, 1.0, 0.0]);
    assert_eq!(s.duration, 3.0);
    assert_eq!(s.description, "every key");
    assert_eq!(s.output.dir.as_deref(), Some(Path::new("frames")));
    assert_eq!(s.output.every, 5);
    assert_eq!(s.output.fps, Some(25.0));
}

/// `surface_tension` and `wall_adhesion` (N/m) are 0 unless a scene sets them, are written
/// back only when set, and are checked naming the key.
#[test]
fn surface_tension_and_wall_adhesion_are_read_written_and_checked() {
    let plain = Scene::from_json(GOOD).unwrap();
    assert_eq!(
        (plain.params.surface_tension, plain.params.wall_adhesion),
        (0.0, 0.0)
    );
    assert!(!plain.to_json().contains("surface_tension"));
    let text = GOOD.replacen(
        "\"fluid_blocks\"",
        "\"surface_tension\": 0.05, \"wall_adhesion\": 0.07, \"fluid_blocks\"",
        1,
    );
    let scene = Scene::from_json(&text).unwrap();
    assert_eq!(scene.params.surface_tension, 0.05);
    assert_eq!(scene.params.wall_adhesion, 0.07);
    let again = Scene::from_json(&scene.to_json()).unwrap();
    assert_eq!(again, scene);
    for (key, value) in [("surface_tension", "-0.05"), ("wall_adhesion", "1e9")] {
        let bad = GOOD.replacen(
            "\"fluid_blocks\"",
            &format!("\"{key}\": {value}, \"fluid_blocks\""),
            1,
        );
        let e = Scene::from_json(&bad).unwrap_err().to_string();
        assert!(e.contains(key), "{e}");
    }
}

#[test]
fn round_trip_through_json() {
    let mut scenes: Vec<Scene> = Scene::builtin_names()
        .iter()
        .map(|n| Scene::builtin(n).unwrap())
        .collect();
    let mut custom = Scene::from_json(GOOD).unwrap();
    custom.params.displacement_tolerance = 1.0 / 3.0 * 1e-4;
    custom.params.solver = crate::SolverKind::Jacobi1;
    custom.params.projection_weight = crate::ProjectionWeight::Unit;
    custom.params.chebyshev.omega2_rule = crate::Omega2Rule::Paper;
    custom.params.coarse_correction = false;
    custom.params.kinematic_viscosity = 1.0 / 3.0 * 1e-3;
    custom.params.no_slip = false;
    custom.params.backend = crate::Backend::Gpu;
    custom.output.dir = Some(PathBuf::from("out [1]/frames"));
    custom.description = "quotes \" and [brackets]".to_string();
    scenes.push(custom);
    for scene in scenes {
        let json = scene.to_json();
        assert_eq!(Scene::from_json(&json).unwrap(), scene, "{json}");
    }
}

#[test]
fn to_json_keeps_number_arrays_on_one_line() {
    let json = Scene::builtin("dam_break_small").unwrap().to_json();
    assert!(json.contains("\"count\": [16, 20, 12]"), "{json}");
}

#[test]
fn missing_required_fields_are_named() {
    let text = GOOD.replace("\"duration\": 0.5", "\"threads\": 1");
    assert_names(
        &message(Scene::from_json(&text)),
        &["missing field `duration`"],
    );
    let text = GOOD.replace("\"particle_radius\": 0.05,", "");
    assert_names(&message(Scene::from_json(&text)), &["`particle_radius`"]);
    let text = r#"{"particle_radius": 0.05, "duration": 1}"#;
    assert_names(&message(Scene::from_json(text)), &["`fluid_blocks`"]);
}

#[test]
fn unknown_keys_are_errors_with_their_path() {
    let text = GOOD.replace("\"duration\": 0.5", "\"duration\": 0.5, \"foo\": 1");
    let msg = message(Scene::from_json(&text));
    assert_names(&msg, &["unknown field `foo`", "line 9"]);
    let text = GOOD.replace("\"count\": [4, 4, 4]", "\"count\": [4, 4, 4], \"speed\": 2");
    assert_names(
        &message(Scene::from_json(&text)),
        &["fluid_blocks[0]", "unknown field `speed`"],
    );
    let text = GOOD.replace("\"max\": [1, 3, 1]", "\"max\": [1, 3, 1], \"layer\": 2");
    assert_names(
        &message(Scene::from_json(&text)),
        &["container", "unknown field `layer`"],
    );
}

#[test]
fn wrong_types_and_names_say_where() {
    let text = GOOD.replace(
        "\"duration\": 0.5",
        "\"duration\": 0.5, \"solver\": {\"kind\": \"sor\"}",
    );
    assert_names(
        &message(Scene::from_json(&text)),
        &["solver.kind", "`sor`", "chebyshev"],
    );
    let text = GOOD.replace("[4, 4, 4]", "[4, -4, 4]");
    assert_names(
        &message(Scene::from_json(&text)),
        &["fluid_blocks[0].count[1]", "-4"],
    );
}

#[test]
fn rho_auto_is_read_written_and_checked() {
    let auto = GOOD.replacen(
        "\"fluid_blocks\"",
        "\"solver\": {\"rho\": \"auto\"}, \"fluid_blocks\"",
        1,
    );
    let scene = Scene::from_json(&auto).unwrap();
    assert!(scene.params.chebyshev.auto_rho);
    let again = Scene::from_json(&scene.to_json()).unwrap();
    assert_eq!(again.params, scene.params);
    // A fixed ρ_c is the default, and a number always gives a fixed ρ_c.
    assert!(!Scene::from_json(GOOD).unwrap().params.chebyshev.auto_rho);
    let fixed = GOOD.replacen(
        "\"fluid_blocks\"",
        "\"solver\": {\"rho\": 0.9}, \"fluid_blocks\"",
        1,
    );
    let fixed = Scene::from_json(&fixed).unwrap().params.chebyshev;
    assert!(!fixed.auto_rho && fixed.rho == 0.9);
    let bad = GOOD.replacen(
        "\"fluid_blocks\"",
        "\"solver\": {\"rho\": \"fast\"}, \"fluid_blocks\"",
        1,
    );
    assert_names(
        &message(Scene::from_json(&bad)),
        &["solver.rho", "fast", "\"auto\""],
    );
}

/// `solver.coarse_correction` is off unless a scene turns it on, and a scene written out
/// keeps the setting.
#[test]
fn coarse_correction_is_read_and_written() {
    assert!(!Scene::from_json(GOOD).unwrap().params.coarse_correction);
    let on = GOOD.replacen(
        "\"fluid_blocks\"",
        "\"solver\": {\"coarse_correction\": true}, \"fluid_blocks\"",
        1,
    );
    let scene = Scene::from_json(&on).unwrap();
    assert!(scene.params.coarse_correction);
    let json = scene.to_json();
    assert!(json.contains("\"coarse_correction\": true"), "{json}");
    let again = Scene::from_json(&json).unwrap();
    assert!(again.params.coarse_correction);
    assert_eq!(again, scene);
    let bad = GOOD.replacen(
        "\"fluid_blocks\"",
        "\"solver\": {\"coarse_correction\": 1}, \"fluid_blocks\"",
        1,
    );
    assert_names(
        &message(Scene::from_json(&bad)),
        &["solver.coarse_correction"],
    );
}

/// `kinematic_viscosity` (m²/s) is 0 and `no_slip` true unless a scene sets them; a scene
/// written out keeps both; a value of the wrong type, a negative viscosity and one that is
/// not a number are refused naming the key.
#[test]
fn kinematic_viscosity_and_no_slip_are_read_written_and_checked() {
    let plain = Scene::from_json(GOOD).unwrap().params;
    assert_eq!((plain.kinematic_viscosity, plain.no_slip), (0.0, true));
    let honey = GOOD.replacen(
        "\"fluid_blocks\"",
        "\"kinematic_viscosity\": 0.01, \"no_slip\": false, \"fluid_blocks\"",
        1,
    );
    let scene = Scene::from_json(&honey).unwrap();
    assert_eq!(scene.params.kinematic_viscosity, 0.01);
    assert!(!scene.params.no_slip);
    let json = scene.to_json();
    assert!(json.contains("\"kinematic_viscosity\": 0.01"), "{json}");
    assert!(json.contains("\"no_slip\": false"), "{json}");
    let again = Scene::from_json(&json).unwrap();
    assert_eq!(
        (again.params.kinematic_viscosity, again.params.no_slip),
        (0.01, false)
    );
    assert_eq!(again, scene);
    // The default is written too, and read back as it was.
    let json = Scene::from_json(GOOD).unwrap().to_json();
    assert!(json.contains("\"kinematic_viscosity\": 0.0"), "{json}");
    assert!(json.contains("\"no_slip\": true"), "{json}");
    let bad = |extra: &str| {
        let text = GOOD.replacen("\"fluid_blocks\"", &format!("{extra}, \"fluid_blocks\""), 1);
        message(Scene::from_json(&text))
    };
    assert_names(&bad("\"no_slip\": 1"), &["no_slip", "a boolean"]);
    assert_names(&bad("\"no_slip\": \"on\""), &["no_slip", "a boolean"]);
    assert_names(
        &bad("\"kinematic_viscosity\": \"honey\""),
        &["kinematic_viscosity", "honey"],
    );
    // JSON has no NaN: the string is a wrong type, the bare word a syntax error.
    assert_names(
        &bad("\"kinematic_viscosity\": \"NaN\""),
        &["kinematic_viscosity", "NaN"],
    );
    assert_names(
        &bad("\"kinematic_viscosity\": NaN"),
        &["line 5 column 32", "invalid JSON"],
    );
    assert_eq!(
        bad("\"kinematic_viscosity\": -1e-6"),
        "kinematic_viscosity must be finite and not negative (m²/s; 0 turns it off), got -0.000001"
    );
}

/// `backend` is `"cpu"` unless a scene sets it; a scene written out keeps it; a value other
/// than `"cpu"` or `"gpu"` is refused naming the key and the choices. A scene for the GPU
/// reads and validates in any build: its world is refused where it is made, naming the
/// backend and what is missing.
#[test]
fn backend_is_read_written_and_checked() {
    use crate::Backend;
    assert_eq!(Scene::from_json(GOOD).unwrap().params.backend, Backend::Cpu);
    let json = Scene::from_json(GOOD).unwrap().to_json();
    assert!(json.contains("\"backend\": \"cpu\""), "{json}");
    let with = |value: &str| {
        GOOD.replacen(
            "\"fluid_blocks\"",
            &format!("\"backend\": {value}, \"fluid_blocks\""),
            1,
        )
    };
    let scene = Scene::from_json(&with("\"gpu\"")).unwrap();
    assert_eq!(scene.params.backend, Backend::Gpu);
    scene.validate().unwrap();
    let json = scene.to_json();
    assert!(json.contains("\"backend\": \"gpu\""), "{json}");
    let again = Scene::from_json(&json).unwrap();
    assert_eq!(again.params.backend, Backend::Gpu);
    assert_eq!(again, scene);
    assert_eq!(
        Scene::from_json(&with("\"cpu\"")).unwrap().params.backend,
        Backend::Cpu
    );
    assert_names(
        &message(Scene::from_json(&with("\"tpu\""))),
        &["backend", "tpu", "`cpu`", "`gpu`"],
    );
    assert_names(
        &message(Scene::from_json(&with("\"GPU\""))),
        &["backend", "GPU", "`cpu`", "`gpu`"],
    );
    assert_names(&message(Scene::from_json(&with("1"))), &["backend", "1"]);
    #[cfg(not(feature = "gpu"))]
    assert_eq!(
        scene.build_world().err().map(|e| e.to_string()),
        Some("backend gpu: not available: this build of projfluid has no `gpu` feature".into())
    );
}

#[test]
fn documented_example_is_valid() {
    let doc = include_str!("../../../docs/scene-format.md");
    let example = doc
        .split("```json\n")
        .nth(1)
        .and_then(|rest| rest.split("```").next())
        .expect("docs/scene-format.md has a json scene example");
    let scene = Scene::from_json(example).unwrap();
    let mut expected = Scene::builtin("dam_break_small").unwrap();
    expected.description = scene.description.clone();
    expected.output = OutputSpec {
        dir: Some(PathBuf::from("frames")),
        every: 20,
        fps: None,
    };
    assert_eq!(scene, expected);
}

#[test]
fn trailing_garbage_is_an_error() {
    let msg = message(Scene::from_json(&format!("{GOOD} x")));
    assert_names(&msg, &["line 10", "trailing"]);
}
