//! Options as a newcomer meets them: one place checks every range, for the command line (which
//! names the flag) and library callers (whose errors name no flag); replays, scene dumps, the
//! camera flags and the help's examples.

use std::path::Path;

mod common;
use common::{json, penumbra, stderr};

use penumbra::{RunError, RunOptions};
use penumbra_scenes::builtin;

/// Refused with exit 2 and a message naming `flag`, and nothing written.
fn refused(args: &[&str], flag: &str) {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    let mut all = args.to_vec();
    all.extend(["--out", out.to_str().expect("utf-8")]);
    let o = penumbra(&all);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
    assert!(e.contains(flag), "{args:?} should name {flag}: {e}");
    assert!(!out.exists(), "{args:?} wrote {}", out.display());
}

#[test]
fn bad_values_name_their_own_flag() {
    refused(
        &[
            "run",
            "textbook",
            "--refine-tol",
            "0.01",
            "--initial-elements",
            "0",
        ],
        "--initial-elements",
    );
    refused(
        &["run", "textbook", "--max-elements", "0"],
        "--max-elements",
    );
    refused(
        &["sweep", "textbook", "--direct-only", "--budgets", "0"],
        "--budgets",
    );
    // This many rays made a run hang; the cap says what it is.
    refused(
        &["run", "textbook", "--rays", "18446744073709551615"],
        "--rays",
    );
    refused(
        &[
            "run",
            "textbook",
            "--ff-samples",
            "100000000",
            "--form-factors",
            "monte-carlo",
        ],
        "--ff-samples",
    );
    for density in ["0", "-5", "NaN"] {
        refused(
            &["run", "textbook", &format!("--penumbra-density={density}")],
            "--penumbra-density",
        );
    }
    refused(&["run", "textbook", "--memory-limit=-5"], "--memory-limit");
    refused(&["run", "textbook", "--refine-tol", "2"], "--refine-tol");
    refused(
        &[
            "run",
            "textbook",
            "--refine-tol",
            "0.01",
            "--refine-rounds",
            "0",
        ],
        "--refine-rounds",
    );
    refused(&["run", "textbook", "--width", "100000"], "--width");
    // Each side within its cap, the whole beyond the renderer's: refused before the run.
    refused(
        &["run", "textbook", "--width", "16384", "--height", "16384"],
        "--width/--height",
    );
    refused(&["run", "textbook", "--up", "0,0,0"], "--up");
    refused(
        &["run", "textbook", "--eye", "0,0,0.4", "--target", "0,0,0.4"],
        "--eye",
    );
    refused(&["run", "textbook", "--fov", "180"], "--fov");
    refused(&["form-factors", "--streams", "100000000"], "--streams");
    // Starting this many threads took longer than any run.
    refused(&["run", "textbook", "--threads", "100000"], "--threads");
    refused(
        &["sweep", "textbook", "--samples", "100000000000"],
        "--samples",
    );
    refused(
        &["sweep", "cornell", "--reference-paths", "0"],
        "--reference-paths",
    );
    refused(&["form-factors", "--resolutions", "3"], "--resolutions");
    refused(&["form-factors", "--samples", "0"], "--samples");
}

#[test]
fn a_missing_file_is_named_once_with_its_cause() {
    let o = penumbra(&["run", "no/such/scene.json"]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains("no/such/scene.json"), "{e}");
    assert_eq!(e.matches("os error 2").count(), 1, "{e}");
}

/// An output directory named like a built-in scene does not hide the scene.
#[test]
fn a_directory_does_not_hide_a_built_in_scene() {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::create_dir(dir.path().join("textbook")).expect("mkdir");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args(["check", "textbook"])
        .current_dir(dir.path())
        .output()
        .expect("the penumbra binary runs");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("builtin:textbook"));
}

/// Library callers get the same checks, with errors that describe the value and name no flag.
#[test]
fn library_options_are_checked_without_flags() {
    for density in [0.0, -5.0, f64::NAN] {
        let options = RunOptions {
            penumbra_density: density,
            ..RunOptions::default()
        };
        let e = options.validate().expect_err("refused");
        assert_eq!(e.option, penumbra::OptionId::PenumbraDensity);
        let loaded = penumbra_scenes::load_scene("textbook").expect("built-in");
        let run = penumbra::run(loaded, &options, &penumbra_solver::NoProgress);
        let Err(RunError::InvalidOption(e)) = run else {
            panic!("penumbra density {density} was not refused");
        };
        assert!(!e.to_string().contains("--"), "{e}");
    }
    let mut options = RunOptions::default();
    options.solver.visibility_rays = usize::MAX;
    assert_eq!(
        options.validate().expect_err("refused").option,
        penumbra::OptionId::VisibilityRays
    );
    assert!(RunOptions::default().validate().is_ok());
}

