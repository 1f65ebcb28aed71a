//! The JSON Schemas of `solution.json` and `report.json` (docs/schemas/) against what the program
//! really writes: runs of the CLI that between them produce every optional section (uniform and
//! discontinuity meshes, direct light only, each solver, adaptive refinement, a spent time
//! budget, shards and their merge), each output validated against its schema.
//!
//! The schemas forbid fields they do not name (`"additionalProperties": false`), so a field
//! added to either file fails these tests until it has its entry, with a `description`, in
//! docs/schemas/; the failure names the path in the document that has no entry.

use std::path::Path;

mod common;
use common::{json, succeeds};

use serde_json::{Value, json};

const SOLUTION_SCHEMA: &str = "solution.schema.json";
const REPORT_SCHEMA: &str = "report.schema.json";

fn schema(name: &str) -> Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("docs/schemas")
        .join(name);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    serde_json::from_str(&text)
        .unwrap_or_else(|e| panic!("{} is not valid JSON: {e}", path.display()))
}

fn validator(name: &str) -> jsonschema::Validator {
    jsonschema::draft202012::new(&schema(name))
        .unwrap_or_else(|e| panic!("docs/schemas/{name} does not compile: {e}"))
}

/// Every way `document` breaks the schema `name`, each with the path in the document that
/// failed and the schema rule it failed.
fn violations(name: &str, document: &Value) -> Vec<String> {
    let validator = validator(name);
    validator
        .iter_errors(document)
        .map(|e| {
            let at = e.instance_path().as_str();
            format!(
                "at {}: {e} (rule {name}#{})",
                if at.is_empty() { "/" } else { at },
                e.schema_path().as_str()
            )
        })
        .collect()
}

/// Fails, listing every violation, unless `document` (read from `origin`) matches schema `name`.
fn assert_matches(name: &str, document: &Value, origin: &str) {
    let found = violations(name, document);
    assert!(
        found.is_empty(),
        "{origin} does not match docs/schemas/{name} (a new field needs its entry there):\n  {}",
        found.join("\n  ")
    );
}

/// `penumbra run SCENE --out OUT` with a small render and `extra` options.
fn run(scene: &str, out: &Path, extra: &[&str]) {
    let mut args = vec![
        "run",
        scene,
        "--out",
        out.to_str().expect("utf-8"),
        "--quiet",
        "--width",
        "48",
        "--height",
        "48",
    ];
    args.extend(extra);
    succeeds(&args);
}

/// What a schema cannot say of a solution: one radiosity per vertex, triangles that index this
/// surface's vertices.
fn check_solution_shape(solution: &Value, origin: &str) {
    let surfaces = solution["surfaces"].as_array().expect("surfaces");
    for (i, s) in surfaces.iter().enumerate() {
        let vertices = s["vertices"].as_array().expect("vertices").len();
        let radiosity = s["radiosity"].as_array().expect("radiosity").len();
        assert_eq!(
            radiosity, vertices,
            "{origin}: /surfaces/{i}: one radiosity per vertex"
        );
        for t in s["triangles"].as_array().expect("triangles") {
            for v in t.as_array().expect("index triple") {
                let v = v.as_u64().expect("index");
                assert!(
                    (v as usize) < vertices,
                    "{origin}: /surfaces/{i}/triangles: vertex {v} of {vertices}"
                );
            }
        }
    }
}

/// Validates `DIR/solution.json` and `DIR/report.json`; returns the report.
fn check_outputs(dir: &Path) -> Value {
    let solution = json(&dir.join("solution.json"));
    let origin = dir.join("solution.json").display().to_string();
    assert_matches(SOLUTION_SCHEMA, &solution, &origin);
    check_solution_shape(&solution, &origin);
    let report = json(&dir.join("report.json"));
    let origin = dir.join("report.json").display().to_string();
    assert_matches(REPORT_SCHEMA, &report, &origin);
    report
}

