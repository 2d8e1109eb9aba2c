//! Validation against the MARIN dam break with a box (Kleefsman et al. 2005, SPHERIC Test 2)
//! at a coarse resolution, its discrimination (a broken gravity or a missing box must fail it),
//! the shipped scene, and `projfluid validate kleefsman`.

mod support;

use projfluid::scene::Scene;
use projfluid_lab::validation::kleefsman::{
    self, Comparison, LEE_GAUGE, Measurements, Reference, Run, Setup, Tolerances, Verdict,
};
use std::path::{Path, PathBuf};
use support::{projfluid, projfluid_ok};

/// Particle radius of the tests (m): d = 5 cm, 11 particles over the depth, 5,500 in all (the
/// command's default is 12.5 mm).
const TEST_RADIUS: f64 = 0.025;

/// The dam break at the test resolution with `change` applied to the default setup, run for
/// `duration` seconds and compared with the measurements at the default tolerances.
fn dam_break(duration: f64, change: impl FnOnce(&mut Setup)) -> (Run, Comparison) {
    let mut setup = Setup {
        particle_radius: TEST_RADIUS,
        duration,
        ..Setup::default()
    };
    change(&mut setup);
    let run = kleefsman::simulate(&setup, |_| {}).expect("dam break runs");
    let data = Measurements::load().unwrap();
    let reference = Reference::load().unwrap();
    let cmp = kleefsman::compare(&run, &data, &reference, Tolerances::default());
    (run, cmp)
}

/// With the experiment's gravity and box, over the first 2 s: the surge reaches H3, H2 and H1
/// (behind the box) within the arrival tolerance of the measured times, and the reservoir's
/// height at H4 lies within the height tolerance at every compared time. No particle escapes
/// and the compression stays small.
///
/// The water content of the gauges' lines agrees with the surface where water stands (H2, H3,
/// H4: RMS difference below a quarter of a spacing once the water is 5 cm deep), while in the
/// box's lee the water first comes through the air: H1's content reaches 5 cm at least 0.1 s
/// before its standing surface does (docs/validation.md).
///
/// The reference solver's run (DFSPH, r = 12.5 mm) is compared over the same times: its
/// arrivals at H3 and H2 lie near the measured ones and its worst gauge is the lee's.
///
/// The same comparison must fail with gravity scaled by 0.8 (every arrival late, the
/// reservoir falls too slowly), and without the box (the surge reaches H1, in the box's lee,
/// about 0.4 s early; 1 s of flow decides it).
#[test]
fn dam_break_past_a_box_matches_kleefsman_and_discriminates() {
    let (run, cmp) = dam_break(2.0, |_| {});
    assert_eq!(run.escaped, 0);
    assert!(
        run.density_error_max < 0.02,
        "compression {}",
        run.density_error_max
    );
    assert!(cmp.covered(), "{}", cmp.table());
    assert!(
        cmp.failures().is_empty(),
        "{}\n{:#?}",
        cmp.table(),
        cmp.failures()
    );

    let first_reaching =
        |series: Vec<(f64, f64)>, level: f64| series.iter().find(|p| p.1 >= level).map(|p| p.0);
    for g in 1..4 {
        let pairs: Vec<(f64, f64)> = (run.heights(g).iter().zip(run.contents(g)))
            .filter(|(h, _)| h.1 > 0.05)
            .map(|(h, c)| (h.1, c.1))
            .collect();
        assert!(pairs.len() > 100, "gauge {g}: {} wet readings", pairs.len());
        let rms =
            (pairs.iter().map(|(h, c)| (c - h).powi(2)).sum::<f64>() / pairs.len() as f64).sqrt();
        // A quarter of a spacing: the RMS moves with the rounding alone (runs whose particle
        // radii differ by 10⁻⁹ to 10⁻⁸ of themselves read 0.004–0.010 m at the first of these
        // gauges).
        assert!(
            rms <= 0.25 * 2.0 * TEST_RADIUS,
            "gauge {g}: content against surface RMS {rms} m"
        );
    }
    // The reference solver's run over the same 2 s, read with the same gauges: its surge
    // reaches H3 and H2 within 0.06 s of the measured times and H1, in the lee, last; its
    // reservoir falls within 3 cm RMS of the measured heights, and the lee is its worst gauge.
    let reference = &cmp.reference;
    for (a, r) in cmp.arrivals.iter().zip(&reference.arrivals) {
        let r = r.expect("the reference's surge reaches every gauge within 2 s");
        if a.gauge != LEE_GAUGE {
            assert!((r - a.measured).abs() < 0.06, "{}", cmp.table());
        }
    }
    assert!(
        reference.arrivals[2] > reference.arrivals[1],
        "{}",
        cmp.table()
    );
    assert!(reference.rms[3] < 0.03, "{}", cmp.table());
    assert!(
        reference.rms[LEE_GAUGE] > reference.rms[1..].iter().copied().fold(0.0, f64::max),
        "{}",
        cmp.table()
    );
    let content = first_reaching(run.contents(LEE_GAUGE), 0.05).expect("water reaches H1");
    let surface = first_reaching(run.heights(LEE_GAUGE), 0.05).expect("water stands at H1");
    assert!(
        content + 0.1 <= surface,
        "H1: content 5 cm at {content} s, surface at {surface} s"
    );

    let (_, weak) = dam_break(2.0, |s| s.gravity *= 0.8);
    assert!(
        !weak.failures().is_empty(),
        "gravity x 0.8 must fail:\n{}",
        weak.table()
    );
    // Weaker gravity: every arrival later than with g, and the reservoir outside its
    // tolerance (too high) at some compared time.
    for (a, w) in cmp.arrivals.iter().zip(&weak.arrivals) {
        assert!(
            w.simulated.unwrap_or(f64::INFINITY) > a.simulated.unwrap(),
            "{}\n{}",
            cmp.table(),
            weak.table()
        );
    }
    let tol = weak.tolerances.reservoir;
    assert!(
        weak.reservoir
            .iter()
            .any(|l| l.verdict(tol) == Verdict::Fail && l.simulated > Some(l.measured)),
        "gravity x 0.8 must keep the reservoir too high:\n{}",
        weak.table()
    );

    let (_, open) = dam_break(1.0, |s| s.obstacle = false);
    let lee = open.arrivals.iter().find(|a| a.gauge == LEE_GAUGE).unwrap();
    assert_eq!(
        lee.verdict(open.tolerances.arrival_window(LEE_GAUGE)),
        Verdict::Fail,
        "without the box H1 must be reached early:\n{}",
        open.table()
    );
    assert!(lee.delay().is_some_and(|d| d < 0.0), "{}", open.table());
}

