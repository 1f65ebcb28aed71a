//! OBJ+MTL import: faces become surfaces, `Kd` their reflectance and `Ke` their emission.
//!
//! Exported meshes are rarely clean. Repairs that cannot change the lighting are made and listed
//! as warnings that say how many faces each touched and name the first few (by surface name
//! and line): repeated corners are dropped, faces that touch themselves are cut into loops,
//! faces with no area dropped, and non-planar faces split into triangles ([`repair`]). Then
//! coplanar adjacent faces of one material are merged into single surfaces where that is exact
//! ([`crate::coplanar`]), unless [`ObjOptions::merge_coplanar`] is off. A material whose `Kd`
//! reaches 1 (white in many exported scenes: Sponza's bricks are `Kd 1 1 1`) has those channels
//! clamped to [`MAX_OBJ_REFLECTANCE`], with one warning per material. Anything else is left for
//! validation to report.
//!
//! Faces are named `object/material/index` ([`faces`]); a merged surface takes the name of its
//! first face, and a face cut into pieces names them `name.0`, `name.1`, ...

mod faces;
mod source_lines;

use std::cell::RefCell;
use std::collections::HashSet;
use std::path::{Path, PathBuf};

use crate::color::Rgb;
use crate::error::SceneError;
use crate::load::{read_bytes, scene_name};
use crate::mesh_file::into_surfaces;
use crate::mesh_file::tally::{FaceSource, Tally};
use crate::model::Scene;
use faces::collect_faces;
use source_lines::SourceLines;

/// Reflectance of faces without a material.
pub(crate) const DEFAULT_REFLECTANCE: f64 = 0.5;

/// The highest reflectance an OBJ material gets: `Kd` channels at or above 1 are clamped to it.
/// A reflectance of 1 keeps all the light a surface receives, which the radiosity equation
/// cannot converge with in a closed scene; 0.99 keeps the material's look (white stays white)
/// and lets light die out after a few hundred bounces. JSON scenes state reflectance
/// deliberately and are refused instead.
pub const MAX_OBJ_REFLECTANCE: f64 = 0.99;

/// Choices in reading OBJ files.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ObjOptions {
    /// Merge coplanar adjacent faces of one material into single surfaces where the union is a
    /// simple polygon (on by default). Off, every face is a surface.
    pub merge_coplanar: bool,
}

impl Default for ObjOptions {
    fn default() -> Self {
        ObjOptions {
            merge_coplanar: true,
        }
    }
}

/// Reads an OBJ file and the MTL files it names, looked for beside it.
pub(crate) fn read_obj_with(
    path: &Path,
    options: &ObjOptions,
) -> Result<(Scene, Vec<String>), SceneError> {
    let bytes = read_bytes(path)?;
    let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    // Names in comments are often in a legacy encoding; they need not stop the import.
    let text = String::from_utf8_lossy(&bytes);
    parse(&text, path, options, |library| {
        let looked_for = dir.join(library);
        let text = std::fs::read(&looked_for).map(|b| String::from_utf8_lossy(&b).into_owned());
        (looked_for, text)
    })
}

/// Parses OBJ text with the default options; every `mtllib` it names reads as `mtl`. `path` only
/// names the source.
pub fn parse_obj_text(
    obj: &str,
    mtl: &str,
    path: &Path,
) -> Result<(Scene, Vec<String>), SceneError> {
    parse_obj_text_with(obj, mtl, path, &ObjOptions::default())
}

/// Parses OBJ text; every `mtllib` it names reads as `mtl`. `path` only names the source.
pub fn parse_obj_text_with(
    obj: &str,
    mtl: &str,
    path: &Path,
    options: &ObjOptions,
) -> Result<(Scene, Vec<String>), SceneError> {
    parse(obj, path, options, |library| {
        (library.to_path_buf(), Ok(mtl.to_string()))
    })
}

/// Parses MTL text. tobj panics on a colour with fewer than three numbers, so such lines are
/// refused here first.
fn load_mtl(text: &str) -> tobj::MTLLoadResult {
    for line in text.lines() {
        let mut words = line.split_whitespace();
        if matches!(words.next(), Some("Ka" | "Kd" | "Ks" | "Ke")) && words.count() < 3 {
            return Err(tobj::LoadError::MaterialParseError);
        }
    }
    tobj::load_mtl_buf(&mut text.as_bytes())
}

/// Reads `text`; `read_library` gives, for a name in `mtllib`, the path it looked for and the
/// library's text.
fn parse(
    text: &str,
    path: &Path,
    options: &ObjOptions,
    read_library: impl Fn(&Path) -> (PathBuf, std::io::Result<String>),
) -> Result<(Scene, Vec<String>), SceneError> {
    let lines = SourceLines::scan(text);
    let Loaded {
        models,
        materials,
        mut warnings,
    } = load_models(text, path, &lines, read_library)?;
    warnings.extend(undefined_materials(&lines, &materials));

    let collected = collect_faces(&models, &materials, &lines);
    warnings.extend(collected.without_material.describe(
        "",
        &format!(
            "faces have no material; they get reflectance {DEFAULT_REFLECTANCE} and no emission"
        ),
    ));
    warnings.extend(collected.polylines.describe(
        "ignored",
        "polylines (`l` statements; they are lines, not surfaces)",
    ));
    let materials_of = |m: Option<usize>| surface_material(m, &materials);
    let (surfaces, made) = into_surfaces(
        collected.faces,
        options.merge_coplanar,
        &materials_of,
        |used| clamped_reflectance_warnings(used, &materials),
    );
    warnings.extend(made);
    Ok((
        Scene {
            up: None,
            unit: None,
            name: scene_name(path),
            camera: None,
            surfaces,
        },
        warnings,
    ))
}

