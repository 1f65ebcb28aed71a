//! `--solver photon-map` from the command line: the textbook's light against the exact direct
//! light, the report's figures, and the same bytes whatever the thread count.

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
}

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
        "9",
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
    }
    assert!(
        solutions[0] == solutions[1],
        "solution.json differs with the thread count"
    );
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
