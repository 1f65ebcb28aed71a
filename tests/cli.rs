//! The command line as a user meets it: outputs, exit codes, messages, determinism.

use std::path::Path;

mod common;
use common::{check_radiosity, json, penumbra, run_quietly};

#[test]
fn run_writes_every_output() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    let o = run_quietly("textbook", &out, &["--max-elements", "1500"]);
    assert!(o.stdout.is_empty(), "--quiet prints nothing");

    let solution = json(&out.join("solution.json"));
    assert_eq!(solution["format"], "penumbra-solution/1");
    assert_eq!(solution["scene"], "textbook");
    let names: Vec<&str> = solution["surfaces"]
        .as_array()
        .expect("surfaces")
        .iter()
        .map(|s| s["name"].as_str().expect("name"))
        .collect();
    assert_eq!(names, ["light", "blocker", "floor"]);
    assert!(check_radiosity(&solution) > 0);

    let report = json(&out.join("report.json"));
    assert_eq!(report["format"], "penumbra-report/1");
    let triangles = report["counts"]["triangles"].as_u64().expect("count");
    // The error-driven mesh stops at its tolerance or at the cap, whichever comes first.
    assert!(triangles > 200 && triangles <= 1500, "{triangles}");
    assert_eq!(report["method"]["mesh"], "error-driven");
    assert!(
        report["mesh_error"]["surfaces"]
            .as_array()
            .is_some_and(|s| !s.is_empty())
    );
    assert_eq!(report["solver"]["stop"], "converged");
    assert!(
        report["energy"]["unshot_fraction"]
            .as_f64()
            .expect("fraction")
            < 1e-3
    );
    assert!(
        report["mesh_quality"]["min_angle_deg"]
            .as_f64()
            .expect("angle")
            > 20.0
    );
    for stage in [
        "mesh",
        "visibility",
        "direct",
        "shooting",
        "render",
        "total",
    ] {
        assert!(report["times_seconds"][stage].as_f64().is_some(), "{stage}");
    }

    let png = std::fs::read(out.join("render.png")).expect("render");
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    // Three surfaces: by default each gets its SVG, listed in the report.
    for (i, name) in names.iter().enumerate() {
        let svg = std::fs::read_to_string(out.join("surfaces").join(format!("{i:03}-{name}.svg")))
            .expect("one SVG per surface");
        assert!(svg.contains("<svg") && svg.contains(name));
    }
    assert_eq!(
        report["svgs"]["written"],
        serde_json::json!([
            "surfaces/000-light.svg",
            "surfaces/001-blocker.svg",
            "surfaces/002-floor.svg"
        ])
    );
    assert_eq!(report["method"]["max_elements"], 1500);
    assert_eq!(report["method"]["max_elements_requested"], 1500);
    assert_eq!(report["energy"]["balanced"], true);
    // Nothing half-written is left behind.
    let leftovers: Vec<_> = std::fs::read_dir(&out)
        .expect("out dir")
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp-"))
        .collect();
    assert!(leftovers.is_empty());
}

#[test]
fn bad_input_exits_2_names_the_problem_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = dir.path().join("bad.json");
    std::fs::write(
        &scene,
        r#"{"surfaces": [
            {"name": "lamp", "polygon": [[0,0,2],[0,1,2],[1,1,2],[1,0,2]], "emission": [1,1,1], "reflectance": [0,0,0]},
            {"name": "floor", "polygon": [[0,0,0],[1,0,0],[1,1,0],[0,1,0]], "reflectance": [1.5, 0.5, 0.5]}
        ]}"#,
    )
    .expect("write scene");
    let out = dir.path().join("out");
    let o = penumbra(&[
        "run",
        scene.to_str().expect("utf-8"),
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("bad.json"), "{err}");
    assert!(
        err.contains("surface \"floor\"") && err.contains("below 1"),
        "{err}"
    );
    assert!(!out.exists(), "no output for bad input");

    // A syntax error gives the file, line and column.
    std::fs::write(&scene, "{\"surfaces\": [\n  {\"name\": \"x\",,}\n]}").expect("write scene");
    let o = penumbra(&["check", scene.to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("bad.json:2:"), "{err}");

    // Unknown scenes and bad options are usage errors too.
    assert_eq!(penumbra(&["run", "nowhere"]).status.code(), Some(2));
    assert_eq!(
        penumbra(&["run", "textbook", "--epsilon", "2"])
            .status
            .code(),
        Some(2)
    );
    assert_eq!(
        penumbra(&["run", "textbook", "--max-elements", "1"])
            .status
            .code(),
        Some(2)
    );
    assert_eq!(
        penumbra(&["run", "textbook", "--mesh", "fancy"])
            .status
            .code(),
        Some(2)
    );
    assert_eq!(
        penumbra(&["run", "textbook", "--penumbra-density", "0.5"])
            .status
            .code(),
        Some(2)
    );
    for (camera, words) in [
        ("1,2:3,4,5", "three finite numbers"),
        ("1,2,3:1,2,3", "the same point"),
        ("0,-4,3:0,0,0:180", "between 0 and 180"),
        ("0,-4,3", "EX,EY,EZ:TX,TY,TZ"),
    ] {
        let o = penumbra(&["run", "textbook", "--camera", camera]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{camera}: {err}");
        assert!(
            err.contains("--camera") && err.contains(words),
            "{camera}: {err}"
        );
    }
}

/// `--camera` moves the render's view, and only it: the solution is the same.
#[test]
fn the_camera_moves_the_render_only() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    run_quietly("textbook", &a, &["--direct-only"]);
    run_quietly(
        "textbook",
        &b,
        &["--direct-only", "--camera", "-0.2,0.3,5:0.2,-0.3,0:60"],
    );
    let read = |d: &Path, f: &str| std::fs::read(d.join(f)).expect("written");
    assert_eq!(read(&a, "solution.json"), read(&b, "solution.json"));
    assert_ne!(read(&a, "render.png"), read(&b, "render.png"));
}

/// EEE events are on by default where a scene has them, counted in the report, listed in the
/// solution, and `--no-eee` leaves them out.
#[test]
fn eee_events_are_reported_and_can_be_left_out() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut counts = Vec::new();
    for (name, extra) in [("with", None), ("without", Some("--no-eee"))] {
        let out = dir.path().join(name);
        // A discontinuity mesh keeps every event; an error-driven one only those that bound an
        // umbra or a penumbra.
        let mut args = vec![
            "--direct-only",
            "--max-elements",
            "3000",
            "--mesh",
            "discontinuity",
        ];
        args.extend(extra);
        run_quietly("bars", &out, &args);
        let report = json(&out.join("report.json"));
        let events = report["discontinuities"]["eee_events"]
            .as_u64()
            .expect("count");
        assert_eq!(report["method"]["eee"].as_bool(), Some(extra.is_none()));
        let solution = json(&out.join("solution.json"));
        let listed = solution["surfaces"]
            .as_array()
            .expect("surfaces")
            .iter()
            .flat_map(|s| s["discontinuities"].as_array().into_iter().flatten())
            .filter(|d| d["event"] == "EEE")
            .count();
        counts.push((events, listed));
    }
    assert!(counts[0].0 > 0 && counts[0].1 > 0, "{counts:?}");
    assert_eq!(counts[1], (0, 0));
}

