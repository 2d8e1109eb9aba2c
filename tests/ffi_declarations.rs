//! The declarations file `include/projfluid_cdef.h` drives the library from FFI tools that
//! do not run the preprocessor: the cffi and LuaJIT examples of docs/c-api.md ("cffi and
//! LuaJIT"), run as they stand there with the paths of this checkout's declarations and of
//! the library this build made, each read the declarations unchanged, create a world, run a
//! small dam break and read its positions. The positions must be those of the same scene
//! through the Rust API, bit for bit (so the declared struct layouts and signatures are the
//! library's), and show the water fallen and kept in its box.
//!
//! The Python interpreter is `$PROJFLUID_PYTHON` or `python3`, with cffi installed; LuaJIT
//! is `luajit`. Outside CI a missing one skips its check with a note; under CI it fails the
//! test (`.ci/run` installs both).

use projfluid::boundary::Aabb;
use projfluid::{Params, Vec3, World};
use std::path::PathBuf;
use std::process::Command;
use std::sync::OnceLock;

#[path = "support/library.rs"]
mod library;
// Only `available_with` is used here: luajit has no `--version`.
#[allow(dead_code)]
#[path = "support/tools.rs"]
mod tools;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The paths the documented examples name, relative to the checkout.
const DOC_DECLARATIONS: &str = "include/projfluid_cdef.h";
const DOC_LIBRARY: &str = "target/release/libprojfluid.so";

/// The examples' scene: a 1 m container box and a 6 × 6 × 6 block from (0.2, 0.2, 0.2) m.
const BLOCK_START: f32 = 0.2;
const BLOCK_COUNT: usize = 6;
const SECONDS: f64 = 0.2;

/// The code block in ```` ```language ```` of the docs' "cffi and LuaJIT" section, with the
/// declarations and library paths replaced by this checkout's and this build's.
fn doc_example(language: &str) -> String {
    let docs = std::fs::read_to_string(root().join("docs/c-api.md")).unwrap();
    let section = docs
        .split("\n## ")
        .find(|s| s.starts_with("cffi and LuaJIT\n"))
        .expect("docs/c-api.md has a section \"cffi and LuaJIT\"");
    let fence = format!("\n```{language}\n");
    let start = section
        .find(&fence)
        .unwrap_or_else(|| panic!("the section has a {language} example"))
        + fence.len();
    let end = start
        + section[start..]
            .find("\n```")
            .expect("the example's code block ends");
    let example = &section[start..=end];
    for path in [DOC_DECLARATIONS, DOC_LIBRARY] {
        assert_eq!(
            example.matches(path).count(),
            1,
            "the {language} example should name {path} once"
        );
    }
    let declarations = root().join(DOC_DECLARATIONS);
    let library = library::shared_library();
    example
        .replace(DOC_DECLARATIONS, declarations.to_str().unwrap())
        .replace(DOC_LIBRARY, library.to_str().unwrap())
}

/// The examples' scene through the Rust API, with the same float inputs widened to f64 as
/// the C API does; its fluid positions as the C API's floats.
fn rust_positions() -> &'static [f32] {
    static POSITIONS: OnceLock<Vec<f32>> = OnceLock::new();
    POSITIONS.get_or_init(|| {
        let v = |x: f32| Vec3::new(x.into(), x.into(), x.into());
        let mut world = World::new(Params::default()).unwrap();
        let container = Aabb {
            min: v(0.0),
            max: v(1.0),
        };
        world.add_container(container, 1).unwrap();
        world
            .add_fluid_block(v(BLOCK_START), [BLOCK_COUNT; 3], Vec3::zeros())
            .unwrap();
        world.advance(SECONDS).unwrap();
        assert_eq!(world.escaped_count(), 0, "no water escapes the box");
        world
            .positions()
            .iter()
            .flat_map(|p| p.iter().map(|&c| c as f32).collect::<Vec<_>>())
            .collect()
    })
}

/// Runs `command` (an example with lines appended that print `positions` and then every
/// coordinate, one a line) in the checkout, checks that it succeeded and printed the
/// example's summary, and checks the positions.
fn run_and_check(tool: &str, mut command: Command) {
    let output = command.current_dir(root()).output().unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "the {tool} example failed ({}):\n{stdout}\n{}",
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    let n = BLOCK_COUNT.pow(3);
    let summary = format!("{n} particles, mean height ");
    assert!(
        stdout.lines().any(|l| l.starts_with(&summary)),
        "the {tool} example did not print its summary:\n{stdout}"
    );
    let positions: Vec<f32> = stdout
        .lines()
        .skip_while(|l| *l != "positions")
        .skip(1)
        .map(|l| {
            l.parse()
                .unwrap_or_else(|e| panic!("{tool} printed {l:?}: {e}"))
        })
        .collect();
    assert_eq!(positions.len(), 3 * n, "{tool}: x, y, z of {n} particles");
    assert!(
        positions.iter().all(|c| c.is_finite()),
        "{tool}: a position is not finite"
    );
    // Inside the container, less r/2 of slack (what counts as escaped).
    let r = Params::default().particle_radius as f32;
    assert!(
        positions
            .iter()
            .all(|&c| (-r / 2.0..=1.0 + r / 2.0).contains(&c)),
        "{tool}: a particle left the 1 m box"
    );
    let spacing = 2.0 * r;
    let start_height = BLOCK_START + spacing * (BLOCK_COUNT - 1) as f32 / 2.0;
    // Gravity points along −y (the default parameters).
    let height = positions.iter().skip(1).step_by(3).sum::<f32>() / n as f32;
    assert!(
        height < start_height - 0.1,
        "{tool}: the water's mean height is {height} m after {SECONDS} s, from {start_height} m"
    );
    assert!(
        positions == rust_positions(),
        "{tool}: the positions differ from the same scene through the Rust API"
    );
}

/// The interpreter to run, when it has cffi; panics under CI otherwise.
fn python_with_cffi() -> Option<String> {
    let python = std::env::var("PROJFLUID_PYTHON").unwrap_or_else(|_| "python3".to_string());
    let found = Command::new(&python)
        .args(["-c", "import cffi"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !found {
        assert!(
            std::env::var_os("CI").is_none(),
            "{python} with cffi is needed, and CI must run every check: .ci/run installs it \
             in a virtualenv and sets PROJFLUID_PYTHON"
        );
        eprintln!("note: {python} lacks cffi; skipping the cffi example");
        return None;
    }
    Some(python)
}

#[test]
fn the_cffi_example_runs_a_dam_break_from_the_declarations() {
    let Some(python) = python_with_cffi() else {
        return;
    };
    let script = doc_example("python")
        + "\nprint(\"positions\")\n\
           for c in ffi.unpack(xyz, len(xyz)):\n    print(\"%.9g\" % c)\n";
    let mut command = Command::new(python);
    command.args(["-c", &script]);
    run_and_check("cffi", command);
}

#[test]
fn the_luajit_example_runs_a_dam_break_from_the_declarations() {
    if !tools::available_with("luajit", &["-v"]) {
        return;
    }
    let script = doc_example("lua")
        + "\nprint(\"positions\")\n\
           for i = 0, 3 * count - 1 do print(string.format(\"%.9g\", xyz[i])) end\n";
    let mut command = Command::new("luajit");
    command.args(["-e", &script]);
    run_and_check("LuaJIT", command);
}