/// `scenes/kleefsman_obstacle.json` is the default setup's scene, and it builds.
#[test]
fn shipped_scene_is_the_default_setup() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/kleefsman_obstacle.json");
    let loaded = Scene::load(&path).unwrap();
    let expected = Setup::default().scene();
    assert_eq!(loaded, expected, "expected:\n{}", expected.to_json());
    assert_eq!(loaded.particle_count(), 49 * 22 * 40);
}

/// `name` under this file's directory for test files, emptied.
fn scratch(name: &str) -> PathBuf {
    support::scratch("kleefsman", name)
}

#[test]
fn cli_kleefsman_writes_its_table_csv_and_charts() {
    let dir = scratch("cli");
    let stdout = projfluid_ok(&[
        "validate",
        "kleefsman",
        "--radius",
        "0.05",
        "--duration",
        "0.5",
        "--threads",
        "2",
        "--out",
        dir.to_str().unwrap(),
    ]);
    for key in [
        "surge arrival",
        "reservoir height at H4",
        "RMS",
        "not reached",
    ] {
        assert!(stdout.contains(key), "`{key}` missing:\n{stdout}");
    }
    for g in ["H1", "H2", "H3", "H4"] {
        let png = std::fs::read(dir.join(format!("kleefsman_{g}.png"))).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    }
    let series = std::fs::read_to_string(dir.join("kleefsman_series.csv")).unwrap();
    assert!(
        series.starts_with(
            "t_s,H1_m,H2_m,H3_m,H4_m,H1_content_m,H2_content_m,H3_content_m,H4_content_m\n"
        ),
        "{series}"
    );
    let csv = std::fs::read_to_string(dir.join("kleefsman_comparison.csv")).unwrap();
    assert!(csv.lines().any(|l| l.starts_with("arrival_s,H1,")), "{csv}");
    for kind in ["content_rms_m", "reference_rms_m", "reference_arrival_s"] {
        assert!(
            csv.lines().any(|l| l.starts_with(&format!("{kind},H1,"))),
            "{csv}"
        );
    }
    assert!(stdout.contains("reference"), "{stdout}");
    assert!(stdout.contains("water on H1's line"), "{stdout}");
}

#[test]
fn cli_kleefsman_rejects_bad_options_with_exit_code_2() {
    let dir = scratch("bad");
    let out_dir = dir.to_str().unwrap();
    for (option, value) in [
        ("--radius", "0.001"),
        ("--radius", "nan"),
        ("--duration", "0"),
        ("--gravity", "-9.81"),
        ("--viscosity", "1.5"),
        ("--tau", "-1"),
    ] {
        let out = projfluid(&["validate", "kleefsman", option, value, "--out", out_dir]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{option} {value}: {stderr}");
        assert!(stderr.contains(option), "{option} {value}: {stderr}");
    }
    assert!(
        !dir.exists(),
        "a rejected command must not create its output directory"
    );
}