/// Calls `visit` with every object in `value` that lists `properties` (a schema of an object),
/// and its path in the schema.
fn object_schemas(value: &Value, path: &str, visit: &mut dyn FnMut(&str, &Value)) {
    match value {
        Value::Object(map) => {
            if map.get("properties").is_some_and(Value::is_object) {
                visit(path, value);
            }
            for (key, v) in map {
                object_schemas(v, &format!("{path}/{key}"), visit);
            }
        }
        Value::Array(items) => {
            for (i, v) in items.iter().enumerate() {
                object_schemas(v, &format!("{path}/{i}"), visit);
            }
        }
        _ => {}
    }
}

/// Both schemas are valid draft 2020-12 schemas, say where the prose is, describe every
/// property, and forbid fields they do not name.
#[test]
fn the_schemas_are_valid_and_document_every_field() {
    for name in [SOLUTION_SCHEMA, REPORT_SCHEMA] {
        let s = schema(name);
        if let Err(e) = jsonschema::draft202012::meta::validate(&s) {
            panic!(
                "docs/schemas/{name} is not a valid draft 2020-12 schema: at {}: {e}",
                e.instance_path().as_str()
            );
        }
        assert_eq!(
            s["$schema"], "https://json-schema.org/draft/2020-12/schema",
            "{name}"
        );
        let description = s["description"].as_str().unwrap_or_default();
        assert!(
            description.contains("docs/outputs.md"),
            "{name}: {description}"
        );
        validator(name);

        let (mut described, mut undocumented, mut open) = (0, Vec::new(), Vec::new());
        object_schemas(&s, "", &mut |path, object| {
            if object["additionalProperties"] != false {
                open.push(path.to_owned());
            }
            for (field, sub) in object["properties"].as_object().into_iter().flatten() {
                match sub["description"].as_str() {
                    Some(d) if !d.is_empty() => described += 1,
                    _ => undocumented.push(format!("{path}/properties/{field}")),
                }
            }
        });
        assert!(described > 5, "{name}");
        assert!(
            undocumented.is_empty(),
            "{name}: properties without a description: {undocumented:?}"
        );
        assert!(
            open.is_empty(),
            "{name}: objects that let unknown fields through: {open:?}"
        );
    }
}

/// A value of every field `schema` names (resolved against `root`'s `$defs`), each within its
/// schema's rules: the document a reader of the schema may meet that has everything in it.
fn example_of(schema: &Value, root: &Value) -> Value {
    if let Some(path) = schema["$ref"].as_str() {
        let name = path.trim_start_matches("#/$defs/");
        return example_of(&root["$defs"][name], root);
    }
    if let Some(value) = schema.get("const") {
        return value.clone();
    }
    if let Some(first) = schema["enum"].as_array().and_then(|e| e.first()) {
        return first.clone();
    }
    for choice in ["oneOf", "anyOf"] {
        if let Some(options) = schema[choice].as_array() {
            let option = options.iter().find(|o| o["type"] != "null");
            return example_of(option.expect("a choice that is not null"), root);
        }
    }
    let types: Vec<&str> = match &schema["type"] {
        Value::String(t) => vec![t.as_str()],
        Value::Array(ts) => ts.iter().filter_map(Value::as_str).collect(),
        _ => vec!["object"],
    };
    match types.into_iter().find(|&t| t != "null").unwrap_or("null") {
        "object" => {
            let properties = schema["properties"].as_object().into_iter().flatten();
            Value::Object(
                properties
                    .map(|(name, sub)| (name.clone(), example_of(sub, root)))
                    .collect(),
            )
        }
        "array" => {
            let items = schema["minItems"].as_u64().unwrap_or(1).max(1) as usize;
            Value::Array(vec![example_of(&schema["items"], root); items])
        }
        "string" => json!(match schema["pattern"].as_str() {
            Some("^[0-9]+/[0-9]+$") => "1/2",
            Some("^[0-9]+\\.[0-9]+\\.[0-9]+") => "1.2.3",
            Some("^[0-9a-f]{16}$") => "0123456789abcdef",
            Some("^surfaces/[0-9]{3,}-[A-Za-z0-9_-]*\\.svg$") => "surfaces/000-floor.svg",
            Some(other) => panic!("no example for the pattern {other}: add one"),
            None => "text",
        }),
        "boolean" => json!(true),
        "integer" => json!(schema["minimum"].as_u64().unwrap_or(1)),
        "number" => json!(number_within(schema)),
        "null" => Value::Null,
        other => panic!("no example of the type {other}"),
    }
}

