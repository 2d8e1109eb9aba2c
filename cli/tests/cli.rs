//! The `projfluid` command line: exit codes, error messages, statistics and frames.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the binary with `args`.
fn projfluid(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_projfluid"))
        .args(args)
        .output()
        .expect("the projfluid binary runs")
}

/// A fresh temporary directory for one test.
fn temp_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("projfluid-cli-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A valid scene with one replacement applied to its text.
fn scene_with(from: &str, to: &str) -> String {
    let good = r#"{
  "name": "cli_test",
  "particle_radius": 0.05,
  "container": {"min": [0, 0, 0], "max": [1, 1, 1]},
  "fluid_blocks": [{"start": [0.1, 0.1, 0.1], "count": [3, 3, 3]}],
  "duration": 0.01
}"#;
    assert!(good.contains(from), "{from}");
    good.replace(from, to)
}

/// Asserts exit code 2 and a stderr starting with `error: ` that mentions every part.
fn assert_bad_input(out: &Output, parts: &[&str]) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "stderr: {stderr}");
    assert!(stderr.starts_with("error: "), "stderr: {stderr}");
    for part in parts {
        assert!(
            stderr.contains(part),
            "stderr {stderr:?} should mention {part:?}"
        );
    }
}

/// Writes `text` as a scene file and runs it for one step.
fn run_scene_text(dir: &Path, file: &str, text: &str) -> Output {
    let path = dir.join(file);
    std::fs::write(&path, text).unwrap();
    projfluid(&["run", path.to_str().unwrap(), "--steps", "1"])
}

