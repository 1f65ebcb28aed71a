//! Runs stopped by a real signal: what they keep and how soon they end. A test file of its own,
//! its tests one at a time, so that no other test's run shares the machine with these timings.

use std::process::Command;
use std::sync::{Mutex, MutexGuard, PoisonError};

mod common;
use common::{check_radiosity, json, run_quietly};

/// Held by each test while it runs.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

/// The machine to this test alone (among these), once the others are done.
fn alone() -> MutexGuard<'static, ()> {
    ONE_AT_A_TIME.lock().unwrap_or_else(PoisonError::into_inner)
}

/// `penumbra ARGS` sent `signal` (`INT`, `TERM`) after `seconds`: what it wrote to stderr, its
/// exit status, and the seconds it took to end once signalled.
fn signalled(args: &[&str], signal: &str, seconds: f64) -> (std::process::Output, f64) {
    let child = Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args(args)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("the penumbra binary runs");
    std::thread::sleep(std::time::Duration::from_secs_f64(seconds));
    let sent = Command::new("kill")
        .args([format!("-{signal}"), child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(sent.success());
    let at = std::time::Instant::now();
    let o = child.wait_with_output().expect("the run ends");
    (o, at.elapsed().as_secs_f64())
}

/// A real SIGINT or SIGTERM to a real run: it stops shooting, writes its solution so far (valid,
/// marked partial, stop "interrupted") and exits 130 or 143, the statuses of the signals.
#[test]
fn interrupted_runs_write_their_partial_solution() {
    let _alone = alone();
    let dir = tempfile::tempdir().expect("temp dir");
    for (signal, code) in [("INT", 130), ("TERM", 143)] {
        let out = dir.path().join(signal);
        // Converging this far takes minutes; the signal comes after two seconds.
        let (o, _) = signalled(
            &[
                "run",
                "cornell",
                "--solver",
                "progressive",
                "--max-elements",
                "20000",
                "--epsilon",
                "1e-9",
                "--quiet",
                "--out",
                out.to_str().expect("utf-8"),
            ],
            signal,
            2.0,
        );
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(code), "{stderr}");
        assert!(stderr.contains("interrupted"), "{stderr}");
        let report = json(&out.join("report.json"));
        assert_eq!(report["partial"], true);
        assert_eq!(report["solver"]["stop"], "interrupted");
        assert!(check_radiosity(&json(&out.join("solution.json"))) > 0);
        assert!(out.join("render.png").exists());
    }
    // A run left alone is not partial.
    let out = dir.path().join("whole");
    run_quietly("textbook", &out, &["--max-elements", "500"]);
    assert_eq!(json(&out.join("report.json"))["partial"], false);
}

/// One SIGTERM stops a run promptly whatever it is computing: here 9 s into boxworld-3000,
/// while the hierarchical solver links its elements (which once went on for 18 s) or later.
/// The run exits with SIGTERM's status, having written its partial solution or nothing.
#[test]
fn one_signal_stops_a_run_promptly() {
    let _alone = alone();
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    let (o, waited) = signalled(
        &[
            "run",
            "boxworld-3000",
            "--width",
            "64",
            "--height",
            "64",
            "--svg",
            "none",
            "--quiet",
            "--out",
            out.to_str().expect("utf-8"),
        ],
        "TERM",
        9.0,
    );
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(143), "{stderr}");
    // A second to stop computing, then the time to write a large partial solution.
    assert!(waited < 5.0, "the run took {waited:.1} s to stop: {stderr}");
    if out.join("report.json").exists() {
        assert_eq!(json(&out.join("report.json"))["partial"], true);
    }
}

/// A signal before any mesh has values (while the discontinuities of a large scene are found,
/// or its mesh is refined) ends the run with the signal's status within a second, having
/// written the scene's least mesh with its direct light, and a report that names the stage it
/// stopped in.
#[test]
fn runs_interrupted_before_a_solution_keep_the_least_mesh_lit() {
    let _alone = alone();
    let dir = tempfile::tempdir().expect("temp dir");
    // Meshing 400,000 triangles by discontinuities takes seconds (the boxes' many surfaces
    // tens of seconds, one trial refinement of their floor half a second); the signals come
    // within it, or within the boxes' discontinuity search on a busy machine.
    let large = ["--max-elements", "400000", "--mesh", "discontinuity"];
    let cases = [
        ("cornell", 0.5, &["mesh"][..]),
        ("cornell", 1.5, &["mesh"]),
        ("boxworld-300", 0.1, &["discontinuities", "mesh"]),
        ("boxworld-300", 0.3, &["discontinuities", "mesh"]),
        ("boxworld-300", 0.7, &["discontinuities", "mesh"]),
        ("boxworld-300", 1.2, &["mesh"]),
    ];
    for (scene, after, stages) in cases {
        let out = dir.path().join(format!("{scene} at {after} s-{after}"));
        std::fs::create_dir(&out).expect("mkdir");
        std::fs::write(out.join("report.json"), b"old").expect("writes");
        let out_arg = out.to_str().expect("utf-8");
        let mut args = vec!["run", scene, "--quiet", "--svg", "none", "--out", out_arg];
        args.extend(large);
        let (o, waited) = signalled(&args, "INT", after);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(130), "{scene} at {after} s: {stderr}");
        assert!(
            waited < 1.0,
            "{scene} at {after} s: {waited:.2} s to stop: {stderr}"
        );
        let report = json(&out.join("report.json"));
        let stopped = &report["stopped"];
        assert!(
            stages.contains(&stopped["stage"].as_str().unwrap_or_default()),
            "{scene} at {after} s: {stopped}"
        );
        assert_eq!(stopped["reason"], "interrupted", "{scene} at {after} s");
        assert_eq!(stopped["kept"], "least_mesh_direct", "{scene} at {after} s");
        assert_eq!(report["partial"], true, "{scene} at {after} s");
        assert_eq!(
            report["solver"]["stop"], "interrupted",
            "{scene} at {after} s"
        );
        // The least mesh: every polygon's own triangles, lit where the light falls.
        let solution = json(&out.join("solution.json"));
        let surfaces = solution["surfaces"].as_array().expect("surfaces");
        let triangles: usize = surfaces
            .iter()
            .map(|s| s["triangles"].as_array().map_or(0, Vec::len))
            .sum();
        assert_eq!(
            report["counts"]["triangles"], triangles,
            "{scene} at {after} s"
        );
        assert!(
            triangles < 2 * surfaces.len() + 64,
            "{scene} at {after} s: {triangles} triangles"
        );
        assert!(check_radiosity(&solution) > 0, "{scene} at {after} s");
        let brightest = surfaces
            .iter()
            .flat_map(|s| s["direct"].as_array().into_iter().flatten())
            .flat_map(|c| c.as_array().into_iter().flatten())
            .filter_map(serde_json::Value::as_f64)
            .fold(0.0, f64::max);
        assert!(brightest > 0.0, "{scene} at {after} s: no direct light");
        assert!(
            stderr.contains("least mesh"),
            "{scene} at {after} s: {stderr}"
        );
    }
}