/// A number within a number schema's bounds.
fn number_within(schema: &Value) -> f64 {
    let low = schema["minimum"]
        .as_f64()
        .or(schema["exclusiveMinimum"].as_f64())
        .unwrap_or(0.0);
    match schema["maximum"].as_f64() {
        Some(high) => (low + high) / 2.0,
        None => low + 0.5,
    }
}

/// The schema of `report.json` and the one type that writes and reads it name the same fields:
/// a report with every field the schema names reads into [`penumbra::report::Report`] (which
/// refuses fields it does not have), and written back it matches the schema (which refuses
/// fields it does not name) and has every field it had.
#[test]
fn the_report_type_and_its_schema_name_the_same_fields() {
    let root = schema(REPORT_SCHEMA);
    let everything = example_of(&root, &root);
    assert_matches(REPORT_SCHEMA, &everything, "the example report");
    let text = everything.to_string();
    let report = penumbra::report::Report::parse(&text).unwrap_or_else(|e| {
        panic!("a report with every field of docs/schemas/{REPORT_SCHEMA} does not read: {e}")
    });
    let written: Value = serde_json::from_str(&report.to_json()).expect("JSON");
    assert_matches(REPORT_SCHEMA, &written, "the example report written back");
    assert_eq!(written, everything, "a field was lost in the round trip");
    // Not vacuous: a field the type lacks is refused, by name.
    let mut more = everything.clone();
    more["scene"]["colour"] = json!("red");
    let refused = penumbra::report::Report::parse(&more.to_string()).expect_err("refused");
    assert!(refused.to_string().contains("colour"), "{refused}");
}

/// A field the schema does not know, and values it does not allow, are rejected, and the
/// message names where in the document they are.
#[test]
fn unknown_fields_and_wrong_values_are_rejected_where_they_are() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    run(
        "textbook",
        &out,
        &["--direct-only", "--max-elements", "300"],
    );
    let report = check_outputs(&out);
    let solution = json(&out.join("solution.json"));

    let rejected = |name: &str, document: &Value, at: &str, words: &[&str]| {
        let found = violations(name, document);
        assert!(
            found
                .iter()
                .any(|v| v.starts_with(&format!("at {at}:")) && words.iter().all(|w| v.contains(w))),
            "{name}: expected a violation at {at} naming {words:?}, found {found:#?}"
        );
    };

    let mut extra = report.clone();
    extra["options"] = json!({"threads": 2});
    rejected(REPORT_SCHEMA, &extra, "/", &["options"]);
    let mut deep = report.clone();
    deep["solver"]["hierarchy"] = json!({"link_tol": 1e-3, "links_by_depth": [], "teleports": 0});
    rejected(REPORT_SCHEMA, &deep, "/solver/hierarchy", &["teleports"]);
    let mut stop = report.clone();
    stop["solver"]["stop"] = json!("done");
    rejected(REPORT_SCHEMA, &stop, "/solver/stop", &["done"]);
    let mut missing = report.clone();
    missing["energy"]
        .as_object_mut()
        .expect("energy")
        .remove("balanced");
    rejected(REPORT_SCHEMA, &missing, "/energy", &["balanced"]);
    let mut nan = report.clone();
    nan["energy"]["closure_error"] = Value::Null;
    rejected(REPORT_SCHEMA, &nan, "/energy/closure_error", &[]);

    let (s, segment) = solution["surfaces"]
        .as_array()
        .expect("surfaces")
        .iter()
        .enumerate()
        .find_map(|(s, surface)| {
            (!surface["discontinuities"].as_array()?.is_empty()).then_some((s, 0))
        })
        .expect("the textbook floor has discontinuities");
    let mut event = solution.clone();
    event["surfaces"][s]["discontinuities"][segment]["event"] = json!("EVE");
    rejected(
        SOLUTION_SCHEMA,
        &event,
        &format!("/surfaces/{s}/discontinuities/{segment}/event"),
        &["EVE"],
    );
    let mut negative = solution.clone();
    negative["surfaces"][s]["radiosity"][0][1] = json!(-0.5);
    rejected(
        SOLUTION_SCHEMA,
        &negative,
        &format!("/surfaces/{s}/radiosity/0/1"),
        &[],
    );
    let mut short = solution.clone();
    short["surfaces"][s]["vertices"][0] = json!([0.0, 1.0]);
    rejected(
        SOLUTION_SCHEMA,
        &short,
        &format!("/surfaces/{s}/vertices/0"),
        &[],
    );
    // The meta-validation of the schemas themselves is not vacuous either.
    assert!(jsonschema::draft202012::meta::validate(&json!({"type": "numbr"})).is_err());
    let mut index = solution.clone();
    index["surfaces"][s]["index"] = json!(s);
    rejected(
        SOLUTION_SCHEMA,
        &index,
        &format!("/surfaces/{s}"),
        &["index"],
    );
}

