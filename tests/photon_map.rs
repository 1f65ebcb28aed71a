//! `--solver photon-map` from the command line: the textbook's light against the exact direct
//! light, the report's figures, the same bytes whatever the thread count, and sweeps with the
//! photon count as the budget.

mod common;
use common::{json, penumbra, run_quietly, stderr};

/// In the textbook nothing reflected comes back to the floor or the blocker (the floor's light
/// reaches the blocker's back and the light, which reflects nothing), so photon mapping gives
/// them the direct-only run's radiosity, to the bit.
#[test]
fn the_textbook_is_its_direct_light() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (pm, direct) = (dir.path().join("pm"), dir.path().join("direct"));
    let mesh = [
        "--mesh",
        "uniform",
        "--max-elements",
        "1500",
        "--export",
        "none",
    ];
    let photons = [
        "--solver",
        "photon-map",
        "--photons",
        "20000",
        "--final-gather",
        "4",
    ];
    run_quietly("textbook", &pm, &[&mesh[..], &photons].concat());
    run_quietly(
        "textbook",
        &direct,
        &[&mesh[..], &["--direct-only"]].concat(),
    );
    let (a, b) = (
        json(&pm.join("solution.json")),
        json(&direct.join("solution.json")),
    );
    for (s, t) in a["surfaces"]
        .as_array()
        .expect("")
        .iter()
        .zip(b["surfaces"].as_array().expect(""))
    {
        if s["name"] != "light" {
            assert_eq!(s["radiosity"], t["radiosity"], "{}", s["name"]);
        }
    }
    let report = json(&pm.join("report.json"));
    assert_eq!(report["method"]["solver"], "photon-map");
    let figures = &report["solver"]["photon_map"];
    assert_eq!(figures["emitted"], 20000);
    assert!(
        figures["stored"].as_u64().expect("stored") > 0,
        "the light receives the floor's"
    );
    // The photons' tally of what leaves, and the time of each stage.
    let escaped = figures["escaped"].as_array().expect("escaped per channel");
    let emitted = report["energy"]["emitted"].as_array().expect("emitted");
    for (lost, given) in escaped.iter().zip(emitted) {
        let (lost, given) = (
            lost.as_f64().expect("a number"),
            given.as_f64().expect("a number"),
        );
        assert!(lost > 0.0 && lost < given, "{lost} of {given}");
    }
    for stage in ["trace_seconds", "estimate_seconds"] {
        assert!(figures[stage].as_f64().expect(stage) > 0.0, "{stage}");
    }
}

/// Tracing, the estimates made in advance and the final gather give the same `solution.json`
/// on 1 and 2 threads.
#[test]
fn photon_maps_are_the_same_bytes_on_one_and_two_threads() {
    let dir = tempfile::tempdir().expect("temp dir");
    let options = [
        "--solver",
        "photon-map",
        "--max-elements",
        "1500",
        "--photons",
        "30000",
        "--final-gather",
        "25",
        "--export",
        "none",
    ];
    let mut solutions = Vec::new();
    for threads in ["1", "2"] {
        let out = dir.path().join(threads);
        run_quietly(
            "cornell",
            &out,
            &[&options[..], &["--threads", threads]].concat(),
        );
        solutions.push(std::fs::read(out.join("solution.json")).expect("written"));
        // The gather reads estimates made in advance, made in parallel too.
        let report = json(&out.join("report.json"));
        assert!(report["solver"]["photon_map"]["precomputed"].as_u64() > Some(0));
    }
    assert!(
        solutions[0] == solutions[1],
        "solution.json differs with the thread count"
    );
}

/// A spent `--time-budget` stops the estimates made in advance and the final gather, and says
/// so; every vertex keeps the map's raw estimate, finite and not negative.
#[test]
fn a_spent_time_budget_stops_the_gather() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    run_quietly(
        "cornell",
        &out,
        &[
            "--solver",
            "photon-map",
            "--time-budget",
            "0.3",
            "--export",
            "none",
        ],
    );
    let report = json(&out.join("report.json"));
    assert_eq!(report["solver"]["stop"], "time_budget");
    assert_eq!(report["solver"]["photon_map"]["precomputed"], 0);
    assert_eq!(report["solver"]["gathered"], 0);
    let solution = json(&out.join("solution.json"));
    let mut values = 0;
    for surface in solution["surfaces"].as_array().expect("surfaces") {
        for b in surface["radiosity"].as_array().expect("radiosity") {
            for c in b.as_array().expect("rgb") {
                let c = c.as_f64().expect("a number");
                assert!(c.is_finite() && c >= 0.0, "{c}");
                values += 1;
            }
        }
    }
    assert!(values > 1000);
}

