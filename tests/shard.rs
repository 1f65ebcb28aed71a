//! Sharded runs (`run --shard I/N`) joined by `penumbra merge` give the run not split, byte for
//! byte, unless an error-driven mesh of a large scene is refined by each shard alone; mixed,
//! missing and duplicate shards are refused.

use std::path::{Path, PathBuf};

mod common;
use common::{path, penumbra, succeeds};
use std::process::Output;

/// Fails with exit 2 and a message holding every one of `words`; returns the message.
fn refused(args: &[&str], words: &[&str]) -> String {
    let o = penumbra(args);
    let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(2), "{args:?}: {stderr}");
    for w in words {
        assert!(stderr.contains(w), "{args:?}: {w:?} not in {stderr}");
    }
    stderr
}

/// A budget that keeps a run small, and spreads it over all surfaces (so that every shard meshes
/// the whole scene).
const CAP: &[&str] = &["--max-elements", "2500"];

/// A direct-only run of `scene` into `out`, with `extra` options (by default [`CAP`]).
fn run(scene: &str, out: &Path, extra: &[&str]) {
    let budget = match extra.contains(&"--fit") {
        true => &[][..],
        false => CAP,
    };
    let mut args = vec![
        "run",
        scene,
        "--direct-only",
        "--width",
        "96",
        "--height",
        "96",
        "--quiet",
        "--out",
        path(out),
    ];
    args.extend(budget);
    args.extend(extra.iter().filter(|&&a| a != "--fit"));
    succeeds(&args);
}

/// Runs shards 0..count of `scene` into `root/shard-I`; returns their directories.
fn shards(scene: &str, root: &Path, count: usize, extra: &[&str]) -> Vec<PathBuf> {
    (0..count)
        .map(|i| {
            let dir = root.join(format!("shard-{i}"));
            let shard = format!("{i}/{count}");
            let mut args = vec!["--shard", shard.as_str()];
            args.extend(extra);
            run(scene, &dir, &args);
            dir
        })
        .collect()
}

fn merge(dirs: &[PathBuf], out: &Path) -> Output {
    let mut args = vec!["merge", "--quiet", "--out", path(out)];
    args.extend(dirs.iter().map(|d| path(d)));
    penumbra(&args)
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).expect("written")).expect("JSON")
}

/// Every file under `dir`, relative, with its bytes.
fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut all = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).expect("readable") {
            let p = e.expect("entry").path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).expect("inside").display().to_string();
                all.push((rel, std::fs::read(&p).expect("readable")));
            }
        }
    }
    all.sort();
    all
}

/// `--fit`: the default budget, fitted to the scene: `boxworld-1000`'s polygons need more than
/// its floor, so with a discontinuity mesh each shard finds the discontinuities of its own
/// surfaces and meshes them alone. The others are error-driven (the default): every shard makes
/// the whole mesh.
#[test]
fn shards_merge_into_the_run_not_split_byte_for_byte() {
    let dir = tempfile::tempdir().expect("temp dir");
    let cases: [(&str, &[&str]); 5] = [
        ("cornell", &[]),
        // The merge renders from the shards' camera.
        ("textbook", &["--camera", "0.2,0.3,5:0.2,0.3,0:60"]),
        ("boxworld-12", &[]),
        ("tessellated-2", &[]),
        ("boxworld-1000", &["--fit", "--mesh", "discontinuity"]),
    ];
    for (scene, extra) in cases {
        let whole = dir.path().join(format!("{scene}-whole"));
        run(scene, &whole, extra);
        let expected = files(&whole);
        let whole_report = json(&whole.join("report.json"));
        for count in [1, 2, 3] {
            let root = dir.path().join(format!("{scene}-{count}"));
            let dirs = shards(scene, &root, count, extra);
            let alone = extra.contains(&"--fit");
            for d in &dirs {
                let shard = json(&d.join("shard.json"));
                assert_eq!(shard["meshed_alone"], alone, "{scene}: {}", d.display());
                // A shard that meshes alone meshes only its own surfaces.
                let triangles = |r: &serde_json::Value| r["counts"]["triangles"].as_u64();
                if alone && count > 1 {
                    assert!(triangles(&shard["report"]) < triangles(&whole_report));
                }
            }
            let out = root.join("merged");
            let o = merge(&dirs, &out);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            let merged = files(&out);
            // solution.json, render.png and every SVG are the same bytes; report.json differs in
            // its times and shards, and in the last digits of summed energies, and the viewer
            // page embeds it.
            assert!(merged.iter().any(|(name, _)| name == "index.html"));
            let same =
                |(name, _): &&(String, Vec<u8>)| name != "report.json" && name != "index.html";
            let want: Vec<_> = expected.iter().filter(same).collect();
            let got: Vec<_> = merged.iter().filter(same).collect();
            assert_eq!(
                want.iter().map(|f| &f.0).collect::<Vec<_>>(),
                got.iter().map(|f| &f.0).collect::<Vec<_>>(),
                "{scene}, {count} shards: the files"
            );
            for (w, g) in want.iter().zip(&got) {
                assert!(w.1 == g.1, "{scene}, {count} shards: {} differs", w.0);
            }
            let report = json(&out.join("report.json"));
            assert_eq!(report["shards"]["count"], count);
            for path in [
                "/counts",
                "/discontinuities/pairs",
                "/discontinuities/segments",
                "/svgs/written",
                "/method/max_elements",
                "/energy/balanced",
            ] {
                assert_eq!(
                    report.pointer(path),
                    whole_report.pointer(path),
                    "{scene}, {count} shards: {path}"
                );
            }
            let fraction = |r: &serde_json::Value| {
                r["energy"]["absorbed_fraction"].as_f64().expect("a number")
            };
            assert!((fraction(&report) - fraction(&whole_report)).abs() < 1e-12);
        }
    }
}