/// Under a bright light, a tolerance relative to every surface's mean radiosity (the light's
/// own exitance included) was several times looser than asked on the dim floor. Relative to
/// the mean reflected radiosity, worked out here from solution.json, it holds.
#[test]
fn refinement_tolerance_is_relative_to_the_reflected_light() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = dir.path().join("two-blockers.json");
    std::fs::write(
        &scene,
        r#"{"name": "two-blockers", "surfaces": [
  {"name": "light", "polygon": [[-0.25,-0.25,2],[-0.25,0.25,2],[0.25,0.25,2],[0.25,-0.25,2]],
   "emission": [100,100,100], "reflectance": [0,0,0]},
  {"name": "left", "polygon": [[-0.9,-0.3,0.6],[-0.3,-0.3,0.6],[-0.3,0.3,0.6],[-0.9,0.3,0.6]],
   "reflectance": [0.5,0.5,0.5]},
  {"name": "right", "polygon": [[0.3,-0.3,0.6],[0.9,-0.3,0.6],[0.9,0.3,0.6],[0.3,0.3,0.6]],
   "reflectance": [0.5,0.5,0.5]},
  {"name": "floor", "polygon": [[-2,-2,0],[2,-2,0],[2,2,0],[-2,2,0]], "reflectance": [0.5,0.5,0.5]}
]}"#,
    )
    .expect("writes");
    let out = dir.path().join("out");
    let tolerance = 0.005;
    let o = penumbra(&[
        "run",
        scene.to_str().expect("utf-8"),
        "--direct-only",
        "--refine-tol",
        &tolerance.to_string(),
        "--max-elements",
        "30000",
        "--quiet",
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let refinement = &json(&out.join("report.json"))["refinement"];
    assert_eq!(
        refinement["tolerance_relative_to"],
        "mean_reflected_radiosity"
    );
    assert_eq!(refinement["stop"], "tolerance");
    let reflected = mean_reflected(&json(&out.join("solution.json")));
    let worst = refinement["residual"]["max"].as_f64().expect("number");
    // The emitter's exitance lifts the mean radiosity far above what the floor reflects.
    let mean = refinement["residual"]["mean_radiosity"]
        .as_f64()
        .expect("number");
    assert!(mean > 3.0 * reflected, "{mean} against {reflected}");
    assert!(
        worst <= tolerance * reflected * (1.0 + 1e-9),
        "worst residual {worst} over {tolerance} of the reflected mean {reflected}"
    );
}

/// The area-weighted mean radiosity of the surfaces that do not emit, from a solution file.
fn mean_reflected(solution: &serde_json::Value) -> f64 {
    let (mut area, mut weighted) = (0.0, 0.0);
    let point = |v: &serde_json::Value| -> glam::DVec3 {
        let c: Vec<f64> = v
            .as_array()
            .expect("xyz")
            .iter()
            .map(|x| x.as_f64().expect("number"))
            .collect();
        glam::DVec3::new(c[0], c[1], c[2])
    };
    for s in solution["surfaces"].as_array().expect("surfaces") {
        if s["name"] == "light" {
            continue;
        }
        let vertices: Vec<glam::DVec3> = s["vertices"]
            .as_array()
            .expect("vertices")
            .iter()
            .map(point)
            .collect();
        let radiosity: Vec<f64> = s["radiosity"]
            .as_array()
            .expect("radiosity")
            .iter()
            .map(|c| point(c).element_sum() / 3.0)
            .collect();
        for t in s["triangles"].as_array().expect("triangles") {
            let t: Vec<usize> = t
                .as_array()
                .expect("triple")
                .iter()
                .map(|i| i.as_u64().expect("index") as usize)
                .collect();
            let a = 0.5
                * (vertices[t[1]] - vertices[t[0]])
                    .cross(vertices[t[2]] - vertices[t[0]])
                    .length();
            area += a;
            weighted += a * t.iter().map(|&i| radiosity[i]).sum::<f64>() / 3.0;
        }
    }
    weighted / area
}

/// `--replay` runs a report's recorded options again: the same solution, byte for byte; it
/// takes no other options, and refuses a file that is not a report or records no command line.
#[test]
fn replays_repeat_a_run() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (first, again) = (dir.path().join("first"), dir.path().join("again"));
    let o = penumbra(&[
        "run",
        "textbook",
        "--solver",
        "progressive",
        "--max-elements",
        "1500",
        "--seed",
        "7",
        "--quiet",
        "--out",
        first.to_str().expect("utf-8"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = json(&first.join("report.json"));
    assert_eq!(report["version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(report["invocation"]["options"]["seed"], 7);
    assert_eq!(report["invocation"]["options"]["solver"], "progressive");
    let recorded = first.join("report.json");
    let o = penumbra(&[
        "run",
        "--replay",
        recorded.to_str().expect("utf-8"),
        "--quiet",
        "--out",
        again.to_str().expect("utf-8"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(first.join("solution.json")).expect("reads"),
        std::fs::read(again.join("solution.json")).expect("reads")
    );
    refused(
        &[
            "run",
            "--replay",
            recorded.to_str().expect("utf-8"),
            "--seed",
            "8",
        ],
        "--seed",
    );
    let o = penumbra(&[
        "run",
        "--replay",
        first.join("solution.json").to_str().expect("utf-8"),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("its format is \"penumbra-solution/1\""),
        "{}",
        stderr(&o)
    );
    // A report written by a library caller records no command line.
    let mut bare = report.clone();
    bare.as_object_mut().expect("object").remove("invocation");
    let bare_path = dir.path().join("bare.json");
    std::fs::write(&bare_path, bare.to_string()).expect("writes");
    let o = penumbra(&["run", "--replay", bare_path.to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("no command line to replay"),
        "{}",
        stderr(&o)
    );
}

/// `scenes --dump` prints a built-in scene in the scene format: loading it back gives the same
/// scene, and running it the same solution.
#[test]
fn dumped_scenes_load_back_unchanged() {
    let dir = tempfile::tempdir().expect("temp dir");
    for name in ["textbook", "cornell", "cie-5.8"] {
        let o = penumbra(&["scenes", "--dump", name]);
        assert!(o.status.success(), "{}", stderr(&o));
        let file = dir.path().join(format!("{name}.json"));
        std::fs::write(&file, &o.stdout).expect("writes");
        let loaded = penumbra_scenes::load_scene(file.to_str().expect("utf-8")).expect("loads");
        assert_eq!(
            loaded.scene,
            builtin::builtin(name).expect("built-in"),
            "{name}"
        );
    }
    let o = penumbra(&["scenes", "--dump", "no-such-scene"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("cornell"), "{}", stderr(&o));
}

/// `--up 0,1,0` turns the picture of a z-up scene: the render changes, the solution does not.
#[test]
fn camera_flags_move_the_render_only() {
    let dir = tempfile::tempdir().expect("temp dir");
    let common = [
        "--direct-only",
        "--max-elements",
        "600",
        "--width",
        "64",
        "--height",
        "64",
        "--quiet",
    ];
    let run = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let mut args = vec!["run", "textbook", "--out", out.to_str().expect("utf-8")];
        args.extend(common);
        args.extend(extra);
        let o = penumbra(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        out
    };
    let plain = run("plain", &[]);
    let turned = run(
        "turned",
        &[
            "--eye",
            "0,-6.5,4.5",
            "--target",
            "0,0,0.4",
            "--up",
            "1,0,0",
            "--fov",
            "50",
        ],
    );
    let read = |dir: &Path, file: &str| std::fs::read(dir.join(file)).expect("reads");
    assert_eq!(
        read(&plain, "solution.json"),
        read(&turned, "solution.json")
    );
    assert_ne!(read(&plain, "render.png"), read(&turned, "render.png"));
}

/// Every command's help has examples, and `run`'s options come under headings.
#[test]
fn help_teaches() {
    for command in [
        &["--help"][..],
        &["run", "--help"],
        &["sweep", "--help"],
        &["scenes", "--help"],
        &["check", "--help"],
        &["merge", "--help"],
        &["form-factors", "--help"],
    ] {
        let o = penumbra(command);
        assert!(o.status.success());
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(
            text.contains("Examples:"),
            "{command:?} has no examples:\n{text}"
        );
    }
    let text = String::from_utf8_lossy(&penumbra(&["run", "--help"]).stdout).into_owned();
    for heading in [
        "Mesh:",
        "Adaptive refinement:",
        "Solver:",
        "Output and render:",
        "Limits:",
    ] {
        assert!(text.contains(heading), "no {heading} in run --help");
    }
}