#[test]
fn scenes_and_check() {
    let o = penumbra(&["scenes"]);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    for name in ["cornell", "textbook", "furnace"] {
        assert!(text.contains(name), "{text}");
    }
    let o = penumbra(&["check", "cornell"]);
    assert!(o.status.success());
    assert!(String::from_utf8_lossy(&o.stdout).contains("17 surfaces, 1 emitting"));
}

/// `--threads` is honoured, and the solution and render are the same bytes with one thread or
/// two, and from run to run: on the Cornell box, and on 100 boxes whose meshes, grading probes
/// and discontinuities are found surface by surface in parallel.
#[test]
fn solutions_are_byte_identical_whatever_the_thread_count() {
    let dir = tempfile::tempdir().expect("temp dir");
    for (scene, budget) in [("cornell", "1500"), ("boxworld", "8000")] {
        let mut outputs = Vec::new();
        for threads in ["1", "2", "2"] {
            let out = dir.path().join(format!("{scene}{}", outputs.len()));
            run_quietly(
                scene,
                &out,
                &["--max-elements", budget, "--threads", threads],
            );
            let report = json(&out.join("report.json"));
            assert_eq!(report["method"]["threads"].to_string(), threads);
            outputs.push((
                std::fs::read(out.join("solution.json")).expect("solution"),
                std::fs::read(out.join("render.png")).expect("render"),
            ));
        }
        assert!(outputs.windows(2).all(|w| w[0] == w[1]), "{scene}");
    }
}

/// `--refine-tol` refines adaptively from a tenth of the budget and says how in `report.json`;
/// a tolerance that is not positive is a usage error. Full solutions refine as they shoot, with
/// either estimate of the indirect light's error, and the mesh that comes out is the one solved.
#[test]
fn adaptive_refinement_is_reported() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    run_quietly(
        "textbook",
        &out,
        &[
            "--direct-only",
            "--max-elements",
            "8000",
            "--refine-tol",
            "0.001",
        ],
    );
    let report = json(&out.join("report.json"));
    let refinement = &report["refinement"];
    let rounds = refinement["rounds"].as_array().expect("rounds");
    assert!(rounds.len() >= 2, "{refinement}");
    let first = rounds[0]["triangles"].as_u64().expect("count");
    let last = report["counts"]["triangles"].as_u64().expect("count");
    assert!(
        first <= 2000 && last > first && last <= 8000,
        "{first} -> {last}"
    );
    assert!(refinement["stop"].is_string());
    assert!(refinement["residual"]["max"].as_f64().expect("max") > 0.0);
    assert_eq!(
        penumbra(&["run", "textbook", "--refine-tol", "0"])
            .status
            .code(),
        Some(2)
    );
    for estimate in ["gradient", "gathered"] {
        let out = dir.path().join(estimate);
        run_quietly(
            "cornell",
            &out,
            &[
                "--solver",
                "progressive",
                "--max-elements",
                "4000",
                "--refine-tol",
                "0.002",
                "--refine-indirect",
                estimate,
                "--epsilon",
                "0.01",
            ],
        );
        let report = json(&out.join("report.json"));
        let solver = &report["solver"];
        let rounds = report["refinement"]["rounds"].as_array().expect("rounds");
        assert!(rounds.len() >= 2 && rounds[0]["shots"].as_u64().expect("shots") > 0);
        assert_eq!(solver["remeshes"].as_u64(), Some(rounds.len() as u64 - 1));
        assert!(solver["gathered"].as_u64().expect("gathered") > 0);
        assert_eq!(solver["receivers"], report["counts"]["vertices"]);
        assert_eq!(solver["stop"], "converged");
    }
}