/// Direct light only, on a discontinuity mesh and a uniform one (whose report has no
/// discontinuity search: `discontinuities` is null).
#[test]
fn direct_light_and_uniform_meshes_match_the_schemas() {
    let dir = tempfile::tempdir().expect("temp dir");
    let direct = dir.path().join("direct");
    run(
        "textbook",
        &direct,
        &["--direct-only", "--max-elements", "500"],
    );
    let report = check_outputs(&direct);
    assert_eq!(report["method"]["solver"], "direct");
    assert_eq!(report["solver"]["stop"], "direct_only");
    assert!(report["discontinuities"].is_object());
    assert_eq!(report["invocation"]["options"]["direct_only"], true);

    let uniform = dir.path().join("uniform");
    run(
        "textbook",
        &uniform,
        &["--mesh", "uniform", "--max-elements", "300"],
    );
    let report = check_outputs(&uniform);
    assert_eq!(report["method"]["mesh"], "uniform");
    assert!(report["discontinuities"].is_null());
    assert_eq!(report["counts"]["discontinuity_segments"], 0);
}

/// A full solution by the default solver, hierarchical radiosity, with its `hierarchy`.
#[test]
fn hierarchical_solutions_match_the_schemas() {
    let dir = tempfile::tempdir().expect("temp dir");
    let hierarchical = dir.path().join("hierarchical");
    run("cornell", &hierarchical, &["--max-elements", "800"]);
    let report = check_outputs(&hierarchical);
    assert_eq!(report["method"]["solver"], "hierarchical");
    assert!(report["solver"]["hierarchy"].is_object());
    assert!(report.get("refinement").is_none());
    assert_eq!(report["energy"]["closed"], false);
    // A closed room: the report says so, lets nothing escape and balances.
    let furnace = dir.path().join("furnace");
    run("furnace-l", &furnace, &["--max-elements", "800"]);
    let report = check_outputs(&furnace);
    let energy = &report["energy"];
    assert_eq!(energy["closed"], true);
    assert_eq!(report["solver"]["closed"], true);
    let escaped = energy["escaped_fraction"].as_f64().expect("fraction");
    assert!(escaped.abs() < 1e-3, "{energy}");
    assert_eq!(energy["balanced"], true, "{energy}");
    assert_eq!(report["warnings"], serde_json::json!([]));
}

#[test]
fn photon_map_solutions_match_the_schemas() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("photon-map");
    let options = [
        "--solver",
        "photon-map",
        "--max-elements",
        "800",
        "--photons",
        "20000",
    ];
    run("cornell", &out, &options);
    let report = check_outputs(&out);
    assert_eq!(report["method"]["solver"], "photon-map");
    assert!(report["solver"]["photon_map"].is_object());
    assert_eq!(report["invocation"]["options"]["photons"], 20000);
}