#[test]
fn bad_scene_files_exit_2_naming_field_and_value() {
    let dir = temp_dir("bad-scenes");
    let cases: [(&str, String, &[&str]); 5] = [
        (
            "missing.json",
            scene_with(",\n  \"duration\": 0.01", ""),
            &["missing.json", "missing field `duration`"],
        ),
        (
            "negative.json",
            scene_with("0.05", "-0.1"),
            &["negative.json", "particle_radius", "-0.1"],
        ),
        (
            "outside.json",
            scene_with("[3, 3, 3]", "[3, 30, 3]"),
            &[
                "outside.json",
                "fluid_blocks[0]",
                "outside the container",
                "max y 3.0",
            ],
        ),
        (
            "unknown.json",
            scene_with("\"duration\"", "\"foo\": 1, \"duration\""),
            &["unknown.json", "unknown field `foo`", "line 6"],
        ),
        (
            "malformed.json",
            scene_with("\"duration\": 0.01", "\"duration\" 0.01"),
            &["malformed.json", "line 6", "column", "invalid JSON"],
        ),
    ];
    for (file, text, parts) in cases {
        assert_bad_input(&run_scene_text(&dir, file, &text), parts);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn missing_scenes_exit_2() {
    let missing = std::env::temp_dir().join("projfluid-no-such-dir/scene.json");
    let missing = missing.to_str().unwrap();
    assert_bad_input(
        &projfluid(&["run", missing, "--steps", "1"]),
        &[missing, "does not exist"],
    );
    assert_bad_input(
        &projfluid(&["run", "dam_break_huge", "--steps", "1"]),
        &["dam_break_huge", "dam_break_small", "dam_break_30k"],
    );
}

#[test]
fn bad_option_values_exit_2_naming_option_and_value() {
    let cases: [(&[&str], &[&str]); 7] = [
        (&["--rho", "1.5"], &["--rho", "1.5"]),
        (&["--rho", "fast"], &["--rho", "fast", "auto"]),
        (&["--tau", "-1"], &["--tau", "-1"]),
        (&["--every", "0"], &["--every", "0"]),
        (&["--steps", "0"], &["--steps", "0"]),
        (&["--duration", "-2"], &["--duration", "-2"]),
        (&["--solver", "sor"], &["--solver", "sor"]),
    ];
    for (options, parts) in cases {
        let mut args = vec!["run", "dam_break_small"];
        args.extend_from_slice(options);
        assert_bad_input(&projfluid(&args), parts);
    }
}

#[test]
fn steps_and_duration_are_exclusive() {
    let out = projfluid(&[
        "run",
        "dam_break_small",
        "--steps",
        "2",
        "--duration",
        "0.1",
    ]);
    assert_bad_input(&out, &["--steps", "--duration"]);
}

#[test]
fn short_run_writes_stats_and_frames() {
    let dir = temp_dir("good-run");
    let stats = dir.join("stats.json");
    let frames = dir.join("frames");
    let out = projfluid(&[
        "run",
        "dam_break_small",
        "--steps",
        "3",
        "--threads",
        "2",
        "--stats",
        stats.to_str().unwrap(),
        "--out",
        frames.to_str().unwrap(),
        "--every",
        "1",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    for row in [
        "dam_break_small",
        "chebyshev",
        "backend                cpu (double precision)",
        "3840",
        "escaped",
        "NaN",
    ] {
        assert!(
            stdout.contains(row),
            "summary {stdout:?} should mention {row:?}"
        );
    }

    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    let keys = [
        "scene",
        "solver",
        "backend",
        "rho",
        "tau",
        "coarse_correction",
        "kinematic_viscosity",
        "no_slip",
        "vorticity_confinement",
        "surface_tension",
        "threads",
        "particles",
        "boundary_particles",
        "steps",
        "sim_time",
        "wall_ms_per_step",
        "outer_iterations_mean",
        "density_error_avg_percent",
        "density_error_max_percent",
        "escaped",
        "nan",
        "positions_hash",
        "ms_per_step_breakdown",
    ];
    for key in keys {
        assert!(json.get(key).is_some(), "stats lack {key}: {json}");
    }
    assert_eq!(json["scene"], "dam_break_small");
    assert_eq!(json["solver"], "chebyshev");
    assert_eq!(json["backend"], "cpu");
    assert_eq!(json["particles"], 3840);
    assert_eq!(json["steps"], 3);
    assert_eq!(json["threads"], 2);
    assert_eq!(json["coarse_correction"], false);
    assert_eq!(json["kinematic_viscosity"], 0.0);
    assert_eq!(json["no_slip"], true);
    assert_eq!(json["vorticity_confinement"], 0.0);
    assert_eq!(json["surface_tension"], 0.0);
    assert_eq!(json["nan"], 0);

    let mut names: Vec<String> = std::fs::read_dir(&frames)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "frame_00000.vtp",
            "frame_00001.vtp",
            "frame_00002.vtp",
            "frame_00003.vtp",
            "frames.csv",
            "frames.pvd"
        ]
    );
    // VTK XML frames are the default.
    let last = std::fs::read_to_string(frames.join("frame_00003.vtp")).unwrap();
    assert!(last.starts_with("<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\""));
    assert!(
        last.contains("<Piece NumberOfPoints=\"3840\""),
        "{last:.400}"
    );
    // One liquid: no material array.
    assert!(!last.contains("Name=\"material\""));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The frames of a scene with several liquids hold each particle's material.
#[test]
fn frames_of_several_liquids_hold_the_materials() {
    let dir = temp_dir("frames-materials");
    let frames = dir.join("frames");
    let out = projfluid(&[
        "run",
        "oil_on_water",
        "--steps",
        "1",
        "--threads",
        "2",
        "--out",
        frames.to_str().unwrap(),
        "--format",
        "vtk-ascii",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(frames.join("frame_00000.vtk")).unwrap();
    let at = text
        .find("SCALARS material int 1")
        .expect("a material array");
    let ids: Vec<&str> = text[at..]
        .lines()
        .skip(2)
        .filter(|l| !l.trim().is_empty())
        .collect();
    assert!(
        ids.iter().all(|l| ["0", "1"].contains(&l.trim())),
        "{ids:?}"
    );
    assert!(ids.iter().any(|l| l.trim() == "0") && ids.iter().any(|l| l.trim() == "1"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Runs the binary with `args`, asserts it succeeded, and returns the JSON of the
/// `--stats` file `stats` it wrote.
fn run_ok_with_stats(args: &[&str], stats: &Path) -> serde_json::Value {
    let out = projfluid(args);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_str(&std::fs::read_to_string(stats).unwrap()).unwrap()
}

/// The TIME field of a binary VTK frame written by `projfluid run` (s).
fn vtk_time(path: &Path) -> f64 {
    let bytes = std::fs::read(path).unwrap();
    let key = b"TIME 1 1 double\n";
    let at = bytes
        .windows(key.len())
        .position(|w| w == key)
        .expect("TIME")
        + key.len();
    f64::from_be_bytes(bytes[at..at + 8].try_into().unwrap())
}

/// The `comment time` of a PLY frame (s).
fn ply_time(path: &Path) -> f64 {
    let bytes = std::fs::read(path).unwrap();
    let text = String::from_utf8_lossy(&bytes[..bytes.len().min(400)]).into_owned();
    let line = text
        .lines()
        .find(|l| l.starts_with("comment time "))
        .expect("time");
    line["comment time ".len()..].parse().unwrap()
}

/// With `--fps` the frames land on the multiples of 1/fps exactly, and `frames.csv`, the
/// frames' TIME fields and the summary's simulated time agree; with `--every` the frames
/// carry the times of their steps, which `frames.csv` lists too. A resumed run continues the
/// index where the checkpoint stood.
#[test]
fn frames_carry_their_simulated_times() {
    let dir = temp_dir("frame-times");
    let (frames, stats) = (dir.join("frames"), dir.join("stats.json"));
    let (frames_arg, stats_arg) = (frames.to_str().unwrap(), stats.to_str().unwrap());
    let json = run_ok_with_stats(
        &[
            "run",
            "dam_break_small",
            "--duration",
            "0.09",
            "--fps",
            "50",
            "--format",
            "vtk",
            "--out",
            frames_arg,
            "--stats",
            stats_arg,
        ],
        &stats,
    );
    let (header, rows) = read_csv(&frames.join("frames.csv"));
    assert_eq!(header, ["frame", "step", "time"]);
    // Frames at 0, 0.02, …, 0.08; the run ends at 0.09, between frames.
    assert_eq!(rows.len(), 5);
    let mut last_step = -1.0;
    for (k, row) in rows.iter().enumerate() {
        let time = number(&header, row, "time");
        assert_eq!(row[0], k.to_string());
        assert_eq!(time, k as f64 / 50.0, "frame {k}");
        assert_eq!(vtk_time(&frames.join(format!("frame_{k:05}.vtk"))), time);
        let step = number(&header, row, "step");
        assert!(step > last_step, "steps rise: {rows:?}");
        last_step = step;
    }
    assert_eq!(json["sim_time"], 0.09);
    assert!(json["steps"].as_f64().unwrap() > last_step, "{json}");

    let ascii = dir.join("ascii");
    let json = run_ok_with_stats(
        &[
            "run",
            "dam_break_small",
            "--steps",
            "2",
            "--every",
            "2",
            "--format",
            "vtk-ascii",
            "--out",
            ascii.to_str().unwrap(),
            "--stats",
            stats_arg,
        ],
        &stats,
    );
    let text = std::fs::read_to_string(ascii.join("frame_00001.vtk")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[2], "ASCII");
    assert_eq!(lines[5], "TIME 1 1 double");
    assert_eq!(
        lines[6].parse::<f64>().unwrap(),
        json["sim_time"].as_f64().unwrap()
    );
    assert!(lines.contains(&"POINTS 3840 float"));

    let ply = dir.join("ply");
    let checkpoints = dir.join("checkpoints");
    let json = run_ok_with_stats(
        &[
            "run",
            "dam_break_small",
            "--steps",
            "6",
            "--every",
            "2",
            "--format",
            "ply",
            "--out",
            ply.to_str().unwrap(),
            "--checkpoint-every",
            "4",
            "--checkpoint-dir",
            checkpoints.to_str().unwrap(),
            "--stats",
            stats_arg,
        ],
        &stats,
    );
    let (header, rows) = read_csv(&ply.join("frames.csv"));
    assert_eq!(rows.len(), 4);
    for (k, row) in rows.iter().enumerate() {
        assert_eq!(number(&header, row, "step"), 2.0 * k as f64);
        let time = number(&header, row, "time");
        assert_eq!(ply_time(&ply.join(format!("frame_{k:05}.ply"))), time);
    }
    assert_eq!(
        number(&header, &rows[3], "time"),
        json["sim_time"].as_f64().unwrap()
    );
    let full = std::fs::read_to_string(ply.join("frames.csv")).unwrap();
    // Resuming from step 4 keeps frames 0–2 and writes frame 3 (step 6) again, bit for bit.
    let checkpoint = checkpoints.join("checkpoint_000004.pfck");
    run_ok_with_stats(
        &[
            "run",
            "--resume",
            checkpoint.to_str().unwrap(),
            "--every",
            "2",
            "--format",
            "ply",
            "--out",
            ply.to_str().unwrap(),
            "--stats",
            stats_arg,
        ],
        &stats,
    );
    assert_eq!(
        std::fs::read_to_string(ply.join("frames.csv")).unwrap(),
        full
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The TIME field of a VTK XML frame written by `projfluid run` (s): one Float64 in an
/// inline base64 array, after its UInt64 byte count.
fn vtp_time(path: &Path) -> f64 {
    use base64::Engine;
    let text = std::fs::read_to_string(path).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    let array = doc
        .descendants()
        .find(|n| n.has_tag_name("DataArray") && n.attribute("Name") == Some("TIME"))
        .expect("TIME");
    assert_eq!(array.parent().unwrap().tag_name().name(), "FieldData");
    let base64 = array.text().unwrap().trim();
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(base64)
        .unwrap();
    assert_eq!(bytes.len(), 16, "{base64}");
    assert_eq!(u64::from_le_bytes(bytes[..8].try_into().unwrap()), 8);
    f64::from_le_bytes(bytes[8..].try_into().unwrap())
}

/// The `(timestep, file)` of every data set a `.pvd` collection lists.
fn read_pvd(path: &Path) -> Vec<(f64, String)> {
    let text = std::fs::read_to_string(path).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    assert_eq!(doc.root_element().attribute("type"), Some("Collection"));
    doc.descendants()
        .filter(|n| n.has_tag_name("DataSet"))
        .map(|n| {
            let time = n.attribute("timestep").unwrap().parse().unwrap();
            (time, n.attribute("file").unwrap().to_string())
        })
        .collect()
}

/// Every file in `dir` with its bytes, by name.
fn files_in(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            let name = e.file_name().to_string_lossy().into_owned();
            (name, std::fs::read(e.path()).unwrap())
        })
        .collect();
    files.sort();
    files
}

/// With VTK XML frames `frames.pvd` lists every frame file there is, at the time that
/// `frames.csv` and the frame's own TIME field give. A run interrupted after a later frame
/// and resumed from an earlier checkpoint writes the frames after the checkpoint again and
/// continues index and collection, ending with the files of the uninterrupted run.
#[test]
fn pvd_lists_every_frame_at_its_time_and_resumes() {
    let dir = temp_dir("pvd");
    let (frames, checkpoints) = (dir.join("frames"), dir.join("checkpoints"));
    let stats = dir.join("stats.json");
    let output = [
        "--fps",
        "50",
        "--format",
        "vtp",
        "--out",
        frames.to_str().unwrap(),
        "--stats",
        stats.to_str().unwrap(),
    ];
    let mut args = vec!["run", "dam_break_small", "--duration", "0.09"];
    args.extend(output);
    args.extend(["--checkpoint-every", "4", "--checkpoint-dir"]);
    args.push(checkpoints.to_str().unwrap());
    let json = run_ok_with_stats(&args, &stats);
    assert_eq!(json["sim_time"], 0.09);

    let (header, rows) = read_csv(&frames.join("frames.csv"));
    let datasets = read_pvd(&frames.join("frames.pvd"));
    // Frames at 0, 0.02, …, 0.08.
    assert_eq!(rows.len(), 5);
    let listed: Vec<&str> = datasets.iter().map(|(_, f)| f.as_str()).collect();
    let full = files_in(&frames);
    let written: Vec<&str> = full
        .iter()
        .map(|(name, _)| name.as_str())
        .filter(|name| name.ends_with(".vtp"))
        .collect();
    assert_eq!(listed, written);
    for (k, (row, (time, file))) in rows.iter().zip(&datasets).enumerate() {
        assert_eq!(*file, format!("frame_{k:05}.vtp"));
        assert_eq!(*time, number(&header, row, "time"), "frame {k}");
        assert_eq!(*time, k as f64 / 50.0, "frame {k}");
        assert_eq!(vtp_time(&frames.join(file)), *time, "frame {k}");
    }

    // The state of the run stopped just after writing frame 3: no frame 4, and index and
    // collection ending at frame 3.
    let step = |k: usize| number(&header, &rows[k], "step") as u64;
    std::fs::remove_file(frames.join("frame_00004.vtp")).unwrap();
    let csv = std::fs::read_to_string(frames.join("frames.csv")).unwrap();
    let csv: Vec<&str> = csv.lines().take(1 + 4).collect();
    std::fs::write(frames.join("frames.csv"), csv.join("\n") + "\n").unwrap();
    let pvd = std::fs::read_to_string(frames.join("frames.pvd")).unwrap();
    let pvd: Vec<&str> = pvd
        .lines()
        .filter(|l| !l.contains("frame_00004.vtp"))
        .collect();
    std::fs::write(frames.join("frames.pvd"), pvd.join("\n") + "\n").unwrap();
    assert_eq!(read_pvd(&frames.join("frames.pvd")).len(), 4);
    // Resumed from the first checkpoint after frame 1, before frame 2: frames 2 and 3 are
    // written again and frame 4 is new.
    let saved = (step(1) + 1..step(2))
        .map(|s| checkpoints.join(format!("checkpoint_{s:06}.pfck")))
        .find(|path| path.exists())
        .expect("a checkpoint between frames 1 and 2");
    let mut args = vec!["run", "--resume", saved.to_str().unwrap()];
    args.extend(output);
    run_ok_with_stats(&args, &stats);
    let resumed = files_in(&frames);
    let names = |files: &[(String, Vec<u8>)]| -> Vec<String> {
        files.iter().map(|(name, _)| name.clone()).collect()
    };
    assert_eq!(names(&resumed), names(&full));
    for ((name, bytes), (_, expected)) in resumed.iter().zip(&full) {
        assert!(
            bytes == expected,
            "{name} differs from the uninterrupted run's"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn unwritable_output_exits_1() {
    let dir = temp_dir("unwritable");
    let blocker = dir.join("file");
    std::fs::write(&blocker, "not a directory").unwrap();
    let out = projfluid(&[
        "run",
        "dam_break_small",
        "--steps",
        "1",
        "--out",
        blocker.join("frames").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.starts_with("error: ") && stderr.contains("frames"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn scenes_lists_builtins_with_particle_counts() {
    let out = projfluid(&["scenes"]);
    assert_eq!(out.status.code(), Some(0));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("dam_break_small") && stdout.contains("3840"),
        "{stdout}"
    );
    assert!(
        stdout.contains("dam_break_30k") && stdout.contains("30000"),
        "{stdout}"
    );
}

/// `--coarse-correction` takes `on` or `off` and replaces the scene's
/// `solver.coarse_correction`, which the summary and the stats report; any other value is
/// refused naming the option.
#[test]
fn coarse_correction_is_switched_on_or_off() {
    let run = |value: &str, stats: &Path| {
        projfluid(&[
            "run",
            "dam_break_small",
            "--steps",
            "2",
            "--coarse-correction",
            value,
            "--stats",
            stats.to_str().unwrap(),
        ])
    };
    let dir = temp_dir("coarse-correction");
    let stats = dir.join("stats.json");
    assert_bad_input(
        &run("maybe", &stats),
        &["--coarse-correction", "maybe", "on", "off"],
    );
    assert!(!stats.exists(), "a refused run wrote {}", stats.display());
    for (value, on) in [("off", false), ("on", true)] {
        let out = run(value, &stats);
        assert_eq!(
            out.status.code(),
            Some(0),
            "--coarse-correction {value}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            stdout.contains(&format!("coarse correction {value}")),
            "{stdout}"
        );
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
        assert_eq!(json["coarse_correction"], on, "{json}");
        assert_eq!(json["steps"], 2);
        assert_eq!(json["nan"], 0);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--kinematic-viscosity` and `--no-slip` replace the scene's `kinematic_viscosity` and
/// `no_slip`, which the summary and the stats report and the run feels (no-slip walls under a
/// viscosity give another final state than free-slip ones or none); a negative, not-a-number or non-numeric viscosity and a switch other
/// than `on` or `off` are refused naming the option, before any stats are written.
#[test]
fn kinematic_viscosity_and_no_slip_reach_the_run() {
    let dir = temp_dir("kinematic-viscosity");
    let stats = dir.join("stats.json");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "run",
            "dam_break_small",
            "--steps",
            "3",
            "--threads",
            "1",
            "--stats",
            stats.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        projfluid(&args)
    };
    for (bad, parts) in [
        (
            ["--kinematic-viscosity", "-0.001"],
            &[
                "--kinematic-viscosity must be finite and not negative",
                "-0.001",
            ][..],
        ),
        (
            ["--kinematic-viscosity", "nan"],
            &[
                "--kinematic-viscosity must be finite and not negative",
                "NaN",
            ],
        ),
        (
            ["--kinematic-viscosity", "honey"],
            &["--kinematic-viscosity", "honey"],
        ),
        (["--no-slip", "2"], &["--no-slip", "'2'", "on", "off"]),
    ] {
        assert_bad_input(&run(&bad), parts);
        assert!(!stats.exists(), "a refused run wrote {}", stats.display());
    }
    let stats_of = |out: &Output, summary: &str| {
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(stdout.contains(summary), "{stdout}");
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
        assert_eq!((&json["steps"], &json["nan"]), (&3.into(), &0.into()));
        json
    };
    let water = stats_of(&run(&[]), "kinematic viscosity    off (no-slip walls)");
    let honey = stats_of(
        &run(&["--kinematic-viscosity", "0.01", "--no-slip", "off"]),
        "kinematic viscosity    1.000e-2 m²/s, free-slip walls",
    );
    assert_eq!(honey["kinematic_viscosity"], 0.01, "{honey}");
    assert_eq!(honey["no_slip"], false, "{honey}");
    // The block's first steps are a uniform fall, which only walls that hold it can shear.
    let held = stats_of(
        &run(&["--kinematic-viscosity", "0.01", "--no-slip", "on"]),
        "kinematic viscosity    1.000e-2 m²/s, no-slip walls",
    );
    assert_eq!(held["no_slip"], true, "{held}");
    assert_ne!(held["positions_hash"], water["positions_hash"]);
    assert_ne!(held["positions_hash"], honey["positions_hash"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--surface-tension` replaces the scene's `surface_tension`, which the summary and the
/// stats report and the run feels (another final state than without); a negative or too
/// large one is refused naming the option, before any stats are written.
#[test]
fn surface_tension_reaches_the_run() {
    let dir = temp_dir("surface-tension");
    let stats = dir.join("stats.json");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "run",
            "dam_break_small",
            "--steps",
            "3",
            "--threads",
            "1",
            "--stats",
            stats.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        projfluid(&args)
    };
    for value in ["-0.07", "11"] {
        assert_bad_input(
            &run(&["--surface-tension", value]),
            &["--surface-tension must be finite and not negative", value],
        );
        assert!(!stats.exists(), "a refused run wrote {}", stats.display());
    }
    let hash = |extra: &[&str], summary: &str| {
        let out = run(extra);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(stdout.contains(summary), "{stdout}");
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
        (
            json["surface_tension"].clone(),
            json["positions_hash"].clone(),
        )
    };
    let (plain, water) = hash(&[], "surface tension        off");
    let (sigma, tense) = hash(
        &["--surface-tension", "0.07"],
        "surface tension        0.07 N/m",
    );
    assert_eq!((plain, sigma), (0.0.into(), 0.07.into()));
    assert_ne!(water, tense);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--rho auto` estimates ρ_c online: the summary and the stats say so and report the mean
/// estimate, which lies in the clamped range rather than at the starting value. Options given
/// with it reach the world (`--threads 1` on any machine).
#[test]
fn rho_auto_runs_and_reports_its_estimate() {
    let dir = temp_dir("rho-auto");
    let stats = dir.join("stats.json");
    let out = projfluid(&[
        "run",
        "dam_break_small",
        "--steps",
        "60",
        "--rho",
        "auto",
        "--threads",
        "1",
        // The displacement rule alone with a tight τ makes the steps long enough to measure
        // the contraction.
        "--eta",
        "0",
        "--tau",
        "2.5e-6",
        "--stats",
        stats.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    assert!(String::from_utf8_lossy(&out.stdout).contains("rho auto"));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    assert_eq!(json["rho_auto"], true);
    // The options reach the world that runs.
    assert_eq!(json["threads"], 1);
    let rho = json["rho"].as_f64().unwrap();
    // The mean over the steps: the starting value 0.99 until the first estimate, then
    // estimates within [0.5, 0.925].
    assert!((0.5..0.95).contains(&rho), "mean rho {rho}");
}

/// Asserts that `path` holds a PNG image.
fn assert_png(path: &Path) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(
        bytes.starts_with(b"\x89PNG\r\n\x1a\n"),
        "{}",
        path.display()
    );
}

/// Parses a CSV file written by `bench` or `tune-rho` into a header and rows of cells.
fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text
        .lines()
        .map(|l| l.split(',').map(String::from).collect());
    let header: Vec<String> = lines.next().unwrap();
    let rows: Vec<Vec<String>> = lines.collect();
    assert!(rows.iter().all(|r| r.len() == header.len()), "{text}");
    (header, rows)
}

/// The cell of `row` under `column`, parsed as a number.
fn number(header: &[String], row: &[String], column: &str) -> f64 {
    let i = header.iter().position(|h| h == column).unwrap();
    row[i]
        .parse()
        .unwrap_or_else(|_| panic!("{column}: {:?}", row[i]))
}

/// On formulation F1 the exact global solvers follow one trajectory, so over the first steps
/// they need the same outer iterations. (cg1 is not exact in general, but on these first
/// steps the diagonal is the same for nearly every particle the iteration moves, the
/// membership floor's, and one CG iteration is exact too; the physics tests show it differ.)
#[test]
fn bench_writes_one_consistent_row_per_scene_and_solver() {
    let dir = temp_dir("bench");
    let out_dir = dir.join("out");
    let out = projfluid(&[
        "bench",
        "--scenes",
        "dam_break_small",
        // Eight steps: later, round-off differences between the exact solvers (1e-10 of
        // ‖b‖) can move a stopping decision by one iteration.
        "--steps",
        "8",
        "--threads",
        "1",
        // The displacement rule alone, with the online ρ_c it goes with: every solver then
        // converges to the same τ.
        "--eta",
        "0",
        "--rho",
        "auto",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    let markdown = std::fs::read_to_string(out_dir.join("bench.md")).unwrap();
    assert_eq!(String::from_utf8_lossy(&out.stdout), markdown);
    assert_eq!(markdown.lines().count(), 2 + 6);
    let (header, rows) = read_csv(&out_dir.join("bench.csv"));
    let solvers: Vec<&str> = rows.iter().map(|r| r[1].as_str()).collect();
    assert_eq!(
        solvers,
        ["chebyshev", "jacobi1", "jacobi", "cg", "cg1", "ldlt"]
    );
    let outer = |solver: &str| {
        let row = &rows[solvers.iter().position(|s| *s == solver).unwrap()];
        number(&header, row, "outer_iterations_mean")
    };
    for row in &rows {
        assert_eq!(row[0], "dam_break_small");
        assert_eq!(number(&header, row, "particles"), 3840.0);
        assert_eq!(number(&header, row, "steps"), 8.0);
        assert!(number(&header, row, "ms_per_step") > 0.0);
        let avg = number(&header, row, "density_error_avg_percent");
        let max = number(&header, row, "density_error_max_percent");
        assert!(0.0 < avg && avg <= max && max < 1.0, "{row:?}");
        assert_eq!(number(&header, row, "max_iteration_hits"), 0.0);
        assert_eq!(number(&header, row, "energy_rise_percent"), 0.0);
        assert_eq!(row.last().unwrap(), "none");
    }
    assert!(
        outer("jacobi1") > 1.0,
        "the scene must exercise the constraint"
    );
    for exact in ["jacobi", "cg", "ldlt"] {
        assert_eq!(outer(exact), outer("jacobi1"), "{exact}");
    }
    // One Jacobi sweep or CG iteration per outer iteration; converged CG needs one or more,
    // more where the diagonal varies.
    let inner = |i: usize| number(&header, &rows[i], "inner_iterations_mean");
    assert_eq!(inner(1), outer("jacobi1"));
    assert_eq!(inner(4), outer("cg1"));
    assert!(inner(3) > outer("cg"));
    assert_png(&out_dir.join("bench.png"));
    assert_png(&out_dir.join("bench_iterations.png"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A stopping threshold of half a particle radius leaves the fluid visibly compressed; the
/// artifacts rule must say so.
#[test]
fn bench_flags_artifacts_of_a_far_too_loose_tolerance() {
    let dir = temp_dir("bench-loose");
    let out = projfluid(&[
        "bench",
        "--scenes",
        "dam_break_small",
        "--solvers",
        "jacobi1",
        "--steps",
        "30",
        "--tau",
        "0.0125",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0));
    let (header, rows) = read_csv(&dir.join("bench.csv"));
    assert_eq!(rows.len(), 1);
    assert!(number(&header, &rows[0], "density_error_max_percent") > 3.0);
    assert!(
        rows[0].last().unwrap().contains("max density error"),
        "{:?}",
        rows[0]
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bench_and_tune_rho_reject_bad_options_with_exit_2() {
    let cases: [(&[&str], &[&str]); 11] = [
        (&["bench", "--steps", "0"], &["--steps", "0"]),
        (
            &["bench", "--kinematic-viscosity", "-1"],
            &[
                "--kinematic-viscosity",
                "must be finite and not negative",
                "-1",
            ],
        ),
        (
            &["bench", "--no-slip", "yes"],
            &["--no-slip", "yes", "on", "off"],
        ),
        (&["bench", "--scenes", "dam_break_small,nope"], &["nope"]),
        (&["bench", "--solvers", "cg,sor"], &["--solvers", "sor"]),
        (&["bench", "--rho", "1.5"], &["--rho", "1.5"]),
        (&["bench", "--tau", "0"], &["--tau", "0"]),
        (&["tune-rho", "nope"], &["nope"]),
        (
            &["tune-rho", "dam_break_small", "--from", "-0.1"],
            &["--from", "-0.1"],
        ),
        (
            &[
                "tune-rho",
                "dam_break_small",
                "--from",
                "0.9",
                "--to",
                "0.8",
            ],
            &["--to", "0.8"],
        ),
        (
            &["tune-rho", "dam_break_small", "--steps", "0"],
            &["--steps", "0"],
        ),
    ];
    for (args, parts) in cases {
        assert_bad_input(&projfluid(args), parts);
    }
}

#[test]
fn tune_rho_writes_a_row_per_rho_and_names_the_choice() {
    let dir = temp_dir("tune-rho");
    let out = projfluid(&[
        "tune-rho",
        "dam_break_small",
        "--warmup",
        "3",
        "--steps",
        "2",
        "--from",
        "0.8",
        "--to",
        "0.9",
        "--step",
        "0.1",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("best rho: "), "{stdout}");
    assert!(stdout.contains("rho auto: "), "{stdout}");
    assert_eq!(
        std::fs::read_to_string(dir.join("tune_rho.md")).unwrap(),
        stdout
    );
    let (header, rows) = read_csv(&dir.join("tune_rho.csv"));
    let labels: Vec<&str> = rows.iter().map(|r| r[0].as_str()).collect();
    assert_eq!(labels, ["plain", "0.8", "0.9", "auto"]);
    for row in &rows {
        assert!(number(&header, row, "outer_iterations_mean") >= 1.0);
    }
    assert_png(&dir.join("tune_rho_time.png"));
    assert_png(&dir.join("tune_rho_iterations.png"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn png_pictures_are_written_at_the_frame_interval() {
    let dir = temp_dir("png");
    let pictures = dir.join("pictures");
    let out = projfluid(&[
        "run",
        "dam_break_small",
        "--steps",
        "4",
        "--every",
        "2",
        "--png",
        pictures.to_str().unwrap(),
        "--png-width",
        "160",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut names: Vec<String> = std::fs::read_dir(&pictures)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "frame_00000.png",
            "frame_00001.png",
            "frame_00002.png",
            "frames.csv"
        ]
    );
    let decoder = png::Decoder::new(std::fs::File::open(pictures.join("frame_00002.png")).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (160, 90));
    // The fluid is drawn: many pixels are bluish, unlike the grey background.
    let blue = buf[..info.buffer_size()]
        .chunks_exact(3)
        .filter(|p| p[2] > 120 && p[2] > p[0] + 40)
        .count();
    assert!(blue > 100, "{blue} blue pixels");
    let out = projfluid(&["run", "dam_break_small", "--steps", "1", "--png-width", "3"]);
    assert_bad_input(&out, &["--png-width", "3"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn ply_frames_hold_every_particle_with_velocity_and_density() {
    let dir = temp_dir("ply");
    let frames = dir.join("frames");
    let out = projfluid(&[
        "run",
        "dam_break_small",
        "--steps",
        "2",
        "--every",
        "2",
        "--out",
        frames.to_str().unwrap(),
        "--format",
        "ply",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(frames.join("frame_00001.ply")).unwrap();
    assert!(!frames.join("frame_00000.vtk").exists());
    let end = b"end_header\n";
    let split = bytes.windows(end.len()).position(|w| w == end).unwrap() + end.len();
    let header = std::str::from_utf8(&bytes[..split]).unwrap();
    let n = 16 * 20 * 12;
    assert!(
        header.contains(&format!("element vertex {n}\n")),
        "{header}"
    );
    assert!(
        header.contains("format binary_little_endian 1.0"),
        "{header}"
    );
    assert_eq!(bytes.len() - split, n * 7 * 4);
    let floats: Vec<f32> = bytes[split..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    // After two steps from rest everything falls (vy < 0); densities are about that of water
    // (lower at the free surface and corners).
    for record in floats.chunks_exact(7) {
        assert!(
            (0.0..2.1).contains(&record[0]) && record[4] < 0.0,
            "{record:?}"
        );
        assert!((500.0..1100.0).contains(&record[6]), "{record:?}");
    }
    let out = projfluid(&["run", "dam_break_small", "--steps", "1", "--format", "obj"]);
    assert_eq!(out.status.code(), Some(2));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The `positions_hash` of a `--stats` file.
fn stats_hash(path: &Path) -> String {
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    json["positions_hash"].as_str().unwrap().to_string()
}

/// Runs projfluid with `args` plus `--stats FILE` and returns that file's positions hash.
fn run_for_hash(dir: &Path, name: &str, args: &[&str]) -> String {
    let stats = dir.join(format!("{name}.json"));
    let mut all = args.to_vec();
    all.extend(["--stats", stats.to_str().unwrap()]);
    let out = projfluid(&all);
    assert!(
        out.status.success(),
        "{name}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    stats_hash(&stats)
}

/// A run with bodies (a scripted paddle, a dynamic box and a static mesh read from an OBJ
/// file next to the scene) resumes bit for bit: the bodies are rebuilt from the scene.
#[test]
fn resumed_runs_with_bodies_equal_uninterrupted_runs() {
    let dir = temp_dir("resume-bodies");
    std::fs::write(
        dir.join("wedge.obj"),
        "v 0 0 0\nv 0.2 0 0\nv 0 0.2 0\nv 0 0 0.2\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    )
    .unwrap();
    let scene = dir.join("tank.json");
    std::fs::write(
        &scene,
        r#"{
  "particle_radius": 0.025,
  "container": {"min": [0, 0, 0], "max": [1.0, 0.8, 0.4]},
  "fluid_blocks": [{"start": [0.2, 0.05, 0.05], "count": [8, 5, 7]}],
  "bodies": [
    {"kind": "kinematic", "box": {"half_extents": [0.01, 0.35, 0.19]}, "position": [0.1, 0.4, 0.2],
     "motion": {"amplitude": [0.04, 0, 0], "period": 0.4}},
    {"kind": "dynamic", "box": {"half_extents": [0.05, 0.04, 0.05]}, "density": 500,
     "position": [0.4, 0.5, 0.2]},
    {"kind": "static", "mesh": {"obj": "wedge.obj"}, "position": [0.75, 0.0, 0.1]}
  ],
  "duration": 1
}"#,
    )
    .unwrap();
    let ckpt = dir.join("ckpt");
    let base = ["run", scene.to_str().unwrap(), "--steps", "24"];
    let whole = run_for_hash(&dir, "whole", &base);
    let mut with_checkpoints = base.to_vec();
    with_checkpoints.extend(["--checkpoint-every", "12", "--checkpoint-dir"]);
    with_checkpoints.push(ckpt.to_str().unwrap());
    assert_eq!(run_for_hash(&dir, "saved", &with_checkpoints), whole);
    let file = ckpt.join("checkpoint_000012.pfck");
    let resumed = run_for_hash(
        &dir,
        "resumed",
        &["run", "--resume", file.to_str().unwrap(), "--threads", "1"],
    );
    assert_eq!(resumed, whole, "the resumed run differs");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn resumed_runs_equal_uninterrupted_runs_bit_for_bit() {
    let dir = temp_dir("resume");
    let ckpt = dir.join("ckpt");
    let ckpt_dir = ckpt.to_str().unwrap();
    for (label, length) in [
        ("steps", ["--steps", "30"]),
        ("time", ["--duration", "0.09"]),
    ] {
        let mut base = vec!["run", "dam_break_small"];
        base.extend(length);
        let whole = run_for_hash(&dir, &format!("{label}-whole"), &base);
        let mut with_checkpoints = base.clone();
        with_checkpoints.extend(["--checkpoint-every", "12", "--checkpoint-dir", ckpt_dir]);
        let saved = run_for_hash(&dir, &format!("{label}-saved"), &with_checkpoints);
        assert_eq!(saved, whole, "{label}: writing checkpoints changed the run");
        let file = ckpt.join("checkpoint_000012.pfck");
        if label == "steps" {
            assert!(ckpt.join("checkpoint_000024.pfck").exists());
        }
        // Resumed on another thread count, the run goes on to the same end.
        let resumed = run_for_hash(
            &dir,
            &format!("{label}-resumed"),
            &["run", "--resume", file.to_str().unwrap(), "--threads", "1"],
        );
        assert_eq!(resumed, whole, "{label}: the resumed run differs");
        std::fs::remove_dir_all(&ckpt).unwrap();
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn damaged_checkpoints_exit_2_with_a_clear_message() {
    let dir = temp_dir("bad-checkpoint");
    let ckpt = dir.join("ckpt");
    let out = projfluid(&[
        "run",
        "dam_break_small",
        "--steps",
        "2",
        "--checkpoint-every",
        "2",
        "--checkpoint-dir",
        ckpt.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let good = std::fs::read(ckpt.join("checkpoint_000002.pfck")).unwrap();
    let bad = dir.join("bad.pfck");
    let bad_str = bad.to_str().unwrap();
    for (bytes, what) in [
        (&good[..good.len() / 2], "damaged or truncated"),
        (&good[..12], "truncated"),
        (
            &b"not a checkpoint at all"[..],
            "not a projfluid checkpoint",
        ),
    ] {
        std::fs::write(&bad, bytes).unwrap();
        let out = projfluid(&["run", "--resume", bad_str]);
        assert_bad_input(&out, &[bad_str, what]);
    }
    let out = projfluid(&["run", "--resume", dir.join("none.pfck").to_str().unwrap()]);
    assert_bad_input(&out, &["cannot read checkpoint", "none.pfck"]);
    let out = projfluid(&[
        "run",
        "dam_break_small",
        "--steps",
        "1",
        "--checkpoint-every",
        "0",
    ]);
    assert_bad_input(&out, &["--checkpoint-every", "0"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A small tank whose own `probes` (a gauge read at 50 Hz) the probes files replace; its walls
/// r/4 beyond one spacing from the water, so that no corner starts compressed.
const PROBE_TANK: &str = r#"{
  "particle_radius": 0.025,
  "container": {"min": [-0.00625, -0.00625, -0.00625], "max": [0.4, 0.4, 0.3]},
  "fluid_blocks": [{"start": [0.05, 0.05, 0.05], "count": [6, 4, 4]}],
  "duration": 0.05,
  "probes": {"rate": 50, "gauges": [{"name": "S", "x": 0.2, "z": 0.15}]}
}"#;

/// Two gauges, a probe in the fluid and one on a side wall, read at 200 Hz.
const PROBES: &str = r#"{
  "rate": 200,
  "gauges": [{"name": "H1", "x": 0.15, "z": 0.15}, {"name": "H2", "x": 0.25, "z": 0.15, "bottom": 0.0, "top": 0.35}],
  "pressure": [{"name": "P1", "position": [0.2, 0.06, 0.15]},
               {"name": "W1", "position": [-0.00625, 0.06, 0.15], "wall": true}]
}"#;

/// `--probes FILE` replaces the scene's probes and writes probes.csv beside the frames: a
/// header with units, a row at every multiple of 1/200 s exactly (frames at 1/60 s as
/// well), finite values; a resumed run continues the file to what an uninterrupted run
/// writes, bit for bit.
#[test]
fn probes_write_a_csv_at_their_rate_and_resume() {
    let dir = temp_dir("probes");
    let (scene, probes) = (dir.join("tank.json"), dir.join("probes.json"));
    std::fs::write(&scene, PROBE_TANK).unwrap();
    std::fs::write(&probes, PROBES).unwrap();
    let (whole, saved, ckpt) = (dir.join("whole"), dir.join("saved"), dir.join("ckpt"));
    let run = |out: &Path, extra: &[&str]| {
        let mut args = vec!["run", scene.to_str().unwrap(), "--probes"];
        args.extend([probes.to_str().unwrap(), "--fps", "60", "--out"]);
        args.push(out.to_str().unwrap());
        args.extend(extra);
        let out = projfluid(&args);
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(out.status.success(), "{stderr}");
        stderr
    };
    // At the default settings the pressure readings are not to be trusted, and the run says
    // so; solved tightly it does not.
    let warning = "warning: the pressure probes read the constraint forces";
    assert!(run(&whole, &[]).contains(warning));
    let tight = dir.join("tight");
    assert!(!run(&tight, &["--tau", "2.5e-7", "--eta", "0", "--steps", "1"]).contains(warning));
    let (header, rows) = read_csv(&whole.join("probes.csv"));
    assert_eq!(header, ["time_s", "H1_m", "H2_m", "P1_Pa", "W1_Pa"]);
    assert_eq!(rows.len(), 11, "{rows:?}");
    for (k, row) in rows.iter().enumerate() {
        assert_eq!(number(&header, row, "time_s"), k as f64 / 200.0, "row {k}");
        for column in &header[1..] {
            let value = number(&header, row, column);
            assert!(value.is_finite(), "{column} at row {k}: {value}");
        }
        for gauge in ["H1_m", "H2_m"] {
            let h = number(&header, row, gauge);
            assert!((0.1..=0.35).contains(&h), "{gauge} at row {k}: {h}");
        }
    }
    let (frame_header, frames) = read_csv(&whole.join("frames.csv"));
    for (k, row) in frames.iter().enumerate() {
        assert_eq!(number(&frame_header, row, "time"), k as f64 / 60.0);
    }
    assert_eq!(frames.len(), 4);

    run(
        &saved,
        &[
            "--checkpoint-every",
            "6",
            "--checkpoint-dir",
            ckpt.to_str().unwrap(),
        ],
    );
    let checkpoint = ckpt.join("checkpoint_000006.pfck");
    let out = projfluid(&["run", "--resume", checkpoint.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        std::fs::read_to_string(saved.join("probes.csv")).unwrap(),
        std::fs::read_to_string(whole.join("probes.csv")).unwrap()
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Bad probes exit 2 naming the file, the key and the value; so do probes without an output
/// directory.
#[test]
fn bad_probes_exit_2() {
    let dir = temp_dir("bad-probes");
    let scene = dir.join("tank.json");
    std::fs::write(&scene, PROBE_TANK).unwrap();
    let out_dir = dir.join("out");
    let run = |probes: &str, out: bool| {
        let path = dir.join("probes.json");
        std::fs::write(&path, probes).unwrap();
        let mut args = vec!["run", scene.to_str().unwrap(), "--steps", "1", "--probes"];
        args.push(path.to_str().unwrap());
        if out {
            args.extend(["--out", out_dir.to_str().unwrap()]);
        }
        projfluid(&args)
    };
    let duplicate = PROBES.replace("\"H2\"", "\"H1\"");
    assert_bad_input(
        &run(&duplicate, true),
        &["probes.json: probes.gauges[1].name must be unique", "`H1`"],
    );
    let inverted = PROBES.replace("\"top\": 0.35", "\"top\": -0.1");
    assert_bad_input(
        &run(&inverted, true),
        &["probes.gauges[1].bottom must lie below top (-0.1), got 0"],
    );
    assert_bad_input(
        &run("{\"rate\": 200, \"gauges\": [}", true),
        &["probes.json", "line 1", "invalid JSON"],
    );
    assert_bad_input(&run(PROBES, false), &["probes.csv", "--out"]);
    let fast = PROBES.replace("\"rate\": 200", "\"rate\": 1e5");
    assert_bad_input(
        &run(&fast, true),
        &["probes.rate must be at most 1/dt_min", "got 100000"],
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `projfluid probes` reads a scene's gauges on saved frames: on the frames of a run (VTK XML,
/// legacy VTK binary and ASCII) it reads what the run read at the same times, within the
/// rounding of the frames' single-precision positions; frames without a time of their own
/// need `--fps`, which numbers them k/fps; bad input exits 2 naming it.
#[test]
fn probes_read_on_saved_frames() {
    let dir = temp_dir("probes-frames");
    let scene = dir.join("tank.json");
    std::fs::write(&scene, PROBE_TANK).unwrap();
    let scene = scene.to_str().unwrap();
    for format in ["vtp", "vtk", "vtk-ascii"] {
        let out = dir.join(format);
        let args = ["run", scene, "--fps", "50", "--format", format, "--out"];
        let run = projfluid(&[&args[..], &[out.to_str().unwrap()]].concat());
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let csv = dir.join(format!("{format}.csv"));
        let (frames, csv_str) = (out.to_str().unwrap(), csv.to_str().unwrap());
        let read = projfluid(&["probes", scene, "--frames", frames, "--out", csv_str]);
        assert!(
            read.status.success(),
            "{}",
            String::from_utf8_lossy(&read.stderr)
        );
        let (header, rows) = read_csv(&csv);
        let (run_header, run_rows) = read_csv(&out.join("probes.csv"));
        assert_eq!(header, run_header);
        assert_eq!(rows.len(), run_rows.len());
        assert_eq!(rows.len(), 3, "{rows:?}");
        for (row, run_row) in rows.iter().zip(&run_rows) {
            let time = number(&header, row, "time_s");
            assert!((time - number(&header, run_row, "time_s")).abs() < 1e-12);
            let (h, run_h) = (number(&header, row, "S_m"), number(&header, run_row, "S_m"));
            assert!(
                (0.1..0.3).contains(&h) && (h - run_h).abs() < 1e-5,
                "{h} {run_h}"
            );
        }
    }
    // The same frames without their time: refused without --fps; numbered by it.
    let plain = dir.join("plain");
    std::fs::create_dir_all(&plain).unwrap();
    for k in 0..3 {
        let text = std::fs::read(dir.join(format!("vtk-ascii/frame_{k:05}.vtk"))).unwrap();
        let text = String::from_utf8(text).unwrap();
        let start = text.find("FIELD").unwrap();
        let end = text.find("POINTS").unwrap();
        let untimed = format!("{}{}", &text[..start], &text[end..]);
        std::fs::write(plain.join(format!("other_{}.vtk", k + 1)), untimed).unwrap();
    }
    let (plain, csv) = (plain.to_str().unwrap(), dir.join("plain.csv"));
    let out = projfluid(&["probes", scene, "--frames", plain]);
    assert_bad_input(&out, &["other_1.vtk", "--fps"]);
    let csv_str = csv.to_str().unwrap();
    let read = projfluid(&[
        "probes", scene, "--frames", plain, "--fps", "4", "--out", csv_str,
    ]);
    assert!(
        read.status.success(),
        "{}",
        String::from_utf8_lossy(&read.stderr)
    );
    let (header, rows) = read_csv(&csv);
    let times: Vec<f64> = rows.iter().map(|r| number(&header, r, "time_s")).collect();
    assert_eq!(times, [0.0, 0.25, 0.5]);
    let missing = dir.join("none");
    let out = projfluid(&["probes", scene, "--frames", missing.to_str().unwrap()]);
    assert_bad_input(&out, &["cannot read directory", "none"]);
    let out = projfluid(&["probes", scene, "--frames", plain, "--fps", "0"]);
    assert_bad_input(&out, &["--fps", "positive"]);
    let out = projfluid(&["probes", "dam_break_small", "--frames", plain]);
    assert_bad_input(&out, &["dam_break_small", "no probes"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A fluid block overlapping a static body: the run's first line says how many particles the
/// scene's blocks held inside the solid and were not created.
#[test]
fn a_run_says_how_many_block_particles_lay_inside_solids() {
    let dir = temp_dir("inside-solids");
    // The block's middle column (x = 0.2 m, 9 particles) lies inside the box.
    let body = r#""bodies": [{"kind": "static", "box": {"half_extents": [0.05, 0.2, 0.2]}, "position": [0.2, 0.2, 0.2]}],
  "duration""#;
    let out = run_scene_text(&dir, "inside.json", &scene_with("\"duration\"", body));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains(
            "cli_test: 18 particles (9 of the fluid blocks' particles lay inside solids and \
             were not created), "
        ),
        "{stderr}"
    );
    // Without the body every particle is created, and the line says nothing of solids.
    let out = run_scene_text(&dir, "free.json", &scene_with("", ""));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("cli_test: 27 particles, "), "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--backend gpu` in the workspace's build, which leaves the GPU backend out, is refused
/// (exit 2) naming the backend and the missing feature, before any step; `--backend` takes
/// only `cpu` and `gpu`, and `--backend cpu` runs.
#[test]
fn the_gpu_backend_is_refused_where_the_build_lacks_it() {
    let out = projfluid(&["run", "dam_break_small", "--steps", "1", "--backend", "gpu"]);
    assert_bad_input(&out, &["backend gpu", "`gpu` feature"]);
    let out = projfluid(&["run", "dam_break_small", "--steps", "1", "--backend", "tpu"]);
    assert_eq!(out.status.code(), Some(2));
    let out = projfluid(&["run", "dam_break_small", "--steps", "1", "--backend", "cpu"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The scene key `backend` chooses the backend as `--backend` does, and `--backend`
/// replaces it: a scene for the GPU is refused in this build (exit 2, naming the backend and
/// the missing feature, before any stats are written), runs with `--backend cpu`, whose
/// summary and stats name the CPU; a value other than `cpu` or `gpu` is refused naming the
/// key.
#[test]
fn the_scene_key_backend_chooses_the_backend_and_the_option_replaces_it() {
    let dir = temp_dir("backend-key");
    let stats = dir.join("stats.json");
    let gpu = dir.join("gpu.json");
    let text = scene_with("\"duration\"", "\"backend\": \"gpu\", \"duration\"");
    std::fs::write(&gpu, &text).unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec!["run", gpu.to_str().unwrap(), "--steps", "1"];
        args.extend_from_slice(&["--stats", stats.to_str().unwrap()]);
        args.extend_from_slice(extra);
        projfluid(&args)
    };
    assert_bad_input(
        &run(&[]),
        &["backend gpu: not available: this build of projfluid has no `gpu` feature"],
    );
    assert!(!stats.exists(), "a refused run wrote {}", stats.display());
    let out = run(&["--backend", "cpu"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("backend                cpu (double precision)"),
        "{stdout}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    assert_eq!(
        (&json["backend"], &json["steps"]),
        (&"cpu".into(), &1.into())
    );
    let out = run_scene_text(&dir, "tpu.json", &text.replace("\"gpu\"", "\"tpu\""));
    assert_bad_input(&out, &["tpu.json", "backend", "tpu", "`cpu`", "`gpu`"]);
    std::fs::remove_dir_all(&dir).unwrap();
}