/// `penumbra sweep` runs the three default methods per budget and writes a row for each, in CSV and JSON,
/// and each sample's values in `samples.csv`;
/// without `--direct-only` it says what is missing and exits 2.
#[test]
fn sweep_writes_a_row_per_method_and_budget() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("sweep");
    let o = penumbra(&[
        "sweep",
        "textbook",
        "--direct-only",
        "--budgets",
        "800,1600",
        "--samples",
        "400",
        "--out",
        out.to_str().expect("utf-8"),
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("sweep.csv")).expect("sweep.csv");
    assert_eq!(csv.lines().count(), 1 + 2 * 3, "{csv}");
    let sweep = json(&out.join("sweep.json"));
    let rows = sweep["rows"].as_array().expect("rows");
    assert_eq!(rows.len(), 6);
    // Each sample with its reference and every run's value there, whose errors give the rows'.
    let samples = std::fs::read_to_string(out.join("samples.csv")).expect("samples.csv");
    let lines: Vec<Vec<f64>> = samples
        .lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .skip(4)
                .map(|v| v.parse().expect("a number"))
                .collect()
        })
        .collect();
    assert_eq!(lines.len(), 400);
    let mean = lines.iter().map(|l| l[0]).sum::<f64>() / 400.0;
    for (k, r) in rows.iter().enumerate() {
        let sum2: f64 = lines.iter().map(|l| (l[k + 1] - l[0]).powi(2)).sum();
        let rms = (sum2 / 400.0).sqrt() / mean;
        let want = r["rms"].as_f64().expect("rms");
        assert!(
            (rms - want).abs() <= 1e-5 * want,
            "row {k}: {rms} from samples.csv, {want}"
        );
    }
    for r in rows {
        let rms = r["rms"].as_f64().expect("rms");
        assert!(rms.is_finite() && rms >= 0.0 && rms <= r["max"].as_f64().expect("max"));
        assert!(
            r["triangles"].as_u64().expect("count") <= r["max_elements"].as_u64().expect("budget")
        );
    }
    // At the larger budget, the discontinuity mesh beats the uniform one.
    let rms_of = |method: &str| {
        rows.iter()
            .find(|r| r["method"] == method && r["max_elements"] == 1600)
            .and_then(|r| r["rms"].as_f64())
            .expect("row")
    };
    assert!(rms_of("discontinuity") < rms_of("uniform"));
    // The worst sample is where the maximum error is.
    for r in rows {
        let worst = &r["worst"];
        let e = (worst["value"].as_f64().expect("value")
            - worst["reference"].as_f64().expect("ref"))
        .abs()
            / sweep["reference_mean"].as_f64().expect("mean");
        assert!((e - r["max"].as_f64().expect("max")).abs() <= 1e-12 * e.max(1.0));
    }
    // Both charts, as SVG with a line per method and as PNG.
    for stem in ["error-vs-elements", "error-vs-time"] {
        let svg = std::fs::read_to_string(out.join(format!("{stem}.svg"))).expect("svg");
        assert_eq!(svg.matches("<polyline").count(), 1 + 3, "frame and 3 lines");
        for method in ["error-driven", "discontinuity"] {
            assert!(svg.contains(method));
        }
        let png = std::fs::read(out.join(format!("{stem}.png"))).expect("png");
        assert!(png.starts_with(b"\x89PNG"));
    }
}

/// Without `--direct-only` the sweep scores full solutions against path tracing at the samples,
/// traced once and cached in the output directory.
#[test]
fn full_sweeps_trace_their_reference_once() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("sweep");
    let args = [
        "sweep",
        "textbook",
        "--budgets",
        "600",
        "--samples",
        "60",
        "--reference-paths",
        "100",
        "--out",
        out.to_str().expect("utf-8"),
        "--quiet",
    ];
    let o = penumbra(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let reference = std::fs::read(out.join("reference.json")).expect("cached reference");
    let sweep = json(&out.join("sweep.json"));
    assert_eq!(sweep["reference"], "path traced");
    assert!(
        sweep["reference_standard_error"]
            .as_f64()
            .expect("error")
            .is_finite()
    );
    assert_eq!(sweep["rows"].as_array().expect("rows").len(), 3);
    let first = std::fs::read(out.join("sweep.json")).expect("sweep.json");
    // A second run reads the reference back, and the same runs give the same bytes.
    let o = penumbra(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        std::fs::read(out.join("reference.json")).expect("cached"),
        reference
    );
    let second: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("sweep.json")).expect("sweep.json"))
            .expect("json");
    let first: serde_json::Value = serde_json::from_slice(&first).expect("json");
    // Timings differ between runs; the errors do not.
    let errors = |v: &serde_json::Value| -> Vec<f64> {
        v["rows"]
            .as_array()
            .expect("rows")
            .iter()
            .map(|r| r["rms"].as_f64().expect("rms"))
            .collect()
    };
    assert_eq!(errors(&first), errors(&second));
}

/// `--time-budget` stops shooting when the time is spent and says so; the solution written is
/// the best so far, with the unshot light reported. A budget that is not positive is a usage
/// error.
#[test]
fn a_spent_time_budget_is_reported() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    run_quietly(
        "cornell",
        &out,
        &[
            "--solver",
            "progressive",
            "--time-budget",
            "0.2",
            "--width",
            "64",
            "--height",
            "64",
        ],
    );
    let report = json(&out.join("report.json"));
    assert_eq!(report["solver"]["stop"], "time_budget");
    assert_eq!(report["method"]["time_budget"].as_f64(), Some(0.2));
    let unshot = report["energy"]["unshot_fraction"]
        .as_f64()
        .expect("fraction");
    assert!(unshot > 1e-3, "{unshot}");
    check_radiosity(&json(&out.join("solution.json")));
    assert_eq!(
        penumbra(&["run", "textbook", "--time-budget", "0"])
            .status
            .code(),
        Some(2)
    );
}