/// Full solutions by Jacobi gathering with `--convergence`, and by the dense direct solve.
#[test]
fn gathering_and_dense_solutions_match_the_schemas() {
    let dir = tempfile::tempdir().expect("temp dir");
    for (solver, name) in [("jacobi", "jacobi"), ("direct", "dense-direct")] {
        let out = dir.path().join(solver);
        run(
            "cornell",
            &out,
            &["--solver", solver, "--max-elements", "800", "--convergence"],
        );
        let report = check_outputs(&out);
        assert_eq!(report["method"]["solver"], name);
        assert!(report["solver"].get("hierarchy").is_none());
        assert!(out.join("convergence.csv").exists());
    }
}

/// Adaptive refinement (`refinement`, with its rounds), and a time budget spent before the
/// discontinuity search and the direct light were done (`time_budget`, a partial run whose
/// direct light is estimated).
#[test]
fn adaptive_and_partial_runs_match_the_schemas() {
    let dir = tempfile::tempdir().expect("temp dir");
    let adaptive = dir.path().join("adaptive");
    run(
        "cornell",
        &adaptive,
        &[
            "--solver",
            "progressive",
            "--max-elements",
            "2000",
            "--initial-elements",
            "400",
            "--refine-tol",
            "0.005",
            "--epsilon",
            "0.01",
        ],
    );
    let report = check_outputs(&adaptive);
    assert!(
        report["refinement"]["rounds"]
            .as_array()
            .expect("rounds")
            .len()
            > 1
    );

    let partial = dir.path().join("partial");
    run(
        "cornell",
        &partial,
        &[
            "--solver",
            "progressive",
            "--max-elements",
            "1500",
            "--time-budget",
            "0.001",
        ],
    );
    let report = check_outputs(&partial);
    assert_eq!(report["partial"], true);
    assert_eq!(report["method"]["time_budget"], 0.001);
    assert_eq!(report["solver"]["stop"], "time_budget");
}

/// A sharded direct-light run: each shard's `shard.json` holds a report of the same schema and
/// its surfaces (each with its `index` in the scene, which solution.json leaves out); the merge
/// writes a solution and a report (with `shards`) that match the schemas.
#[test]
fn shards_and_their_merge_match_the_schemas() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut dirs = Vec::new();
    // The shards' surfaces in shard order: runs of consecutive surfaces, each surface once.
    let mut indices = Vec::new();
    for i in 0..2 {
        let out = dir.path().join(format!("shard-{i}"));
        let shard = format!("{i}/2");
        run(
            "textbook",
            &out,
            &["--direct-only", "--max-elements", "500", "--shard", &shard],
        );
        let file = json(&out.join("shard.json"));
        let origin = format!("{}: report", out.join("shard.json").display());
        assert_matches(REPORT_SCHEMA, &file["report"], &origin);
        let surfaces: Vec<Value> = file["surfaces"]
            .as_array()
            .expect("surfaces")
            .iter()
            .map(|s| {
                let mut s = s.clone();
                let index = s
                    .as_object_mut()
                    .and_then(|s| s.remove("index"))
                    .and_then(|i| i.as_u64())
                    .expect("a shard's surface has its index in the scene");
                indices.push(index);
                s
            })
            .collect();
        let part = json!({
            "format": "penumbra-solution/1",
            "scene": file["report"]["scene"]["name"],
            "surfaces": surfaces,
        });
        let origin = format!("{}: surfaces", out.join("shard.json").display());
        assert_matches(SOLUTION_SCHEMA, &part, &origin);
        dirs.push(out.to_str().expect("utf-8").to_owned());
    }
    assert_eq!(indices, (0..indices.len() as u64).collect::<Vec<_>>());
    let merged = dir.path().join("merged");
    let mut args = vec!["merge", "--quiet", "--out", merged.to_str().expect("utf-8")];
    args.extend(dirs.iter().map(String::as_str));
    succeeds(&args);
    let report = check_outputs(&merged);
    assert_eq!(report["shards"]["count"], 2);
    assert!(report["times_seconds"]["merge"].is_number());
}