/// What tobj reads of an OBJ file and its material libraries.
struct Loaded {
    models: Vec<tobj::Model>,
    materials: Vec<tobj::Material>,
    /// One for each material library that could not be read: the import goes on without its
    /// materials.
    warnings: Vec<String>,
}

/// The models and materials tobj reads from `text`, with the libraries it names.
fn load_models(
    text: &str,
    path: &Path,
    lines: &SourceLines,
    read_library: impl Fn(&Path) -> (PathBuf, std::io::Result<String>),
) -> Result<Loaded, SceneError> {
    // tobj takes the library loader as `Fn`, so the warnings it notes need a cell.
    let library_warnings = RefCell::new(Vec::new());
    let load_options = tobj::LoadOptions {
        triangulate: false,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, materials) = tobj::load_obj_buf(&mut text.as_bytes(), &load_options, |library| {
        load_library(library, lines, &read_library, &library_warnings)
    })
    .map_err(|e| SceneError::Obj {
        path: path.to_path_buf(),
        message: format!("{e}; check the file is a valid OBJ"),
    })?;
    // tobj reports a library error only when no library loaded; `load_library` has warned of it.
    let materials = materials.unwrap_or_default();
    Ok(Loaded {
        models,
        materials,
        warnings: library_warnings.into_inner(),
    })
}

/// Reads and parses the material library `library`; when it cannot, notes in `warnings` why,
/// naming the `mtllib` line.
fn load_library(
    library: &Path,
    lines: &SourceLines,
    read_library: impl Fn(&Path) -> (PathBuf, std::io::Result<String>),
    warnings: &RefCell<Vec<String>>,
) -> tobj::MTLLoadResult {
    let (looked_for, read) = read_library(library);
    let looked_for = looked_for.display();
    let at = lines
        .libraries
        .get(library.to_string_lossy().as_ref())
        .map(|line| format!(" (mtllib at line {line})"))
        .unwrap_or_default();
    let text = read.map_err(|e| {
        let problem = if e.kind() == std::io::ErrorKind::NotFound {
            format!("material library not found: looked for {looked_for}{at}")
        } else {
            format!("cannot read material library {looked_for}{at}: {e}")
        };
        warnings.borrow_mut().push(library_warning(&problem));
        tobj::LoadError::OpenFileFailed
    })?;
    load_mtl(&text).inspect_err(|e| {
        warnings.borrow_mut().push(library_warning(&format!(
            "materials could not be read from {looked_for}{at} ({e})"
        )));
    })
}

/// `problem` with a material library, followed by what its faces get instead.
fn library_warning(problem: &str) -> String {
    format!(
        "{problem}; faces with its materials get reflectance {DEFAULT_REFLECTANCE} and no emission"
    )
}

/// One warning per material of `used` whose `Kd` reaches 1, in material order.
fn clamped_reflectance_warnings(used: &[usize], materials: &[tobj::Material]) -> Vec<String> {
    used.iter()
        .filter_map(|&m| materials.get(m))
        .filter_map(clamped_reflectance_warning)
        .collect()
}

/// A face's reflectance and emission from its material (an index into `materials`), or the defaults without one.
fn surface_material(material: Option<usize>, materials: &[tobj::Material]) -> (Rgb, Rgb) {
    match material.and_then(|m| materials.get(m)) {
        Some(m) => (
            m.diffuse
                .map(|kd| Rgb::from(kd).map(clamp_reflectance))
                .unwrap_or(Rgb::splat(DEFAULT_REFLECTANCE)),
            m.emissive.map(Rgb::from).unwrap_or(Rgb::ZERO),
        ),
        None => (Rgb::splat(DEFAULT_REFLECTANCE), Rgb::ZERO),
    }
}

/// A `Kd` channel as a reflectance: at or above 1, [`MAX_OBJ_REFLECTANCE`]; anything else as it
/// is (what is negative or not a number is validation's to refuse).
fn clamp_reflectance(kd: f64) -> f64 {
    if kd >= 1.0 { MAX_OBJ_REFLECTANCE } else { kd }
}

/// The warning for a material whose `Kd` reaches 1 in some channel, if it does.
fn clamped_reflectance_warning(material: &tobj::Material) -> Option<String> {
    let kd = material.diffuse?;
    if !kd.iter().any(|&c| c >= 1.0) {
        return None;
    }
    Some(format!(
        "material \"{}\" has Kd {} {} {}: a surface cannot reflect all the light it receives, so \
         its channels at or above 1 become {MAX_OBJ_REFLECTANCE}",
        material.name, kd[0], kd[1], kd[2]
    ))
}

/// Materials `usemtl` selects that no library defines, as one warning.
fn undefined_materials(lines: &SourceLines, materials: &[tobj::Material]) -> Option<String> {
    let defined: HashSet<&str> = materials.iter().map(|m| m.name.as_str()).collect();
    let mut undefined = Tally::default();
    for (name, line) in &lines.materials_used {
        if !defined.contains(name.as_str()) {
            undefined.note(&FaceSource {
                name: format!("\"{name}\""),
                line: Some(*line),
            });
        }
    }
    undefined.describe(
        "",
        &format!(
            "materials are used but defined in no material library; their faces get reflectance \
             {DEFAULT_REFLECTANCE} and no emission"
        ),
    )
}