/// `--solver` picks how the system is solved; Gauss–Seidel and the dense direct solve agree with
/// progressive refinement on the same mesh to the solvers' tolerance; `--convergence` writes the
/// residual's history as CSV and charts; adaptive refinement with another solver is refused.
#[test]
fn solvers_agree_and_report_their_convergence() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut solutions = Vec::new();
    for solver in ["progressive", "gauss-seidel", "direct"] {
        let out = dir.path().join(solver);
        run_quietly(
            "cornell",
            &out,
            &[
                "--max-elements",
                "1500",
                "--solver",
                solver,
                "--epsilon",
                "1e-6",
                "--convergence",
            ],
        );
        let report = json(&out.join("report.json"));
        let stats = &report["solver"];
        assert!(
            stats["residual"].as_f64().expect("residual") < 1e-6,
            "{stats}"
        );
        let csv = std::fs::read_to_string(out.join("convergence.csv")).expect("csv");
        let rows = csv.lines().count() - 1;
        assert_eq!(
            rows as u64,
            stats["iterations"].as_u64().expect("iterations") + 1
        );
        for stem in ["convergence-iterations", "convergence-time"] {
            assert!(
                out.join(format!("{stem}.svg")).exists()
                    && out.join(format!("{stem}.png")).exists()
            );
        }
        let solution = json(&out.join("solution.json"));
        let values: Vec<f64> = solution["surfaces"]
            .as_array()
            .expect("surfaces")
            .iter()
            .flat_map(|s| s["radiosity"].as_array().expect("radiosity").clone())
            .map(|b| b[0].as_f64().expect("r"))
            .collect();
        assert!(values.iter().all(|v| v.is_finite() && *v >= 0.0));
        solutions.push(values);
    }
    let largest = solutions[2].iter().copied().fold(0.0, f64::max);
    for other in &solutions[..2] {
        let worst = other
            .iter()
            .zip(&solutions[2])
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-4 * largest, "{worst} of {largest}");
    }
    let o = penumbra(&[
        "run",
        "textbook",
        "--solver",
        "jacobi",
        "--refine-tol",
        "0.01",
        "--out",
        dir.path().join("x").to_str().expect("utf-8"),
        "--quiet",
    ]);
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// `--solver hierarchical` converges, reports its hierarchy and links, agrees with the dense
/// solve on the surfaces' means, stops at a spent time budget with a partial solution, refines
/// adaptively, and refuses a link tolerance outside (0, 1) by naming the option.
#[test]
fn hierarchical_runs_report_their_links() {
    let dir = tempfile::tempdir().expect("temp dir");
    // The room's large surfaces (the blocks' sides, a few patches each for the dense solve at
    // this budget, are where its own discretization errs most).
    let means = |out: &Path| -> Vec<f64> {
        json(&out.join("solution.json"))["surfaces"]
            .as_array()
            .expect("surfaces")
            .iter()
            .filter(|s| !s["name"].as_str().expect("name").contains("block"))
            .map(|s| {
                let b = s["radiosity"].as_array().expect("radiosity");
                b.iter().map(|c| c[1].as_f64().expect("g")).sum::<f64>() / b.len() as f64
            })
            .collect()
    };
    let out = dir.path().join("hierarchical");
    // A mesh spread by area: the dense solve's patches group about as many elements each, and
    // are coarse where an error-driven mesh is.
    let common = [
        "--mesh",
        "discontinuity",
        "--max-elements",
        "3000",
        "--epsilon",
        "1e-6",
        "--convergence",
    ];
    run_quietly(
        "cornell",
        &out,
        &[&common[..], &["--solver", "hierarchical"]].concat(),
    );
    let report = json(&out.join("report.json"));
    let stats = &report["solver"];
    assert_eq!(stats["stop"], "converged", "{stats}");
    let h = &stats["hierarchy"];
    let links = h["links"].as_u64().expect("links");
    let by_depth: u64 = h["links_by_depth"]
        .as_array()
        .expect("by depth")
        .iter()
        .map(|n| n.as_u64().expect("count"))
        .sum();
    assert!(links > 0 && by_depth == links, "{h}");
    assert_eq!(
        h["links_open"].as_u64().expect("open") + h["links_partial"].as_u64().expect("partial"),
        links
    );
    assert!(h["clusters"].as_u64().expect("clusters") > 0);
    let csv = std::fs::read_to_string(out.join("convergence.csv")).expect("csv");
    assert_eq!(
        csv.lines().count() as u64 - 1,
        stats["iterations"].as_u64().expect("iterations") + 1
    );
    let dense = dir.path().join("direct");
    run_quietly(
        "cornell",
        &dense,
        &[&common[..], &["--solver", "direct"]].concat(),
    );
    for (h, d) in means(&out).iter().zip(means(&dense)) {
        assert!((h - d).abs() < 0.03 * d, "{h} against {d}");
    }
    let spent = dir.path().join("spent");
    let o = penumbra(&[
        "run",
        "cornell",
        "--solver",
        "hierarchical",
        "--time-budget",
        "0.01",
        "--out",
        spent.to_str().expect("utf-8"),
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report = json(&spent.join("report.json"));
    assert_eq!(report["partial"], true);
    assert_eq!(report["solver"]["stop"], "time_budget");
    assert!(check_radiosity(&json(&spent.join("solution.json"))) > 0);
    // Adaptive refinement: new vertices gather through the links, then the refined mesh is
    // solved with its own hierarchy.
    let adaptive = dir.path().join("adaptive");
    run_quietly(
        "cornell",
        &adaptive,
        &[
            "--solver",
            "hierarchical",
            "--max-elements",
            "4000",
            "--refine-tol",
            "2e-3",
        ],
    );
    let report = json(&adaptive.join("report.json"));
    let rounds = report["refinement"]["rounds"].as_array().expect("rounds");
    assert!(rounds.len() > 1, "{}", report["refinement"]);
    assert!(report["solver"]["remeshes"].as_u64().expect("remeshes") > 0);
    assert!(report["counts"]["triangles"].as_u64().expect("triangles") > 1000);
    assert!(check_radiosity(&json(&adaptive.join("solution.json"))) > 0);
    let o = penumbra(&[
        "run",
        "cornell",
        "--solver",
        "hierarchical",
        "--refine-tol",
        "1e-3",
        "--refine-indirect",
        "gathered",
        "--out",
        dir.path().join("gathered").to_str().expect("utf-8"),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("--refine-indirect"), "{stderr}");
    // Links that cannot fit are refused before the run starts, with a tolerance that fits.
    let o = penumbra(&[
        "run",
        "cornell",
        "--solver",
        "hierarchical",
        "--link-tol",
        "1e-9",
        "--memory-limit",
        "1000",
        "--out",
        dir.path().join("links").to_str().expect("utf-8"),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("--link-tol") && stderr.contains("or more"),
        "{stderr}"
    );
    for bad in ["0", "-1", "NaN", "1"] {
        let o = penumbra(&[
            "run",
            "textbook",
            "--solver",
            "hierarchical",
            &format!("--link-tol={bad}"),
            "--out",
            dir.path().join("bad").to_str().expect("utf-8"),
        ]);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains("--link-tol"), "{stderr}");
        assert!(!dir.path().join("bad").exists());
    }
}

/// `penumbra sweep --solvers` repeats each plain run with each solver (adaptive runs shoot), a
/// row and a chart line each, the solver named in the CSV.
#[test]
fn sweeps_compare_solvers() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("sweep");
    let o = penumbra(&[
        "sweep",
        "textbook",
        "--budgets",
        "600",
        "--samples",
        "40",
        "--reference-paths",
        "64",
        "--methods",
        "discontinuity,discontinuity+adaptive",
        "--solvers",
        "progressive,gauss-seidel,direct",
        "--out",
        out.to_str().expect("utf-8"),
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let sweep = json(&out.join("sweep.json"));
    let rows = sweep["rows"].as_array().expect("rows");
    let pairs: Vec<(String, String)> = rows
        .iter()
        .map(|r| {
            (
                r["method"].as_str().expect("method").to_owned(),
                r["solver"].as_str().expect("solver").to_owned(),
            )
        })
        .collect();
    assert_eq!(pairs.len(), 4, "{pairs:?}");
    assert!(pairs.contains(&("discontinuity+adaptive".into(), "progressive".into())));
    assert!(pairs.contains(&("discontinuity".into(), "direct".into())));
    let csv = std::fs::read_to_string(out.join("sweep.csv")).expect("csv");
    assert!(csv.lines().next().expect("header").contains(",solver,"));
    let svg = std::fs::read_to_string(out.join("error-vs-elements.svg")).expect("svg");
    assert_eq!(
        svg.matches("<polyline").count(),
        1,
        "one point per line: markers only"
    );
    assert!(svg.contains("discontinuity (gauss-seidel)"));
}

/// `--form-factors hemicube` solves the same system as the analytic form factors, to within the
/// pixel grid's error; it gives rows of a fixed mesh, so adaptive refinement refuses it.
#[test]
fn hemicube_form_factors_run_and_refuse_refinement() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut absorbed = Vec::new();
    for ff in ["analytic", "hemicube"] {
        let out = dir.path().join(ff);
        run_quietly(
            "cornell",
            &out,
            &[
                "--solver",
                "progressive",
                "--max-elements",
                "1500",
                "--form-factors",
                ff,
            ],
        );
        check_radiosity(&json(&out.join("solution.json")));
        let report = json(&out.join("report.json"));
        absorbed.push(
            report["energy"]["absorbed_fraction"]
                .as_f64()
                .expect("absorbed"),
        );
    }
    assert!((absorbed[0] - absorbed[1]).abs() < 1e-3, "{absorbed:?}");
    for bad in [
        vec!["--form-factors", "hemicube", "--refine-tol", "0.01"],
        vec!["--form-factors", "hemicube", "--hemicube-resolution", "7"],
    ] {
        let out = dir.path().join("x");
        let mut args = vec![
            "run",
            "textbook",
            "--out",
            out.to_str().expect("utf-8"),
            "--quiet",
        ];
        args.extend(bad);
        let o = penumbra(&args);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(String::from_utf8_lossy(&o.stderr).contains("hemicube"));
    }
}

/// A run that would need more memory than it may use stops before it starts (exit 2), and
/// names a --max-elements that fits; with that budget the same limit is enough, and the peak
/// the run reports stays under it.
#[test]
fn runs_too_large_for_memory_are_refused_with_a_budget_that_fits() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    let o = penumbra(&["run", "cornell", "--memory-limit", "60", "--quiet"]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    let suggested: usize = stderr
        .split("--max-elements ")
        .nth(1)
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no --max-elements in: {stderr}"));
    assert!((500..10_000).contains(&suggested), "{suggested}");
    assert!(!out.exists());
    let budget = suggested.to_string();
    run_quietly(
        "cornell",
        &out,
        &["--memory-limit", "60", "--max-elements", &budget],
    );
    let report = json(&out.join("report.json"));
    let memory = &report["memory"];
    assert_eq!(memory["limit_bytes"], 60 << 20);
    let estimate = memory["estimate_bytes"].as_u64().expect("bytes");
    assert!(estimate <= 60 << 20, "{estimate}");
    if let Some(peak) = memory["peak_bytes"]["render"].as_u64() {
        assert!(peak <= estimate, "peak {peak} over the estimate {estimate}");
    }
    // Far beyond any machine: a dense gathering matrix of a hundred million elements.
    let o = penumbra(&[
        "run",
        "cornell",
        "--solver",
        "gauss-seidel",
        "--max-elements",
        "100000000",
        "--quiet",
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("TiB"), "{stderr}");
}

/// The memory estimate is an upper bound of what a run holds, on a scene of many polygons and
/// many triangles: the peak resident memory `report.json` gives at each stage stays under it.
#[test]
fn the_memory_estimate_bounds_the_peak() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    run_quietly(
        "boxworld-1000",
        &out,
        &["--max-elements", "80000", "--direct-only"],
    );
    let report = json(&out.join("report.json"));
    assert_eq!(report["scene"]["surfaces"], 5002);
    let memory = &report["memory"];
    let estimate = memory["estimate_bytes"].as_u64().expect("bytes");
    let peaks = memory["peak_bytes"].as_object().expect("stages");
    assert_eq!(peaks.len(), 5);
    for (stage, peak) in peaks {
        // Absent where the system does not say (not Linux).
        if let Some(peak) = peak.as_u64() {
            assert!(
                peak <= estimate,
                "{stage}: {peak} over the estimate {estimate}"
            );
        }
    }
}

/// `penumbra check` on OBJ files: repairs and merges are reported, `--no-merge` keeps every face,
/// and when validation refuses a scene the repairs come first, before the problems.
#[test]
fn check_reports_obj_repairs_even_when_the_scene_is_refused() {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(
        dir.path().join("m.mtl"),
        "newmtl white\nKd 0.7 0.7 0.7\nnewmtl lamp\nKd 0 0 0\nKe 5 5 5\n",
    )
    .expect("write mtl");
    // A floor of two triangles under a lamp, and a face with no area.
    let lit = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 0 0 1\nv 0 1 1\nv 1 1 1\n\
        o floor\nusemtl white\nf 1 2 3\nf 1 3 4\nf 1 2 5\n\
        o lamp\nusemtl lamp\nf 6 7 8\n";
    let scene = dir.path().join("lit.obj");
    std::fs::write(&scene, lit).expect("write obj");
    let path = scene.to_str().expect("utf-8");
    let o = penumbra(&["check", path]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("warning: dropped 1 faces with zero area (first: floor/white/2 at line 14)"),
        "{err}"
    );
    assert!(
        err.contains("warning: merged 2 coplanar faces into 1 surfaces"),
        "{err}"
    );
    assert!(String::from_utf8_lossy(&o.stdout).contains("2 surfaces, 1 emitting"));
    let o = penumbra(&["check", "--no-merge", path]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("3 surfaces, 1 emitting"));

    // Without the lamp the scene is refused, and the repair is still reported, first.
    let dark = dir.path().join("dark.obj");
    std::fs::write(&dark, lit.replace("usemtl lamp", "usemtl white")).expect("write obj");
    let o = penumbra(&["check", dark.to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    let warning = err
        .find("warning: dropped 1 faces")
        .expect("the repair is reported");
    let error = err.find("error:").expect("the refusal is reported");
    assert!(warning < error && err.contains("no surface emits"), "{err}");
}

/// An OBJ scene of `n` x `n` small triangles hovering apart over a floor, under a lamp (and a
/// material library beside it): n² + 2 polygons needing n² + 4 triangles, but each triangle
/// casts its own shadow on the floor, whose discontinuities as mesh edges need many more.
fn leaves_obj(dir: &Path, n: usize) -> std::path::PathBuf {
    std::fs::write(
        dir.join("leaves.mtl"),
        "newmtl white\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0 0 0\nKe 10 10 10\n",
    )
    .expect("write mtl");
    let mut obj = String::from(
        "mtllib leaves.mtl\nv -5 -5 0\nv 5 -5 0\nv 5 5 0\nv -5 5 0\n\
         v -0.5 -0.5 5\nv -0.5 0.5 5\nv 0.5 0.5 5\nv 0.5 -0.5 5\n\
         o floor\nusemtl white\nf 1 2 3 4\no lamp\nusemtl lamp\nf 5 6 7 8\no leaves\nusemtl white\n",
    );
    let size = 4.0 / n as f64;
    for k in 0..n * n {
        let x = -4.0 + 8.0 * ((k / n) as f64 + 0.5) / n as f64;
        let y = -4.0 + 8.0 * ((k % n) as f64 + 0.5) / n as f64;
        let v = 8 + 3 * k;
        obj += &format!(
            "v {x} {y} 1\nv {} {y} 1\nv {x} {} 1\nf {} {} {}\n",
            x + size,
            y + size,
            v + 1,
            v + 2,
            v + 3
        );
    }
    let path = dir.join("leaves.obj");
    std::fs::write(&path, obj).expect("write obj");
    path
}

/// Without `--max-elements` the budget fits the scene: 10,000 triangles, or the least mesh of
/// its polygons with their discontinuities as edges and 4 triangles more per surface. An
/// explicit budget one triangle short of that least mesh is refused (exit 2), naming it; one
/// below what the polygons alone need is refused before the discontinuities are looked for,
/// naming the polygons' own figure. Adaptive refinement starts from the least mesh and refines
/// up to the fitted budget.
#[test]
fn the_default_budget_fits_the_scene() {
    let dir = tempfile::tempdir().expect("temp dir");
    let n = 40;
    let scene = leaves_obj(dir.path(), n);
    let path = scene.to_str().expect("utf-8");
    let surfaces = n * n + 2;
    let polygons_need = n * n + 4;
    let out = dir.path().join("fit");
    run_quietly(path, &out, &["--direct-only", "--mesh", "discontinuity"]);
    let report = json(&out.join("report.json"));
    assert_eq!(report["scene"]["surfaces"], surfaces);
    assert_eq!(report["method"]["max_elements_requested"], "fit");
    let budget = report["method"]["max_elements"].as_u64().expect("budget") as usize;
    let triangles = report["counts"]["triangles"].as_u64().expect("count") as usize;
    assert!(
        triangles > 10_000 && triangles <= budget,
        "{triangles} of {budget}"
    );
    let least = budget - penumbra_meshing::FIT_TRIANGLES_PER_SURFACE * surfaces;
    assert!(least > polygons_need + 4 * surfaces, "{least}");

    let refused = dir.path().join("refused");
    let try_budget = |n: usize| {
        let o = penumbra(&[
            "run",
            path,
            "--direct-only",
            "--mesh",
            "discontinuity",
            "--max-elements",
            &n.to_string(),
            "--out",
            refused.to_str().expect("utf-8"),
            "--quiet",
        ]);
        assert_eq!(o.status.code(), Some(2));
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let late = try_budget(least - 1);
    assert!(
        late.contains(&format!(
            "--max-elements {} is too small: the scene's polygons, with their discontinuities as \
             edges, need at least {least} triangles; use --max-elements {least} or more",
            least - 1
        )),
        "{late}"
    );
    // The figure is the polygons' own: the discontinuities were not looked for.
    let early = try_budget(polygons_need - 1);
    assert!(
        early.contains(&format!(
            "the scene's polygons need at least {polygons_need} triangles; use --max-elements \
             {polygons_need} or more"
        )) && !early.contains("discontinuities"),
        "{early}"
    );
    assert!(!refused.exists());

    let out = dir.path().join("adaptive");
    // Tight enough that the fitted mesh is not already within it.
    run_quietly(path, &out, &["--direct-only", "--refine-tol", "0.001"]);
    let report = json(&out.join("report.json"));
    assert_eq!(report["method"]["max_elements"], budget);
    let rounds = report["refinement"]["rounds"].as_array().expect("rounds");
    let first = rounds[0]["triangles"].as_u64().expect("count") as usize;
    let last = report["counts"]["triangles"].as_u64().expect("count") as usize;
    assert!(
        first < least + surfaces && last > first && last <= budget,
        "{first} -> {last} of {budget}"
    );
    // An explicit budget that fits the scene but not the default start (a tenth of it, enough
    // for the polygons alone) names the start's option.
    let explicit = (10 * (polygons_need + 1)).max(budget);
    assert!(explicit / 10 < least);
    let o = penumbra(&[
        "run",
        path,
        "--direct-only",
        "--refine-tol",
        "0.01",
        "--max-elements",
        &explicit.to_string(),
        "--out",
        refused.to_str().expect("utf-8"),
        "--quiet",
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains(&format!("use --initial-elements {least} or more")),
        "{stderr}"
    );
}

/// `--svg`: by default the 24 surfaces with the most discontinuity segments, then the largest
/// (every surface of a smaller scene); `all`, `none`, or names. `report.json` lists the files
/// written; an unknown name is refused before the run, naming it.
#[test]
fn svgs_are_written_for_the_surfaces_asked_for() {
    let dir = tempfile::tempdir().expect("temp dir");
    let svgs = |out: &Path| -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(out.join("surfaces"))
            .map(|d| {
                d.map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
                    .collect()
            })
            .unwrap_or_default();
        names.sort();
        names
    };
    let listed = |out: &Path| -> Vec<String> {
        let report = json(&out.join("report.json"));
        report["svgs"]["written"]
            .as_array()
            .expect("list")
            .iter()
            .map(|s| {
                s.as_str()
                    .expect("name")
                    .trim_start_matches("surfaces/")
                    .to_owned()
            })
            .collect()
    };
    let base = ["--direct-only", "--max-elements", "9000"];
    // 100 boxes: 502 surfaces.
    let out = dir.path().join("auto");
    run_quietly("boxworld", &out, &base);
    let written = svgs(&out);
    assert_eq!(written.len(), 24);
    assert_eq!(listed(&out), written);
    assert_eq!(json(&out.join("report.json"))["svgs"]["selection"], "auto");
    // The floor has the most segments: every shadow falls on it.
    assert!(written.contains(&"001-floor.svg".to_owned()), "{written:?}");
    // The same choice every time.
    let again = dir.path().join("again");
    run_quietly("boxworld", &again, &base);
    assert_eq!(svgs(&again), written);

    let out = dir.path().join("all");
    run_quietly("boxworld", &out, &[&base[..], &["--svg", "all"]].concat());
    assert_eq!(svgs(&out).len(), 502);
    assert_eq!(listed(&out), svgs(&out));

    let out = dir.path().join("none");
    run_quietly("boxworld", &out, &[&base[..], &["--svg", "none"]].concat());
    assert!(!out.join("surfaces").exists());
    assert!(listed(&out).is_empty());

    let out = dir.path().join("named");
    run_quietly(
        "boxworld",
        &out,
        &[&base[..], &["--svg", "box7_top,floor"]].concat(),
    );
    assert_eq!(svgs(&out), ["001-floor.svg", "037-box7_top.svg"]);
    assert_eq!(json(&out.join("report.json"))["svgs"]["selection"], "named");

    let out = dir.path().join("unknown");
    let o = penumbra(&[
        "run",
        "boxworld",
        "--svg",
        "floor,roof,box7_top,chimney",
        "--out",
        out.to_str().expect("utf-8"),
        "--quiet",
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("--svg") && stderr.contains("\"roof\", \"chimney\""),
        "{stderr}"
    );
    assert!(!out.exists());
}

/// A wall of few large triangles with a corner right beside a lamp: the linear interpolant of
/// the light at its corners takes in more than the lamp gives, the escaped power is negative,
/// and the report and stderr say so; with enough triangles the balance closes.
#[test]
fn an_energy_balance_that_does_not_close_is_flagged() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = dir.path().join("sliver.json");
    std::fs::write(
        &scene,
        r#"{"name": "sliver", "surfaces": [
            {"name": "lamp", "polygon": [[-0.5,-0.5,2],[-0.5,0.5,2],[0.5,0.5,2],[0.5,-0.5,2]],
             "emission": [10,10,10], "reflectance": [0,0,0]},
            {"name": "floor", "polygon": [[-5,-5,0],[5,-5,0],[5,5,0],[-5,5,0]], "reflectance": [0.5,0.5,0.5]},
            {"name": "wall", "polygon": [[0.51,0,1.999],[0.51,4,0.5],[0.51,-4,0.5]], "reflectance": [0.5,0.5,0.5]}
        ]}"#,
    )
    .expect("write scene");
    let path = scene.to_str().expect("utf-8");
    let coarse = ["--direct-only", "--mesh", "uniform", "--max-elements", "20"];
    let out = dir.path().join("coarse");
    let mut args = vec!["run", path, "--out", out.to_str().expect("utf-8")];
    args.extend(coarse);
    let o = penumbra(&args);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(
        stderr.contains("warning: the energy account does not balance"),
        "{stderr}"
    );
    let report = json(&out.join("report.json"));
    let energy = &report["energy"];
    assert_eq!(energy["balanced"], false);
    assert!(
        energy["escaped_fraction"].as_f64().expect("fraction") < -0.1,
        "{energy}"
    );
    assert!(
        report["warnings"]
            .as_array()
            .expect("warnings")
            .iter()
            .any(|w| w
                .as_str()
                .is_some_and(|w| w.contains("escaped power is negative"))),
        "{report}"
    );
    // --quiet keeps stderr clean; the report still says it.
    let quiet = run_quietly(path, &dir.path().join("quiet"), &coarse);
    assert!(quiet.stderr.is_empty());

    let out = dir.path().join("fine");
    run_quietly(path, &out, &["--direct-only", "--mesh", "uniform"]);
    let report = json(&out.join("report.json"));
    assert_eq!(report["energy"]["balanced"], true);
    assert!(
        report["energy"]["escaped_fraction"]
            .as_f64()
            .expect("fraction")
            > 0.0
    );
    assert_eq!(report["warnings"], serde_json::json!([]));
}

/// An OBJ material with `Kd 1 1 1` is clamped below 1 with one warning naming it, not refused.
#[test]
fn obj_reflectance_of_one_is_clamped_with_a_warning() {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(
        dir.path().join("m.mtl"),
        "newmtl bricks\nKd 1 1 1\nnewmtl lamp\nKd 0 0 0\nKe 5 5 5\n",
    )
    .expect("write mtl");
    // Two floors of bricks, apart, under a lamp.
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 3 0 0\nv 4 0 0\nv 4 1 0\n\
        v 0 0 1\nv 0 1 1\nv 1 1 1\n\
        usemtl bricks\nf 1 2 3\nf 4 5 6\nusemtl lamp\nf 7 8 9\n";
    let scene = dir.path().join("bricks.obj");
    std::fs::write(&scene, obj).expect("write obj");
    let o = penumbra(&["check", scene.to_str().expect("utf-8")]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert_eq!(stderr.matches("Kd").count(), 1, "{stderr}");
    assert!(
        stderr.contains("warning: material \"bricks\" has Kd 1 1 1") && stderr.contains("0.99"),
        "{stderr}"
    );
}

/// A time budget spent before the discontinuity search starts its first pair leaves the mesh
/// without events, and the direct light estimated by rays at every vertex: the run still
/// completes, and `report.json` says the result is partial, how many pairs were skipped and how
/// many vertices were estimated, with a warning.
#[test]
fn a_budget_spent_in_the_discontinuity_search_makes_the_run_partial() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    run_quietly(
        "textbook",
        &out,
        &["--direct-only", "--time-budget", "1e-9"],
    );
    let report = json(&out.join("report.json"));
    assert_eq!(report["partial"], true);
    let d = &report["discontinuities"];
    assert!(d["pairs"].as_u64().expect("pairs") > 0);
    assert_eq!(d["pairs_skipped"], d["pairs"]);
    assert_eq!(d["segments"], 0);
    assert!(check_radiosity(&json(&out.join("solution.json"))) > 0);
    let solver = &report["solver"];
    assert_eq!(solver["stop"], "time_budget");
    assert_eq!(solver["direct_estimated"], solver["receivers"]);
    let warned = report["warnings"]
        .as_array()
        .expect("warnings")
        .iter()
        .any(|w| {
            w.as_str()
                .is_some_and(|w| w.contains("estimated with rays"))
        });
    assert!(warned, "{}", report["warnings"]);
}
