//! What the tests share: running the binary, reading what it says and writes, and running a
//! scene in this process ([`in_process`]). Each test file uses its own part of it.
#![allow(dead_code)]

pub mod in_process;

use std::path::Path;
use std::process::{Command, Output};

/// `penumbra ARGS`, whatever its exit status.
pub fn penumbra(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args(args)
        .output()
        .expect("the penumbra binary runs")
}

/// `penumbra ARGS`; fails the test unless it succeeds.
pub fn succeeds(args: &[&str]) -> Output {
    let o = penumbra(args);
    assert!(o.status.success(), "penumbra {args:?}: {}", stderr(&o));
    o
}

/// `penumbra run SCENE --out OUT --quiet` with `extra` options; fails the test unless it
/// succeeds.
pub fn run_quietly(scene: &str, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["run", scene, "--out", path(out), "--quiet"];
    args.extend(extra);
    succeeds(&args)
}

/// What a run said on standard error.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A JSON file the run wrote.
pub fn json(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{} is not JSON: {e}", path.display()))
}

/// A path as a command-line argument.
pub fn path(p: &Path) -> &str {
    p.to_str().expect("utf-8")
}

/// Every radiosity in a solution is finite and non-negative; returns how many there are.
pub fn check_radiosity(solution: &serde_json::Value) -> usize {
    let mut n = 0;
    for s in solution["surfaces"].as_array().expect("surfaces") {
        let vertices = s["vertices"].as_array().expect("vertices").len();
        let radiosity = s["radiosity"].as_array().expect("radiosity");
        assert_eq!(radiosity.len(), vertices);
        for c in radiosity.iter().flat_map(|c| c.as_array().expect("rgb")) {
            let v = c.as_f64().expect("a number, not null (NaN)");
            assert!(v.is_finite() && v >= 0.0, "radiosity {v}");
            n += 1;
        }
        for t in s["triangles"].as_array().expect("triangles") {
            for i in t.as_array().expect("index triple") {
                assert!((i.as_u64().expect("index") as usize) < vertices);
            }
        }
    }
    n
}