#[test]
fn bad_photon_options_are_refused() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    let out = out.to_str().expect("utf-8");
    for (flag, value) in [
        ("--photons", "0"),
        ("--gather-photons", "0"),
        ("--final-gather", "70000"),
    ] {
        let o = penumbra(&[
            "run",
            "cornell",
            "--solver",
            "photon-map",
            flag,
            value,
            "--out",
            out,
        ]);
        assert_eq!(o.status.code(), Some(2), "{flag} {value}");
        assert!(stderr(&o).contains(flag), "{flag}: {}", stderr(&o));
    }
    let o = penumbra(&[
        "run",
        "cornell",
        "--solver",
        "photon-map",
        "--refine-tol",
        "0.1",
        "--out",
        out,
    ]);
    assert_eq!(o.status.code(), Some(2));
}

/// `penumbra sweep --solvers photon-map` runs photon mapping at each photon budget, on one mesh,
/// a line per final gather (a value given twice runs once); the other solvers keep their element
/// budgets. Photon-map lines
/// appear against time, not against triangles (their triangles do not change).
#[test]
fn sweeps_take_photons_as_the_photon_maps_budget() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("sweep");
    let o = penumbra(&[
        "sweep",
        "cornell",
        "--budgets",
        "700",
        "--samples",
        "60",
        "--reference-paths",
        "64",
        "--methods",
        "discontinuity",
        "--solvers",
        "hierarchical,photon-map",
        "--photons",
        "20000,40000",
        "--final-gather",
        "0,4,0",
        "--photon-elements",
        "900",
        "--out",
        out.to_str().expect("utf-8"),
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let sweep = json(&out.join("sweep.json"));
    let rows = sweep["rows"].as_array().expect("rows");
    let runs: Vec<(String, u64, Option<u64>, Option<u64>)> = rows
        .iter()
        .map(|r| {
            (
                r["solver"].as_str().expect("solver").to_owned(),
                r["max_elements"].as_u64().expect("budget"),
                r["photons"].as_u64(),
                r["final_gather"].as_u64(),
            )
        })
        .collect();
    let pm = |photons, rays| ("photon-map".to_owned(), 900, Some(photons), Some(rays));
    assert_eq!(
        runs,
        vec![
            ("hierarchical".to_owned(), 700, None, None),
            pm(20000, 0),
            pm(40000, 0),
            pm(20000, 4),
            pm(40000, 4),
        ]
    );
    for r in rows {
        assert!(r["rms"].as_f64().expect("rms").is_finite());
    }
    let csv = std::fs::read_to_string(out.join("sweep.csv")).expect("csv");
    assert!(
        csv.lines()
            .next()
            .expect("header")
            .ends_with(",solver,photons,final_gather")
    );
    assert!(
        csv.lines().any(|l| l.ends_with(",photon-map,40000,4")),
        "{csv}"
    );
    let time = std::fs::read_to_string(out.join("error-vs-time.svg")).expect("svg");
    assert!(time.contains("discontinuity (photon-map, 4 rays)"));
    assert!(time.contains("discontinuity (photon-map, 0 rays)"));
    let elements = std::fs::read_to_string(out.join("error-vs-elements.svg")).expect("svg");
    assert!(!elements.contains("photon-map") && elements.contains("hierarchical"));
    // Bad photon options are refused naming their flag, before a reference is traced.
    let fresh = dir.path().join("refused");
    for (flag, value, methods) in [
        ("--photons", "1000,0", "discontinuity"),
        ("--final-gather", "0,70000", "discontinuity"),
        ("--photon-elements", "0", "discontinuity"),
        ("--solvers", "photon-map", "uniform+adaptive"),
    ] {
        let o = penumbra(&[
            "sweep",
            "cornell",
            "--solvers",
            "photon-map",
            "--methods",
            methods,
            flag,
            value,
            "--out",
            fresh.to_str().expect("utf-8"),
        ]);
        assert_eq!(o.status.code(), Some(2), "{flag} {value}");
        assert!(stderr(&o).contains(flag), "{flag}: {}", stderr(&o));
        assert!(!fresh.join("reference.json").exists(), "{flag}: traced");
    }
    // A mesh budget too small for the scene is told as --photon-elements.
    let o = penumbra(&[
        "sweep",
        "cornell",
        "--budgets",
        "700",
        "--samples",
        "20",
        "--reference-paths",
        "16",
        "--methods",
        "discontinuity",
        "--solvers",
        "photon-map",
        "--photon-elements",
        "50",
        "--out",
        fresh.to_str().expect("utf-8"),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("--photon-elements 50 is too small"),
        "{}",
        stderr(&o)
    );
}