/// An error-driven mesh of a large scene with the fitted budget: each shard refines its own
/// surfaces alone, from their least mesh, with its part (by estimated cost) of the fit's extra
/// triangles. One shard is the run not split, byte for byte. More spend the same budget in all,
/// each on its own surfaces (where the run not split spends it where the whole scene's error is
/// largest), against the same scene mean.
#[test]
fn error_driven_shards_of_a_large_scene_refine_alone() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = "boxworld-1000";
    let whole = dir.path().join("whole");
    run(scene, &whole, &["--fit"]);
    let whole_report = json(&whole.join("report.json"));
    let one = shards(scene, &dir.path().join("one"), 1, &["--fit"]);
    let out = dir.path().join("one-merged");
    assert!(merge(&one, &out).status.success());
    assert!(
        std::fs::read(out.join("solution.json")).expect("merged")
            == std::fs::read(whole.join("solution.json")).expect("whole")
    );
    let dirs = shards(scene, &dir.path().join("three"), 3, &["--fit"]);
    let mut triangles = 0;
    for d in &dirs {
        let shard = json(&d.join("shard.json"));
        assert_eq!(shard["meshed_alone"], true, "{}", d.display());
        triangles += shard["report"]["mesh_error"]["triangles"]
            .as_u64()
            .expect("a count");
    }
    let out = dir.path().join("merged");
    let o = merge(&dirs, &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report = json(&out.join("report.json"));
    let at = |r: &serde_json::Value, p: &str| r.pointer(p).cloned().expect(p);
    assert_eq!(
        at(&report, "/mesh_error/mean_reflected"),
        at(&whole_report, "/mesh_error/mean_reflected")
    );
    // The budget, shared out (each part rounded).
    let budget = |r: &serde_json::Value| at(r, "/method/max_elements").as_i64().expect("a count");
    assert!((budget(&report) - budget(&whole_report)).abs() <= 3);
    let refined = |r: &serde_json::Value| at(r, "/mesh_error/surfaces").as_array().map(Vec::len);
    assert!(refined(&report) > Some(0));
    assert_eq!(at(&report, "/mesh_error/triangles"), triangles);
    assert_eq!(at(&report, "/counts/triangles"), triangles);
    // Direct-light runs with a fitted budget split at points measured up to twice it.
    assert!(triangles as i64 <= 2 * budget(&report));
    // Where both meshes have a point, its direct light agrees to 1e-9 of the brightest (on a
    // contact line, both sides' values): the mesh may measure a vertex that the direct light
    // pass lights in the other run, which rounds differently.
    let whole_solution = json(&whole.join("solution.json"));
    let merged_solution = json(&out.join("solution.json"));
    let (shared, same) = same_light_at_shared_points(&whole_solution, &merged_solution, 1e-9);
    assert!(shared > 1000, "{shared} points shared");
    assert_eq!(same, shared);
    // The light's energy accounted for as in the run not split.
    let fraction = |r: &serde_json::Value| at(r, "/energy/escaped_fraction").as_f64();
    let (split, not_split) = (fraction(&report), fraction(&whole_report));
    assert!((split.expect("a number") - not_split.expect("a number")).abs() < 0.01);
}

/// Of the points (by their coordinates' bits) where both solutions have vertices on the same
/// surface: how many, and at how many both give the same direct light values, each channel
/// within `tolerance` of the brightest value of either.
fn same_light_at_shared_points(
    a: &serde_json::Value,
    b: &serde_json::Value,
    tolerance: f64,
) -> (usize, usize) {
    type Values = std::collections::BTreeMap<Vec<u64>, Vec<Vec<f64>>>;
    let list = |v: &serde_json::Value| v.as_array().cloned().unwrap_or_default();
    let numbers = |v: &serde_json::Value| -> Vec<f64> {
        list(v)
            .iter()
            .filter_map(serde_json::Value::as_f64)
            .collect()
    };
    let by_point = |s: &serde_json::Value| {
        let mut at = Values::new();
        for (p, d) in list(&s["vertices"]).iter().zip(list(&s["direct"])) {
            let point = numbers(p).into_iter().map(f64::to_bits).collect();
            at.entry(point).or_default().push(numbers(&d));
        }
        at.values_mut()
            .for_each(|v| v.sort_by(|x, y| x.partial_cmp(y).expect("finite")));
        at
    };
    let surfaces = |s: &serde_json::Value| list(&s["surfaces"]);
    let brightest = [a, b]
        .iter()
        .flat_map(|s| surfaces(s))
        .flat_map(|s| list(&s["direct"]))
        .flat_map(|d| numbers(&d))
        .fold(0.0, f64::max);
    let close = |x: &Vec<Vec<f64>>, y: &Vec<Vec<f64>>| {
        x.len() == y.len()
            && (x.iter().flatten().zip(y.iter().flatten()))
                .all(|(u, v)| (u - v).abs() <= tolerance * brightest)
    };
    let (mut shared, mut same) = (0, 0);
    for (x, y) in surfaces(a).iter().zip(&surfaces(b)) {
        let (x, y) = (by_point(x), by_point(y));
        for (point, values) in &x {
            if let Some(other) = y.get(point) {
                shared += 1;
                same += usize::from(close(values, other));
            }
        }
    }
    (shared, same)
}

/// More shards than surfaces: some shards light nothing, and the merge is still the whole run.
#[test]
fn empty_shards_merge_too() {
    let dir = tempfile::tempdir().expect("temp dir");
    let whole = dir.path().join("whole");
    run("textbook", &whole, &[]);
    let dirs = shards("textbook", dir.path(), 5, &[]);
    // Fewer surfaces than shards: some shards light none, each surface is in one.
    let lit = |d: &PathBuf| {
        json(&d.join("shard.json"))["surfaces"]
            .as_array()
            .map_or(0, Vec::len)
    };
    let surfaces = json(&whole.join("solution.json"))["surfaces"]
        .as_array()
        .map_or(0, Vec::len);
    assert!(surfaces < dirs.len());
    assert_eq!(dirs.iter().map(lit).sum::<usize>(), surfaces);
    assert!(dirs.iter().any(|d| lit(d) == 0));
    let out = dir.path().join("merged");
    // The directories in any order.
    let mut shuffled = dirs.clone();
    shuffled.reverse();
    let o = merge(&shuffled, &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        std::fs::read(out.join("solution.json")).expect("merged")
            == std::fs::read(whole.join("solution.json")).expect("whole")
    );
}

#[test]
fn merge_refuses_missing_duplicate_and_mixed_shards() {
    let dir = tempfile::tempdir().expect("temp dir");
    let dirs = shards("textbook", &dir.path().join("a"), 3, &[]);
    let out = dir.path().join("merged");
    let out_s = path(&out);
    let (d0, d1, d2) = (path(&dirs[0]), path(&dirs[1]), path(&dirs[2]));
    refused(
        &["merge", "--out", out_s, d0, d2],
        &["missing shard 1 of 3"],
    );
    refused(
        &["merge", "--out", out_s, d0, d1, d2, d1],
        &["shard 1/3 is given twice"],
    );
    // Other options: another element budget.
    let other = shards(
        "textbook",
        &dir.path().join("b"),
        3,
        &["--penumbra-density", "4"],
    );
    refused(
        &["merge", "--out", out_s, d0, path(&other[1]), d2],
        &["not from the same run", "options differ"],
    );
    // Another scene.
    let scene = shards("cornell", &dir.path().join("c"), 3, &[]);
    refused(
        &["merge", "--out", out_s, d0, path(&scene[1]), d2],
        &["not from the same run", "scenes differ"],
    );
    // Another count.
    let two = shards("textbook", &dir.path().join("d"), 2, &[]);
    refused(
        &["merge", "--out", out_s, path(&two[0]), path(&two[1]), d2],
        &["shard counts differ"],
    );
    // Not a shard: a run not split.
    let whole = dir.path().join("whole");
    run("textbook", &whole, &[]);
    refused(&["merge", "--out", out_s, path(&whole)], &["shard.json"]);
    refused(&["merge", "--out", out_s], &["DIRS"]);
    assert!(!out.exists(), "nothing written");
}

#[test]
fn run_refuses_shards_it_cannot_split() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    let out_s = path(&out);
    refused(
        &["run", "textbook", "--shard", "0/2", "--out", out_s],
        &["--shard needs --direct-only", "bounces"],
    );
    for bad in ["2/2", "0/0", "x", "1", "-1/2", ""] {
        let flag = format!("--shard={bad}");
        let message = refused(
            &["run", "textbook", "--direct-only", &flag, "--out", out_s],
            &["--shard: "],
        );
        assert!(message.contains(if bad == "2/2" { "0 to 1" } else { "I/N" }) || bad == "0/0");
    }
    for (flag, value) in [("--refine-tol", "0.01"), ("--time-budget", "5")] {
        refused(
            &[
                "run",
                "textbook",
                "--direct-only",
                "--shard",
                "0/2",
                flag,
                value,
                "--out",
                out_s,
            ],
            &[&format!("--shard with {flag}")],
        );
    }
    assert!(!out.exists(), "nothing written");
}
